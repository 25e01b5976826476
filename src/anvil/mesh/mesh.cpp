#include "anvil/mesh/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "anvil/core/hash.hpp"
#include "anvil/fe/hex8.hpp"

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

std::int64_t Mesh::append_nodes(const Mesh& other, const std::string& prefix) {
  const std::int64_t node_shift = num_nodes();
  // File ids where either mesh has them (a generated mesh's nodes: their position).
  if (!node_ids.empty() || !other.node_ids.empty()) {
    // (Our nodes without ids are generated ones: id = position + 1. node_id(n) would read
    // node_ids[n] once the first is pushed: past its end, ASan found, a generated part
    // before a file's with ids.)
    for (std::size_t n = node_ids.size(); n < nodes.size(); ++n)
      node_ids.push_back(static_cast<std::int64_t>(n) + 1);
    for (std::size_t n = 0; n < other.nodes.size(); ++n)
      node_ids.push_back(other.node_ids.empty() ? node_shift + static_cast<std::int64_t>(n) + 1
                                                : other.node_ids[n]);
  }
  nodes.insert(nodes.end(), other.nodes.begin(), other.nodes.end());
  auto name = [&](const std::string& s) { return prefix.empty() ? s : prefix + "." + s; };
  for (const auto& [k, ids] : other.node_sets) {
    auto& dst = node_sets[name(k)];
    for (auto id : ids) dst.push_back(id + node_shift);
    std::sort(dst.begin(), dst.end());
    dst.erase(std::unique(dst.begin(), dst.end()), dst.end());
  }
  return node_shift;
}

namespace {
bool without_repeats(std::vector<std::int64_t> ids) {
  std::sort(ids.begin(), ids.end());
  return std::adjacent_find(ids.begin(), ids.end()) == ids.end();
}
} // namespace

bool Mesh::node_ids_unique() const {
  return node_ids.empty() || without_repeats(node_ids);
}

bool Mesh::element_ids_unique() const {
  std::vector<std::int64_t> all;
  for (const auto& b : blocks)
    for (std::size_t e = 0; e < b.elements.size(); ++e) all.push_back(b.id(e));
  return without_repeats(std::move(all));
}

void Mesh::append(const Mesh& other, const std::string& prefix) {
  const std::int64_t elem_shift = num_elements();
  const std::int64_t node_shift = append_nodes(other, prefix);
  for (const auto& b : other.blocks) {
    ElementBlock nb{b.name, b.elements, b.ids};
    for (auto& h : nb.elements)
      for (auto& n : h) n += node_shift;
    blocks.push_back(std::move(nb));
  }
  auto name = [&](const std::string& s) { return prefix.empty() ? s : prefix + "." + s; };
  for (const auto& [k, sides] : other.side_sets) {
    auto& dst = side_sets[name(k)];
    for (auto s : sides) dst.push_back({s.element + elem_shift, s.face});
  }
}

void Mesh::translate(const Vec3& d) {
  for (auto& p : nodes) p += d;
}

std::string degenerate_hex(const Hex& nodes, std::int64_t id, int* corner) {
  for (int a = 0; a < 8; ++a)
    for (int k = 0; k < a; ++k)
      if (nodes[a] == nodes[k]) {
        if (corner) *corner = a;
        return fmt::format("element {} uses node {} twice (N{} and N{}): degenerate hexahedra "
                           "(wedges and tetrahedra written as hexahedra) are not supported",
                           id, nodes[a], k + 1, a + 1);
      }
  return {};
}

std::uint64_t mesh_fingerprint(const Mesh& mesh) {
  Fnv1a h;
  h.values(mesh.nodes);
  for (const auto& b : mesh.blocks) {
    const std::uint64_t n = b.elements.size();
    h.bytes(&n, sizeof n).values(b.elements);
  }
  return h.value();
}

namespace {

// Natural coordinates of the hexahedron's corners.
constexpr int corner_xi[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                 {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};

// det J of the trilinear map at the natural coordinates xi, from the corners' positions
// relative to the first (the same wherever the element sits).
double det_jacobian(const std::array<Vec3, 8>& x, const double (&xi)[3]) {
  const auto& s = corner_xi;
  double J[3][3] = {};
  for (int a = 0; a < 8; ++a) {
    double dN[3];
    for (int d = 0; d < 3; ++d) {
      dN[d] = 0.125 * s[a][d];
      for (int e = 0; e < 3; ++e)
        if (e != d) dN[d] *= (1 + s[a][e] * xi[e]);
    }
    for (int i = 0; i < 3; ++i)
      for (int d = 0; d < 3; ++d) J[i][d] += (x[a][i] - x[0][i]) * dN[d];
  }
  return hex8::determinant(J);
}

} // namespace

double hex_volume(const std::array<Vec3, 8>& x) {
  // det J of the trilinear map is of degree two in each parent coordinate, so the
  // 2x2x2 Gauss rule integrates it exactly.
  const auto& s = corner_xi;
  const double g = 1.0 / std::sqrt(3.0);
  double v = 0;
  for (int q = 0; q < 8; ++q) v += det_jacobian(x, {s[q][0] * g, s[q][1] * g, s[q][2] * g});
  return v;
}

double hex_centre_jacobian(const std::array<Vec3, 8>& x) {
  double xe[8][3];
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i) xe[a][i] = x[a][i] - x[0][i]; // (differences: see det_jacobian)
  return hex8::centre_jacobian(xe);
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
  // A mark per node, read in order: O(corners + nodes), no sort of the corners (QA round
  // 20: 0.5 s per part-scoped node set at 2 M elements, on every rank).
  std::vector<unsigned char> used(static_cast<std::size_t>(mesh.num_nodes()), 0);
  std::size_t count = 0;
  for (const auto& h : mesh.blocks[b].elements)
    for (const std::int64_t n : h) {
      count += used[static_cast<std::size_t>(n)] == 0;
      used[static_cast<std::size_t>(n)] = 1;
    }
  std::vector<std::int64_t> ids;
  ids.reserve(count);
  for (std::size_t n = 0; n < used.size(); ++n)
    if (used[n]) ids.push_back(static_cast<std::int64_t>(n));
  return ids;
}

