// Exodus II reader: a hexahedral mesh file (.exo, .e, .g, .gen, .ex2) as a Mesh.
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
//   element e+1. HEX/HEX8 blocks are taken as they are; HEX20/HEX27 by their 8 corner
//   nodes (mid-side nodes stay in `nodes` but no element uses them). Any other type in
//   a non-empty block is an InputError naming the block and its type; empty blocks of
//   other types are skipped.
// - node sets as sorted unique ids, named from the file or "nodeset_<id>",
// - side sets as (element, face) with face = Exodus side - 1 (see hex_faces), in file
//   order, named from the file or "sideset_<id>".
// Every problem (not a regular file, unreadable file, not 3-D, ids out of range, duplicate
// set names) is an InputError naming `path`; the file is closed on every path out.
Mesh read_exodus(const std::string& path);

} // namespace anvil
