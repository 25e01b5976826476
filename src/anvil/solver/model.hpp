// From configuration to the global mesh: generates or reads every part's mesh, appends
// them in deck order (the global node and element numbering), and resolves node
// selections against it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "anvil/io/config.hpp"
#include "anvil/mesh/mesh.hpp"
#include "anvil/parallel/comm.hpp"

namespace anvil {

// The whole model's mesh, block i = part i, sets renamed PART.SET.
Mesh build_mesh(const Config& config);

// Sorted global node ids of a selection; an InputError (at the selection's deck
// location) if it names an unknown set or selects nothing.
std::vector<std::int64_t> resolve_selection(const Mesh& mesh, const Config& config,
                                            const Selection& sel);

// The faces of a pressure load's surface, ascending (element, face): the side set of that
// name if the mesh has one, else the faces of the model's surface (exterior faces, those of
// the selection's part only if it names one) whose four nodes the node selection holds. An
// InputError (at the selection's deck location) if there is none.
std::vector<SideEntry> resolve_surface(const Mesh& mesh, const Config& config,
                                       const Selection& sel);

// For each point, the smallest global id of an element of `blocks` that holds it inside
// the body (behind the plane of each of its six faces, through the face's centre with the
// normal of its diagonals, by more than 1e-6 of the element's size where the face bounds
// the blocks: a point on the body's surface is not inside, one on a face between two
// elements is; nor is a point within 1e-6 of a face's size of a face bounding the holding
// element's block, which tetrahedra and wedges reach by a corner or an edge only), leaving
// out the elements of which it is a corner (`node[i]`: the point's
// global node id, or -1 for a particle); -1 where none does. The points are binned on a
// grid of the elements' mean size; exact for flat faces, a warning's accuracy for warped
// ones.
std::vector<std::int64_t> elements_holding(const Mesh& mesh, std::span<const std::size_t> blocks,
                                           std::span<const Vec3> points,
                                           std::span<const std::int64_t> node);

// The static FE decomposition of the model (DESIGN.md section 1; `decomposition` in the
// deck): the owner rank of every element in global element order, the same on every
// rank. METIS k-way on the element dual graph (run on rank 0, its answer broadcast), or
// an RCB of the element centres in the deck's stretched coordinates; both weigh each
// element by its formulation's cost (element_cost), so that a thick-shell part and a
// solid part share the ranks by work, not by count. Collective.
// With METIS the graph also links the elements of bodies in contact that start within a
// face's size of each other (contact_body_links).
std::vector<int> partition_model(const Mesh& mesh, const Config& config, const Comm& comm);

// The links between bodies of the deck's contact (links_between_bodies of its parts'
// exterior faces); none without contact.
std::vector<std::array<std::int64_t, 2>> contact_body_links(const Mesh& mesh, const Config& config);

} // namespace anvil
