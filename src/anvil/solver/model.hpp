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

} // namespace anvil
