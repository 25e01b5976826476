// Contact surfaces: the exterior faces of the solid parts (faces that belong to exactly
// one element of the whole mesh; quadrilaterals, and the triangles of wedges, pyramids
// and tetrahedra) and the nodes on them.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "anvil/mesh/mesh.hpp"

namespace anvil {

struct ExteriorFaces {
  // Face f: element `element[f]` (global id), its side `side[f]` (index into hex_faces),
  // nodes `nodes[f]` (global ids, counter-clockwise seen from outside; a triangle's third
  // node twice, at places 2 and 3, as face_nodes() gives them). Ordered by
  // (element, side): the position is the face's global id.
  std::vector<std::int64_t> element;
  std::vector<int> side;
  std::vector<std::array<std::int64_t, 4>> nodes;
  // The element across the face (global id): -1 for an exterior face; for a face that
  // erosion may expose, the element whose erosion does.
  std::vector<std::int64_t> behind;
  std::vector<std::int64_t> contact_nodes; // sorted, unique global ids of the faces' nodes

  std::size_t size() const { return element.size(); }
};

// The blocks of the named parts (all of them when `parts` is empty): a contact's surfaces.
std::vector<bool> blocks_named(const Mesh& mesh, const std::vector<std::string>& parts);

// Exterior faces of the blocks with `selected[b]` true. A face is exterior when no other
// element of the whole mesh (any block) has the same nodes (face_key). With `erodible` (per
// block; empty: none), also the faces between two elements of which one is erodible:
// the faces erosion may expose (LS-DYNA's eroding contact), `behind` their neighbour.
ExteriorFaces exterior_faces(const Mesh& mesh, const std::vector<bool>& selected,
                             const std::vector<bool>& erodible = {});

// Pairs of elements (global ids, the lower first, ascending, each once) of different
// bodies whose faces among `faces` come within a face's size of each other, each face
// linked to the nearest such face of another body (by centre): the bodies
// (the mesh's connected components, elements joined by shared nodes) that start close
// enough to meet soon. The static partition joins them (partition_elements' links), so
// that the elements of a contact interface tend to fall on one rank, as the contact
// decomposition's boxes put them; docs/cycle.md, "The decompositions".
std::vector<std::array<std::int64_t, 2>> links_between_bodies(const Mesh& mesh,
                                                              const ExteriorFaces& faces);

} // namespace anvil
