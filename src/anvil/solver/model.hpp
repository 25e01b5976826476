// From configuration to the global mesh: generates or reads every part's mesh, appends
// them in deck order (the global node and element numbering), and resolves node
// selections against it.
#pragma once

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

// The static FE decomposition of the model (DESIGN.md section 1; `decomposition` in the
// deck): the owner rank of every element in global element order, the same on every
// rank. METIS k-way on the element dual graph (run on rank 0, its answer broadcast), or
// an RCB of the element centres in the deck's stretched coordinates; both weigh each
// element by its formulation's cost (element_cost), so that a thick-shell part and a
// solid part share the ranks by work, not by count. Collective.
std::vector<int> partition_model(const Mesh& mesh, const Config& config, const Comm& comm);

} // namespace anvil
