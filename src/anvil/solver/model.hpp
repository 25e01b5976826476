// From configuration to the global mesh: generates or reads every part's mesh, appends
// them in deck order (the global node and element numbering), and resolves node
// selections against it.
#pragma once

#include <vector>

#include "anvil/io/config.hpp"
#include "anvil/mesh/mesh.hpp"

namespace anvil {

// The whole model's mesh, block i = part i, sets renamed PART.SET.
Mesh build_mesh(const Config& config);

// Sorted global node ids of a selection; an InputError (at the selection's deck
// location) if it names an unknown set or selects nothing.
std::vector<std::int64_t> resolve_selection(const Mesh& mesh, const Config& config,
                                            const Selection& sel);

// The static FE decomposition of the model (DESIGN.md section 1): the owner rank of every
// element in global element order, METIS k-way on the element dual graph with each
// element weighted by its formulation's cost (element_cost), so that a thick-shell part
// and a solid part share the ranks by work, not by count.
std::vector<int> partition_model(const Mesh& mesh, const Config& config, int parts);

} // namespace anvil
