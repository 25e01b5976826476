// The nearest of a set of points to a query point, by a uniform grid of cells (about one
// point per cell), for the probes of history.csv: each query costs a few cells, not a
// pass over every point (QA round 20: 16,129 probes on 2 M nodes took 49 s).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "anvil/core/vec3.hpp"

namespace anvil {

class NearestGrid {
public:
  // The points `pick` of the arrays x, y, z (indices into them), with ids `id`.
  NearestGrid(const double* x, const double* y, const double* z, const std::int64_t* id,
              std::span<const int> pick);

  struct Hit {
    double r2;       // squared distance (infinity when there are no points)
    std::int64_t id; // the point's id: the lowest among those at the same distance
    int index;       // its index into the arrays, or -1
  };
  // The same answer as a pass over every point keeping the nearest, the lowest id on a
  // tie. `skip`: an index into the arrays that is not a candidate (a point's own, when
  // looking for its nearest neighbour).
  Hit nearest(const Vec3& q, int skip = -1) const;

private:
  const double *x_, *y_, *z_;
  const std::int64_t* id_;
  Vec3 lo_;
  double h_ = 1; // cell edge
  int n_[3] = {1, 1, 1};
  std::vector<int> start_; // cell c holds points_[start_[c], start_[c + 1])
  std::vector<int> points_;
  int cell_of(double v, int d) const;
};

} // namespace anvil
