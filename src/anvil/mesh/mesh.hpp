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

// Solids with fewer than eight corners are hexahedra whose nodes repeat (LS-DYNA's
// degenerate hexahedra), kept in one canonical form each, whose faces (hex_faces) are the
// solid's own: a triangle has its repeated node at places 2 and 3 once rotated by
// face_nodes(), and a face that collapses to an edge or a point is no face (face_key).
//   tetrahedron a b c d (a b c counter-clockwise seen from d):         a b c c d d d d
//   pyramid     base a b c d (counter-clockwise seen from apex e):     a b c d e e e e
//   wedge       a b c, d e f above them (a b c counter-clockwise seen
//               from d e f; edges a-d, b-e, c-f):                      a b c c d e f f
enum class Shape : std::uint8_t { hexahedron, wedge, pyramid, tetrahedron };
Hex tetrahedron_hex(std::int64_t a, std::int64_t b, std::int64_t c, std::int64_t d);
Hex pyramid_hex(std::int64_t a, std::int64_t b, std::int64_t c, std::int64_t d, std::int64_t e);
Hex wedge_hex(std::int64_t a, std::int64_t b, std::int64_t c, std::int64_t d, std::int64_t e,
              std::int64_t f);
// The canonical hexahedron of a solid from its corners `v` in the letters' order above
// (Exodus's and Gmsh's order; a hexahedron's 8 as they are), and their number.
Hex solid_hex(Shape s, const std::int64_t* v);
int corner_count(Shape s);
// The shape of a hexahedron in canonical form.
Shape shape_of(const Hex& h);
const char* shape_name(Shape s, bool plural = false); // "wedge", "wedges"
// The solid's own corners in VTK's order, into out[0..n), and its VTK cell type:
// hexahedron 12 (8 corners), wedge 13 (6: VTK's first triangle runs counter-clockwise
// seen from outside, so a c b, d f e), pyramid 14 (5), tetrahedron 10 (4).
int vtk_cell(const Hex& h, std::array<std::int64_t, 8>& out, int& n);

// Reads the eight nodes of a solid element as a mesh file gives them: eight different
// nodes are a hexahedron; repeated ones must follow one of LS-DYNA's patterns
// (tetrahedron N4 = N5 = ... = N8, pyramid N5 = ... = N8, pentahedron N5 = N6 and
// N7 = N8) or anvil's canonical forms above, and are rewritten into the canonical form.
// Returns why the element is refused (empty when it is read): "element 2 repeats nodes as
// no solid does (N3 = N7): ...". `id` is the file's element id for the message; `corner`
// (if given) gets the 0-based corner of the first repeat that does not fit.
std::string canonical_hex(Hex& nodes, std::int64_t id, int* corner = nullptr);

// Face f of h by its sorted distinct nodes, the missing ones -1 in front: two elements
// share a face when their keys are equal. is_face() is false for a face that collapsed
// to an edge or a point (fewer than 3 distinct nodes).
using FaceKey = std::array<std::int64_t, 4>;
FaceKey face_key(const Hex& h, int f);
FaceKey face_key(std::array<std::int64_t, 4> nodes); // of four nodes in any order
inline bool is_face(const FaceKey& k) {
  return k[1] >= 0;
}
// Face f of h, counter-clockwise seen from outside, in the order contact and pressure
// read it: a quadrilateral as hex_faces gives it, a triangle turned so that its repeated
// node is at places 2 and 3.
std::array<std::int64_t, 4> face_nodes(const Hex& h, int f);
std::array<std::int64_t, 4> face_nodes(const std::array<std::int64_t, 4>& q); // q in order

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
