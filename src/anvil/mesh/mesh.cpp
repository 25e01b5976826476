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

Hex tetrahedron_hex(std::int64_t a, std::int64_t b, std::int64_t c, std::int64_t d) {
  return {a, b, c, c, d, d, d, d};
}

Hex pyramid_hex(std::int64_t a, std::int64_t b, std::int64_t c, std::int64_t d, std::int64_t e) {
  return {a, b, c, d, e, e, e, e};
}

Hex wedge_hex(std::int64_t a, std::int64_t b, std::int64_t c, std::int64_t d, std::int64_t e,
              std::int64_t f) {
  return {a, b, c, c, d, e, f, f};
}

Hex solid_hex(Shape s, const std::int64_t* v) {
  switch (s) {
  case Shape::tetrahedron:
    return tetrahedron_hex(v[0], v[1], v[2], v[3]);
  case Shape::wedge:
    return wedge_hex(v[0], v[1], v[2], v[3], v[4], v[5]);
  case Shape::pyramid:
    return pyramid_hex(v[0], v[1], v[2], v[3], v[4]);
  case Shape::hexahedron:
    break;
  }
  return {v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]};
}

int corner_count(Shape s) {
  switch (s) {
  case Shape::tetrahedron:
    return 4;
  case Shape::pyramid:
    return 5;
  case Shape::wedge:
    return 6;
  case Shape::hexahedron:
    break;
  }
  return 8;
}

namespace {

// For each corner, the first corner with the same node.
std::array<int, 8> repeats(const Hex& h) {
  std::array<int, 8> rep{};
  for (int a = 0; a < 8; ++a) {
    rep[a] = a;
    for (int k = 0; k < a; ++k)
      if (h[a] == h[k]) {
        rep[a] = k;
        break;
      }
  }
  return rep;
}

constexpr std::array<int, 8> hexahedron_pattern = {0, 1, 2, 3, 4, 5, 6, 7};
constexpr std::array<int, 8> tetrahedron_pattern = {0, 1, 2, 2, 4, 4, 4, 4};
constexpr std::array<int, 8> pyramid_pattern = {0, 1, 2, 3, 4, 4, 4, 4};
constexpr std::array<int, 8> wedge_pattern = {0, 1, 2, 2, 4, 5, 6, 6};
// LS-DYNA's forms (*ELEMENT_SOLID): tetrahedron N1 N2 N3 N4 N4 N4 N4 N4, pentahedron
// N1 N2 N3 N4 N5 N5 N6 N6 (a wedge lying on its quadrilateral N1-N4; its triangles are
// N1 N2 N5 and N4 N3 N6).
constexpr std::array<int, 8> dyna_tetrahedron_pattern = {0, 1, 2, 3, 3, 3, 3, 3};
constexpr std::array<int, 8> dyna_pentahedron_pattern = {0, 1, 2, 3, 4, 4, 6, 6};

} // namespace

Shape shape_of(const Hex& h) {
  const auto rep = repeats(h);
  if (rep == tetrahedron_pattern) return Shape::tetrahedron;
  if (rep == pyramid_pattern) return Shape::pyramid;
  if (rep == wedge_pattern) return Shape::wedge;
  return Shape::hexahedron;
}

const char* shape_name(Shape s, bool plural) {
  switch (s) {
  case Shape::wedge:
    return plural ? "wedges" : "wedge";
  case Shape::pyramid:
    return plural ? "pyramids" : "pyramid";
  case Shape::tetrahedron:
    return plural ? "tetrahedra" : "tetrahedron";
  case Shape::hexahedron:
    break;
  }
  return plural ? "hexahedra" : "hexahedron";
}

int vtk_cell(const Hex& h, std::array<std::int64_t, 8>& out, int& n) {
  switch (shape_of(h)) {
  case Shape::tetrahedron:
    n = 4;
    out = {h[0], h[1], h[2], h[4]};
    return 10;
  case Shape::pyramid:
    n = 5;
    out = {h[0], h[1], h[2], h[3], h[4]};
    return 14;
  case Shape::wedge:
    n = 6;
    out = {h[0], h[2], h[1], h[4], h[6], h[5]};
    return 13;
  case Shape::hexahedron:
    break;
  }
  n = 8;
  out = h;
  return 12;
}

std::string canonical_hex(Hex& n, std::int64_t id, int* corner) {
  const auto rep = repeats(n);
  if (rep == hexahedron_pattern || rep == tetrahedron_pattern || rep == pyramid_pattern ||
      rep == wedge_pattern)
    return {};
  if (rep == dyna_tetrahedron_pattern) {
    n = tetrahedron_hex(n[0], n[1], n[2], n[3]);
    return {};
  }
  if (rep == dyna_pentahedron_pattern) {
    // Seen from outside the triangle N1 N2 N5 runs counter-clockwise, so from inside
    // (from N4 N3 N6) N1 N5 N2 does.
    n = wedge_hex(n[0], n[4], n[1], n[3], n[6], n[2]);
    return {};
  }
  std::string equal;
  int first = -1;
  for (int a = 0; a < 8; ++a)
    if (rep[a] != a) {
      if (first < 0) first = a;
      equal += fmt::format("{}N{} = N{}", equal.empty() ? "" : ", ", rep[a] + 1, a + 1);
    }
  if (corner) *corner = first;
  return fmt::format("element {} repeats nodes as no solid anvil reads does ({}; node {}): a "
                     "tetrahedron is N4 = N5 = N6 = N7 = N8 (or N3 = N4 and N5 = N6 = N7 = N8), "
                     "a pyramid N5 = N6 = N7 = N8, a pentahedron N5 = N6 and N7 = N8 (or N3 = N4 "
                     "and N7 = N8)",
                     id, equal, n[static_cast<std::size_t>(first)]);
}

FaceKey face_key(std::array<std::int64_t, 4> k) {
  std::sort(k.begin(), k.end());
  const auto end = std::unique(k.begin(), k.end());
  const auto distinct = end - k.begin();
  std::rotate(k.begin(), end, k.end()); // the distinct ones last
  std::fill(k.begin(), k.begin() + (4 - distinct), -1);
  return k;
}

FaceKey face_key(const Hex& h, int f) {
  const auto& q = hex_faces[static_cast<std::size_t>(f)];
  return face_key({h[q[0]], h[q[1]], h[q[2]], h[q[3]]});
}

std::array<std::int64_t, 4> face_nodes(const std::array<std::int64_t, 4>& q) {
  for (int k = 0; k < 4; ++k)
    if (q[k] == q[(k + 1) % 4]) { // a triangle (or less): its repeat to places 2 and 3
      std::array<std::int64_t, 4> r;
      for (int m = 0; m < 4; ++m) r[m] = q[(k + 2 + m) % 4];
      return r;
    }
  return q;
}

std::array<std::int64_t, 4> face_nodes(const Hex& h, int f) {
  const auto& q = hex_faces[static_cast<std::size_t>(f)];
  return face_nodes({h[q[0]], h[q[1]], h[q[2]], h[q[3]]});
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
  std::vector<FaceKey> faces;
  faces.reserve(6 * mesh.blocks[b].elements.size());
  for (const Hex& h : mesh.blocks[b].elements)
    for (int f = 0; f < 6; ++f) faces.push_back(face_key(h, f));
  std::sort(faces.begin(), faces.end());
  auto is_free = [&](const Hex& h, int f) {
    const auto [lo, hi] = std::equal_range(faces.begin(), faces.end(), face_key(h, f));
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
