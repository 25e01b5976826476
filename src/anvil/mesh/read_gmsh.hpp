// Gmsh reader: a mesh of solids in the MSH 4.1 or 2.2 ASCII format as a Mesh.
#pragma once

#include <string>
#include <string_view>

#include "anvil/mesh/mesh.hpp"

namespace anvil {

// Parses the text of an MSH file; `name` is the file name used in error messages.
// - Nodes in the file's order (0-based position; Gmsh node tags may be sparse).
// - Solids form one block per 3-D physical group, named from $PhysicalNames or
//   "volume_<tag>", in ascending physical tag, then a block "mesh" for solids in no
//   physical group; elements keep the file's order within a block, whatever their type.
//   Hexahedra (type 5), tetrahedra (4), prisms (6) and pyramids (7), and their higher
//   orders by their corners (which Gmsh numbers first: hexahedra 17, 12, 92, 93,
//   tetrahedra 11, 29, 30, 31, prisms 18, 13, pyramids 19, 14). A tetrahedron, prism or
//   pyramid is its canonical degenerate hexahedron (tetrahedron_hex, wedge_hex,
//   pyramid_hex in mesh.hpp); a hexahedron that repeats nodes is rewritten by
//   canonical_hex or refused. A volume in several 3-D groups puts its elements in the
//   block of the lowest tag.
// - Every physical group gives a node set of all the nodes of its elements (any
//   dimension), named from $PhysicalNames or "point_<tag>", "curve_<tag>",
//   "surface_<tag>", "volume_<tag>". No side sets are made.
// - A solid naming a node twice (other than as canonical_hex allows), binary files,
//   other versions, partitioned files, references to undefined nodes or entities, wrong
//   counts, bad numbers and missing sections are InputErrors naming `name`, the line
//   and the section.
// Never throws anything but InputError, whatever the text (fuzzing entry point).
Mesh parse_gmsh(std::string_view text, const std::string& name);

// Reads the file at `path` (an InputError if it is not a regular file) and parses it with
// parse_gmsh. A UTF-8 byte-order mark at the start of the text is skipped.
Mesh read_gmsh(const std::string& path);

} // namespace anvil