namespace {

// turn[t][k]: the old corner that becomes corner k when the old axis t (0 xi, 1 eta)
// becomes zeta by a cyclic turn of the axes (t = 0: (xi, eta, zeta) -> (zeta, xi, eta)
// as new (xi', eta', zeta') = (eta, zeta, xi); t = 1: new (xi', eta', zeta') =
// (zeta, xi, eta)).
std::array<std::array<int, 8>, 2> corner_turns() {
  std::array<std::array<int, 8>, 2> turn{};
  for (int t = 0; t < 2; ++t)
    for (int k = 0; k < 8; ++k) {
      const int* c = corner_xi[k];
      const int old[3] = {t == 0 ? c[2] : c[1], t == 0 ? c[0] : c[2], t == 0 ? c[1] : c[0]};
      for (int a = 0; a < 8; ++a)
        if (corner_xi[a][0] == old[0] && corner_xi[a][1] == old[1] && corner_xi[a][2] == old[2])
          turn[t][k] = a;
    }
  return turn;
}

} // namespace

void orient_thickness_zeta(Mesh& mesh, std::size_t b) {
  const auto turn = corner_turns();
  // face_map[t][f]: the new number of old face f after turn t.
  std::array<std::array<int, 6>, 2> face_map{};
  for (int t = 0; t < 2; ++t)
    for (int f = 0; f < 6; ++f)
      for (int g = 0; g < 6; ++g) {
        std::array<int, 4> old{};
        for (int m = 0; m < 4; ++m) old[m] = turn[t][hex_faces[g][m]];
        std::sort(old.begin(), old.end());
        std::array<int, 4> mine = hex_faces[f];
        std::sort(mine.begin(), mine.end());
        if (old == mine) face_map[t][f] = g;
      }
  const std::int64_t first = mesh.block_offsets()[b];
  // The block's faces (sorted corner ids) that two of its elements share. A wall one
  // element thick has both faces of its thickness direction free, so its elements are
  // turned by the mesh, not by their sizes: a cube's three sizes tie, and round-off in
  // its corners would pick the thickness (QA round 7: on a wall of 2 mm cubes some
  // elements bent through their hourglass modes, 40% of the work).
  using FaceKey = std::array<std::int64_t, 4>;
  auto key = [](const Hex& h, int f) {
    FaceKey k;
    for (int m = 0; m < 4; ++m) k[m] = h[hex_faces[f][m]];
    std::sort(k.begin(), k.end());
    return k;
  };
  std::vector<FaceKey> faces;
  faces.reserve(6 * mesh.blocks[b].elements.size());
  for (const Hex& h : mesh.blocks[b].elements)
    for (int f = 0; f < 6; ++f) faces.push_back(key(h, f));
  std::sort(faces.begin(), faces.end());
  auto is_free = [&](const Hex& h, int f) {
    const auto [lo, hi] = std::equal_range(faces.begin(), faces.end(), key(h, f));
    return hi - lo == 1;
  };
  // Natural direction d's two faces (hex_faces: xi -+ 3, 1; eta -+ 0, 2; zeta -+ 4, 5).
  constexpr int side_faces[3][2] = {{3, 1}, {0, 2}, {4, 5}};
  std::vector<int> turned(mesh.blocks[b].elements.size(), -1);
  for (std::size_t e = 0; e < turned.size(); ++e) {
    Hex& h = mesh.blocks[b].elements[e];
    double len2[3] = {0, 0, 0};
    for (int d = 0; d < 3; ++d)
      for (int i = 0; i < 3; ++i) {
        double s = 0;
        for (int a = 0; a < 8; ++a) s += corner_xi[a][d] * mesh.nodes[h[a]][i];
        len2[d] += s * s;
      }
    bool through[3];
    int count = 0;
    for (int d = 0; d < 3; ++d) {
      through[d] = is_free(h, side_faces[d][0]) && is_free(h, side_faces[d][1]);
      count += through[d] ? 1 : 0;
    }
    // Directions left out are those with a face shared, where some direction has none.
    double l2[3];
    for (int d = 0; d < 3; ++d)
      l2[d] = count > 0 && !through[d] ? std::numeric_limits<double>::infinity() : len2[d];
    int t = -1;
    if (l2[0] < l2[2] && l2[0] <= l2[1])
      t = 0;
    else if (l2[1] < l2[2] && l2[1] < l2[0])
      t = 1;
    if (t < 0) continue;
    const Hex old = h;
    for (int k = 0; k < 8; ++k) h[k] = old[turn[t][k]];
    turned[e] = t;
  }
  for (auto& [name, sides] : mesh.side_sets)
    for (auto& s : sides) {
      const std::int64_t e = s.element - first;
      if (e >= 0 && e < static_cast<std::int64_t>(turned.size()) && turned[e] >= 0)
        s.face = face_map[turned[e]][s.face];
    }
}

} // namespace anvil
