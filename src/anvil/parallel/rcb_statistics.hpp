// Statistics of an RCB decomposition as JSON (for `anvil decompose` and the benchmarks).
#pragma once

#include <nlohmann/json.hpp>

#include "anvil/parallel/rcb.hpp"

namespace anvil {

// Summary of the last partition of `rcb`, identical on every rank (no communication):
//   ranks, points, counts[rank], weights[rank], imbalance (max weight / mean weight),
//   count_imbalance (max count / mean count), points_moved, incremental,
//   iterations[level], total_iterations,
//   domain {lo, hi} (bounding box of the points),
//   boxes[rank] {lo, hi}: each rank's box clipped to the domain (JSON has no infinity),
//   cuts[m - 1] {split, level, dim, value, gid (null when the cut is a plain plane)}.
nlohmann::json rcb_statistics(const Rcb& rcb);

} // namespace anvil
