// The static FE decomposition's partitioner: METIS k-way on the element dual graph
// (elements adjacent through a face, and bodies about to meet), as the paper used Chaco.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "anvil/mesh/mesh.hpp"

namespace anvil {

// Owner part (0..parts-1) of every element in global element order. Deterministic for
// given input (fixed seed). With more parts than elements, element i goes to part i.
// `block_weight` (empty, or one positive value per mesh block) weighs each element of a
// block by its cost, so that the parts balance work instead of counts. `links` (pairs of
// global element ids) are edges of the graph besides the faces between elements
// (links_between_bodies: bodies about to meet); without them the partition is METIS's
// METIS_PartMeshDual.
std::vector<int> partition_elements(const Mesh& mesh, int parts,
                                    std::span<const int> block_weight = {},
                                    std::span<const std::array<std::int64_t, 2>> links = {});

// Number of face-adjacent element pairs whose parts differ (the edge cut).
long long partition_cut(const Mesh& mesh, const std::vector<int>& part);

} // namespace anvil
