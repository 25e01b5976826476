// Exodus II reader: a mesh file of solids (.exo, .e, .g, .gen, .ex2) as a Mesh.
#pragma once

#include <string>

#include "anvil/mesh/mesh.hpp"

namespace anvil {

// Reads the mesh in the Exodus II file at `path` (netCDF classic or netCDF-4):
// - nodes in the file's order (0-based position), their ids from the node id map in
//   Mesh::node_ids (empty without one); an id <= 0 there or in the element id map is an
//   InputError,
// - one ElementBlock per element block, in file order, named from the file or
//   "block_<id>"; elements keep the file's order, so global element e is the file's
//   element e+1. HEX/HEX8 blocks are taken as they are (a hexahedron that repeats nodes
//   is rewritten by canonical_hex, or refused); TETRA/TETRA4, WEDGE/WEDGE6 and
//   PYRAMID/PYRAMID5 elements become their canonical degenerate hexahedra
//   (tetrahedron_hex, wedge_hex, pyramid_hex in mesh.hpp), which may mix with hexahedra
//   in a file. Higher orders are read by their corners (HEX20, HEX27, TETRA8, TETRA10,
//   TETRA14, TETRA15, WEDGE15, WEDGE16, WEDGE18, PYRAMID13, PYRAMID14; mid-side nodes
//   stay in `nodes` but no element uses them). The type is known by its first three
//   letters in any case, as the Exodus library knows it. Any other type in a non-empty
//   block is an InputError naming the block and its type; empty blocks of other types
//   are skipped.
// - node sets as sorted unique ids, named from the file or "nodeset_<id>",
// - side sets as (element, face), in file order, named from the file or "sideset_<id>":
//   face = Exodus side - 1 for a hexahedron (see hex_faces); for a tetrahedron, wedge or
//   pyramid, and a hexahedron that canonical_hex renumbered, the face of the canonical
//   hexahedron with the side's nodes (face_key). A side beyond the solid's (a tetrahedron
//   has 4, a wedge and a pyramid 5) or one that collapses is an InputError.
// Every problem (not a regular file, unreadable file, not 3-D, ids out of range, duplicate
// set names) is an InputError naming `path`; the file is closed on every path out.
Mesh read_exodus(const std::string& path);

} // namespace anvil
