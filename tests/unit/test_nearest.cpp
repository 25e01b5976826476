// NearestGrid (the probes' search) against a pass over every point: the same point for
// every query, on clouds, a flat plate, a line, coincident points (the lowest id wins),
// queries far outside the points, and no points at all.
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <vector>

#include "anvil/core/nearest.hpp"

namespace {

using namespace anvil;

struct Cloud {
  std::vector<double> x, y, z;
  std::vector<std::int64_t> id;
  void add(double a, double b, double c, std::int64_t i) {
    x.push_back(a);
    y.push_back(b);
    z.push_back(c);
    id.push_back(i);
  }
};

NearestGrid::Hit brute(const Cloud& c, const std::vector<int>& pick, const Vec3& q) {
  NearestGrid::Hit best{std::numeric_limits<double>::infinity(),
                        std::numeric_limits<std::int64_t>::max(), -1};
  for (int k : pick) {
    const double dx = c.x[k] - q.x, dy = c.y[k] - q.y, dz = c.z[k] - q.z;
    const double r2 = dx * dx + dy * dy + dz * dz;
    if (r2 < best.r2 || (r2 == best.r2 && c.id[k] < best.id)) best = {r2, c.id[k], k};
  }
  return best;
}

void expect_same(const Cloud& c, const std::vector<int>& pick, std::mt19937& rng, double spread) {
  const NearestGrid grid(c.x.data(), c.y.data(), c.z.data(), c.id.data(), pick);
  std::uniform_real_distribution<double> u(-spread, spread);
  for (int t = 0; t < 300; ++t) {
    // Queries on the points themselves (as the keyword probes are), and anywhere.
    const Vec3 q = t % 3 == 0 && !pick.empty()
                       ? Vec3{c.x[pick[t % pick.size()]], c.y[pick[t % pick.size()]],
                              c.z[pick[t % pick.size()]]}
                       : Vec3{u(rng), u(rng), u(rng)};
    const auto a = grid.nearest(q), b = brute(c, pick, q);
    ASSERT_EQ(a.index, b.index) << "query " << q.x << " " << q.y << " " << q.z;
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.r2, b.r2);
  }
}

TEST(NearestGrid, SameAsAPassOverEveryPoint) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  Cloud cloud, plate, line;
  for (int i = 0; i < 2000; ++i) {
    cloud.add(u(rng), u(rng), 0.2 * u(rng), 3 * i + 7);
    plate.add(u(rng), u(rng), 0.5, i);
    line.add(0, 0, u(rng), i);
  }
  // Coincident points with different ids: the lowest id wins wherever it lies.
  for (int i = 0; i < 50; ++i) cloud.add(cloud.x[i], cloud.y[i], cloud.z[i], 100000 - i);
  for (int i = 0; i < 50; ++i) cloud.add(cloud.x[i], cloud.y[i], cloud.z[i], i);
  std::vector<int> all(cloud.x.size()), every(plate.x.size()), half;
  for (std::size_t k = 0; k < all.size(); ++k) all[k] = static_cast<int>(k);
  for (std::size_t k = 0; k < every.size(); ++k) every[k] = static_cast<int>(k);
  for (std::size_t k = 0; k < all.size(); k += 2) half.push_back(static_cast<int>(k));
  for (double spread : {1.0, 20.0}) { // inside the points' box, and far around it
    expect_same(cloud, all, rng, spread);
    expect_same(cloud, half, rng, spread); // a subset (a rank's owned nodes)
    expect_same(plate, every, rng, spread);
    expect_same(line, every, rng, spread);
  }
  Cloud one;
  one.add(1, 2, 3, 9);
  expect_same(one, {0}, rng, 10.0);
  const NearestGrid none(one.x.data(), one.y.data(), one.z.data(), one.id.data(), {});
  EXPECT_EQ(none.nearest({0, 0, 0}).index, -1);
}

} // namespace
