#include "anvil/mesh/mesh.hpp"

#include <algorithm>
#include <cmath>

namespace anvil {

std::int64_t Mesh::num_elements() const {
  std::int64_t n = 0;
  for (const auto& b : blocks) n += static_cast<std::int64_t>(b.elements.size());
  return n;
}

std::vector<std::int64_t> Mesh::block_offsets() const {
  std::vector<std::int64_t> off(1, 0);
  for (const auto& b : blocks)
    off.push_back(off.back() + static_cast<std::int64_t>(b.elements.size()));
  return off;
}

void Mesh::append(const Mesh& other, const std::string& prefix) {
  const std::int64_t node_shift = num_nodes();
  const std::int64_t elem_shift = num_elements();
  nodes.insert(nodes.end(), other.nodes.begin(), other.nodes.end());
  for (const auto& b : other.blocks) {
    ElementBlock nb{b.name, b.elements};
    for (auto& h : nb.elements)
      for (auto& n : h) n += node_shift;
    blocks.push_back(std::move(nb));
  }
  auto name = [&](const std::string& s) { return prefix.empty() ? s : prefix + "." + s; };
  for (const auto& [k, ids] : other.node_sets) {
    auto& dst = node_sets[name(k)];
    for (auto id : ids) dst.push_back(id + node_shift);
    std::sort(dst.begin(), dst.end());
    dst.erase(std::unique(dst.begin(), dst.end()), dst.end());
  }
  for (const auto& [k, sides] : other.side_sets) {
    auto& dst = side_sets[name(k)];
    for (auto s : sides) dst.push_back({s.element + elem_shift, s.face});
  }
}

void Mesh::translate(const Vec3& d) {
  for (auto& p : nodes) p += d;
}

double hex_volume(const std::array<Vec3, 8>& x) {
  // det J of the trilinear map is of degree two in each parent coordinate, so the
  // 2x2x2 Gauss rule integrates it exactly.
  static constexpr double s[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                     {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  const double g = 1.0 / std::sqrt(3.0);
  double v = 0;
  for (int q = 0; q < 8; ++q) {
    const double xi[3] = {s[q][0] * g, s[q][1] * g, s[q][2] * g};
    double J[3][3] = {};
    for (int a = 0; a < 8; ++a) {
      double dN[3];
      for (int d = 0; d < 3; ++d) {
        dN[d] = 0.125 * s[a][d];
        for (int e = 0; e < 3; ++e)
          if (e != d) dN[d] *= (1 + s[a][e] * xi[e]);
      }
      for (int i = 0; i < 3; ++i)
        for (int d = 0; d < 3; ++d) J[i][d] += x[a][i] * dN[d];
    }
    v += J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
         J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
         J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
  }
  return v;
}

std::vector<std::int64_t> select_nodes(const Mesh& mesh, const Box3& box,
                                       const std::vector<std::int64_t>* candidates) {
  std::vector<std::int64_t> out;
  if (candidates && !candidates->empty()) {
    for (auto id : *candidates)
      if (box.contains(mesh.nodes[id])) out.push_back(id);
  } else {
    for (std::int64_t id = 0; id < mesh.num_nodes(); ++id)
      if (box.contains(mesh.nodes[id])) out.push_back(id);
  }
  return out;
}

std::vector<std::int64_t> block_nodes(const Mesh& mesh, std::size_t b) {
  std::vector<std::int64_t> ids;
  ids.reserve(mesh.blocks[b].elements.size() * 8);
  for (const auto& h : mesh.blocks[b].elements) ids.insert(ids.end(), h.begin(), h.end());
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

} // namespace anvil
