// Gmsh reader: a hexahedral mesh in the MSH 4.1 or 2.2 ASCII format as a Mesh.
#pragma once

#include <string>
#include <string_view>

#include "anvil/mesh/mesh.hpp"

namespace anvil {

// Parses the text of an MSH file; `name` is the file name used in error messages.
// - Nodes in the file's order (0-based position; Gmsh node tags may be sparse).
// - Hexahedra (type 5; types 17 and 12, the 20- and 27-node hexahedra, by their 8 corner
//   nodes, which come first in Gmsh's order) form one block per 3-D physical group, named
//   from $PhysicalNames or "volume_<tag>", in ascending physical tag, then a block "mesh"
//   for hexahedra in no physical group; elements keep the file's order within a block.
//   A volume in several 3-D groups puts its elements in the block of the lowest tag.
// - Every physical group gives a node set of all the nodes of its elements (any
//   dimension), named from $PhysicalNames or "point_<tag>", "curve_<tag>",
//   "surface_<tag>", "volume_<tag>". No side sets are made.
// - Any other 3-D element type, binary files, other versions, partitioned files,
//   references to undefined nodes or entities, wrong counts, bad numbers and missing
//   sections are InputErrors naming `name`, the line and the section.
// Never throws anything but InputError, whatever the text (fuzzing entry point).
Mesh parse_gmsh(std::string_view text, const std::string& name);

// Reads the file at `path` (an InputError if it is not a regular file) and parses it with
// parse_gmsh. A UTF-8 byte-order mark at the start of the text is skipped.
Mesh read_gmsh(const std::string& path);

} // namespace anvil
