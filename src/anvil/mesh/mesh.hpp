// Mesh: the global description of the finite-element model as read or generated, before
// it is distributed. Nodes are numbered 0..N-1 (the global node id), elements are
// numbered across blocks in block order (the global element id). Every sum over
// elements in the solver runs in ascending global element id (DESIGN.md section 3).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "anvil/core/vec3.hpp"

namespace anvil {

// Hexahedron node order (Exodus, VTK and Flanagan-Belytschko alike): nodes 0-3 around
// the bottom face counter-clockwise seen from above, 4-7 the top face above them.
using Hex = std::array<std::int64_t, 8>;

// Local node numbers of the six faces, each counter-clockwise seen from outside
// (outward normal by the right-hand rule). Face order is Exodus's side numbering
// minus one: sides 1-4 around the element, 5 bottom, 6 top.
inline constexpr std::array<std::array<int, 4>, 6> hex_faces = {
    {{0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}, {0, 3, 2, 1}, {4, 5, 6, 7}}};

struct ElementBlock {
  std::string name;          // part name (deck) or block name (mesh file)
  std::vector<Hex> elements; // connectivity by global node id
  // The mesh file's id of each element (LS-DYNA EID, Gmsh tag, Exodus elem_num_map),
  // for messages; empty for a generated mesh, whose elements are 1, 2, ... in order.
  std::vector<std::int64_t> ids;

  std::int64_t id(std::size_t e) const {
    return ids.empty() ? static_cast<std::int64_t>(e) + 1 : ids[e];
  }
};

struct SideEntry {
  std::int64_t element; // global element id
  int face;             // 0..5, see hex_faces
};

struct Mesh {
  std::vector<Vec3> nodes; // coordinates by global id
  // The mesh file's id of each node (LS-DYNA NID, Gmsh tag, Exodus node_num_map), for the
  // outputs' id arrays; empty for a generated mesh, whose nodes are 1, 2, ... in order.
  std::vector<std::int64_t> node_ids;
  std::vector<ElementBlock> blocks;                           // in global element order
  std::map<std::string, std::vector<std::int64_t>> node_sets; // sorted, unique node ids
  std::map<std::string, std::vector<SideEntry>> side_sets;

  std::int64_t num_nodes() const { return static_cast<std::int64_t>(nodes.size()); }
  std::int64_t node_id(std::size_t n) const {
    return node_ids.empty() ? static_cast<std::int64_t>(n) + 1 : node_ids[n];
  }
  std::int64_t num_elements() const;
  // Global id of the first element of each block, plus the total at the end.
  std::vector<std::int64_t> block_offsets() const;

  // Appends `other` after this mesh (nodes and elements renumbered after ours). Its
  // blocks keep their names; its sets are renamed `prefix.SET` unless prefix is empty.
  void append(const Mesh& other, const std::string& prefix);
  // Appends the nodes of `other` (with their file ids and node sets, renamed as by
  // append()) and returns the global id its first node takes here.
  std::int64_t append_nodes(const Mesh& other, const std::string& prefix);
  // Whether the file ids of the nodes, and of the elements of every block together, are
  // each without repeats (models assembled from several files may repeat them).
  bool node_ids_unique() const;
  bool element_ids_unique() const;

  // Moves every node by `d`.
  void translate(const Vec3& d);
};

// Why a hexahedron that names a node twice is refused, or an empty string when its eight
// nodes differ: "element 2 uses node 11 twice (N7 and N8): degenerate hexahedra ... are
// not supported". `nodes` and `id` are numbered as in the file; `corner` (if given) gets
// the 0-based corner of the repeat. Every mesh reader checks its elements with it.
std::string degenerate_hex(const Hex& nodes, std::int64_t id, int* corner = nullptr);

// A hash of the nodes' coordinates (their bits) and of every block's connectivity, in
// global id order: equal for equal meshes, whoever computes it. A checkpoint carries it.
std::uint64_t mesh_fingerprint(const Mesh& mesh);

// Signed volume of a hexahedron (exact for the trilinear map).
double hex_volume(const std::array<Vec3, 8>& x);
// det J of the trilinear map at the hexahedron's centre (V / 8 on a parallelepiped): the
// one-point element's volume measure, which a tangled element's volume can hide.
double hex_centre_jacobian(const std::array<Vec3, 8>& x);

// Sorted, unique ids of the nodes inside `box` (boundary included), optionally only
// among `candidates` (sorted); an empty candidate list means all nodes.
std::vector<std::int64_t> select_nodes(const Mesh& mesh, const Box3& box,
                                       const std::vector<std::int64_t>* candidates = nullptr);

// Turns every element of block `b` so that its thickness direction is its zeta axis: the
// natural direction whose two faces are both on the block's surface (shared with no other
// element of the block), where exactly one is, as through a wall one element thick;
// otherwise the thinnest of those directions (or of all three where none is), by the
// smallest column of the Jacobian at the centre, ties kept in the order zeta, xi, eta.
// The corners are renumbered by a cyclic turn of the natural axes, which keeps the
// element's orientation and its node set. The thick-shell element integrates through
// zeta (docs/element.md). Side sets on the block follow the new face numbers.
void orient_thickness_zeta(Mesh& mesh, std::size_t b);

// Sorted, unique ids of the nodes used by the elements of block `b`.
std::vector<std::int64_t> block_nodes(const Mesh& mesh, std::size_t b);

} // namespace anvil
