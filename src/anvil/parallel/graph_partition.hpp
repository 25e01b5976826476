// The static FE decomposition's partitioner: METIS k-way on the element dual graph
// (elements adjacent through a face), as the paper used Chaco.
#pragma once

#include <vector>

#include "anvil/mesh/mesh.hpp"

namespace anvil {

// Owner part (0..parts-1) of every element in global element order. Deterministic for
// given input (fixed seed). With more parts than elements, element i goes to part i.
std::vector<int> partition_elements(const Mesh& mesh, int parts);

// Number of face-adjacent element pairs whose parts differ (the edge cut).
long long partition_cut(const Mesh& mesh, const std::vector<int>& part);

} // namespace anvil
