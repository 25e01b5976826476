#include "anvil/core/nearest.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace anvil {

NearestGrid::NearestGrid(const double* x, const double* y, const double* z, const std::int64_t* id,
                         std::span<const int> pick)
    : x_(x), y_(y), z_(z), id_(id) {
  if (pick.empty()) {
    start_.assign(2, 0);
    return;
  }
  Vec3 hi;
  lo_ = hi = Vec3{x[pick[0]], y[pick[0]], z[pick[0]]};
  for (int k : pick) {
    lo_ = {std::min(lo_.x, x[k]), std::min(lo_.y, y[k]), std::min(lo_.z, z[k])};
    hi = {std::max(hi.x, x[k]), std::max(hi.y, y[k]), std::max(hi.z, z[k])};
  }
  // Cells of edge h: the largest extent over cbrt(N) cells, so at most about N cells
  // whatever the shape (a plate or a line gets fewer, fuller cells).
  const double extent[3] = {hi.x - lo_.x, hi.y - lo_.y, hi.z - lo_.z};
  const double longest = std::max({extent[0], extent[1], extent[2]});
  const double per_side = std::max(1.0, std::floor(std::cbrt(static_cast<double>(pick.size()))));
  h_ = longest > 0 && std::isfinite(longest) ? longest / per_side : 1.0;
  for (int d = 0; d < 3; ++d)
    n_[d] = std::clamp(static_cast<int>(std::floor(extent[d] / h_)) + 1, 1, 1 << 20);
  const std::size_t cells = static_cast<std::size_t>(n_[0]) * n_[1] * n_[2];
  start_.assign(cells + 1, 0);
  std::vector<int> cell(pick.size());
  for (std::size_t j = 0; j < pick.size(); ++j) {
    const int k = pick[j];
    cell[j] = (cell_of(z[k], 2) * n_[1] + cell_of(y[k], 1)) * n_[0] + cell_of(x[k], 0);
    ++start_[static_cast<std::size_t>(cell[j]) + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
  points_.resize(pick.size());
  std::vector<int> fill(start_.begin(), start_.end() - 1);
  for (std::size_t j = 0; j < pick.size(); ++j)
    points_[static_cast<std::size_t>(fill[static_cast<std::size_t>(cell[j])]++)] = pick[j];
}

int NearestGrid::cell_of(double v, int d) const {
  const double lo = d == 0 ? lo_.x : (d == 1 ? lo_.y : lo_.z);
  const double c = std::floor((v - lo) / h_);
  if (!(c > 0)) return 0; // (NaN too)
  return c >= n_[d] - 1 ? n_[d] - 1 : static_cast<int>(c);
}

NearestGrid::Hit NearestGrid::nearest(const Vec3& q, int skip) const {
  Hit best{std::numeric_limits<double>::infinity(), std::numeric_limits<std::int64_t>::max(), -1};
  if (points_.empty()) return best;
  // The query's cell, clamped into the grid. Every cell at ring r + 1 or beyond (in the
  // cells' Chebyshev distance) is at least r h from the query, inside the grid or out of
  // it, so the search ends once (r h)^2 exceeds the best squared distance: points at
  // exactly that distance are still seen (the lowest id wins a tie).
  const int c0[3] = {cell_of(q.x, 0), cell_of(q.y, 1), cell_of(q.z, 2)};
  const int rings = std::max({n_[0], n_[1], n_[2]});
  for (int r = 0; r <= rings; ++r) {
    const double reach = (r - 1) * h_;
    if (r > 0 && reach > 0 && reach * reach > best.r2) break;
    int lo[3], hi[3];
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::max(c0[d] - r, 0);
      hi[d] = std::min(c0[d] + r, n_[d] - 1);
    }
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) {
          // Only the ring's own cells (the inner ones were searched before).
          if (std::max({std::abs(i - c0[0]), std::abs(j - c0[1]), std::abs(k - c0[2])}) != r)
            continue;
          const std::size_t c = (static_cast<std::size_t>(k) * n_[1] + j) * n_[0] + i;
          for (int s = start_[c]; s < start_[c + 1]; ++s) {
            const int p = points_[static_cast<std::size_t>(s)];
            if (p == skip) continue;
            const double dx = x_[p] - q.x, dy = y_[p] - q.y, dz = z_[p] - q.z;
            const double r2 = dx * dx + dy * dy + dz * dz;
            if (r2 < best.r2 || (r2 == best.r2 && id_[p] < best.id)) best = {r2, id_[p], p};
          }
        }
  }
  return best;
}

} // namespace anvil
