// Checks the serial side of Rcb and Migration on one rank (Comm::self): the tree's split
// rule; a one-rank partition owns everything, its box is all of space and its domain the
// bounding box; invalid input (mismatched lengths, a NaN coordinate, a negative or
// infinite weight) throws instead of partitioning; repartition without previous cuts is
// a scratch partition; a one-rank Migration is the identity both ways; the statistics JSON.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "anvil/parallel/comm.hpp"
#include "anvil/parallel/migration.hpp"
#include "anvil/parallel/rcb.hpp"
#include "anvil/parallel/rcb_statistics.hpp"

namespace {

using namespace anvil;

TEST(RcbSerial, SplitRule) {
  EXPECT_EQ(Rcb::split(0, 2), 1);
  EXPECT_EQ(Rcb::split(0, 3), 1); // lower side takes the smaller half
  EXPECT_EQ(Rcb::split(1, 3), 2);
  EXPECT_EQ(Rcb::split(0, 8), 4);
  EXPECT_EQ(Rcb::split(3, 8), 5);
}

TEST(RcbSerial, OneRankOwnsEverything) {
  const Comm self = Comm::self();
  const std::vector<double> x{0, 1, 2}, y{5, -1, 0}, z{0, 0, 3};
  const std::vector<std::int64_t> gid{7, 8, 9};
  Rcb rcb(self);
  rcb.partition({x, y, z, gid, {}});
  ASSERT_EQ(rcb.destinations().size(), 3u);
  for (int d : rcb.destinations()) EXPECT_EQ(d, 0);
  EXPECT_EQ(rcb.count(0), 3);
  EXPECT_EQ(rcb.stats().points, 3);
  EXPECT_EQ(rcb.stats().points_moved, 0);
  EXPECT_DOUBLE_EQ(rcb.stats().imbalance, 1.0);
  EXPECT_EQ(rcb.domain().lo, (Vec3{0, -1, 0}));
  EXPECT_EQ(rcb.domain().hi, (Vec3{2, 5, 3}));
  const Box3 b = rcb.box(0);
  EXPECT_EQ(b.lo.x, -std::numeric_limits<double>::infinity());
  EXPECT_EQ(b.hi.z, std::numeric_limits<double>::infinity());
  EXPECT_EQ(rcb.owner(Vec3{1e300, -1e300, 0}), 0);
  std::vector<int> out{42};
  rcb.overlapping(Box3{{0, 0, 0}, {1, 1, 1}}, out);
  EXPECT_EQ(out, std::vector<int>{0});

  rcb.repartition({x, y, z, gid, {}});
  EXPECT_FALSE(rcb.stats().incremental); // nothing to reuse on one rank
  const auto j = rcb_statistics(rcb);
  EXPECT_EQ(j["counts"], nlohmann::json::array({3}));
  EXPECT_EQ(j["cuts"].size(), 0u);
}

TEST(RcbSerial, InvalidInputThrows) {
  const Comm self = Comm::self();
  Rcb rcb(self);
  const std::vector<double> x{0, 1}, y{0, 1}, z{0, 1}, short_z{0};
  const std::vector<std::int64_t> gid{1, 2};
  EXPECT_THROW(rcb.partition({x, y, short_z, gid, {}}), std::invalid_argument);
  const std::vector<double> nan_x{0, std::nan("")};
  EXPECT_THROW(rcb.partition({nan_x, y, z, gid, {}}), std::invalid_argument);
  const std::vector<double> negative{1, -1}, infinite{1, std::numeric_limits<double>::infinity()};
  EXPECT_THROW(rcb.partition({x, y, z, gid, negative}), std::invalid_argument);
  EXPECT_THROW(rcb.partition({x, y, z, gid, infinite}), std::invalid_argument);
  EXPECT_NO_THROW(rcb.partition({x, y, z, gid, {}}));
}

TEST(MigrationSerial, OneRankIsTheIdentity) {
  const Comm self = Comm::self();
  Migration plan;
  const std::vector<int> dest(5, 0);
  plan.build(self, dest);
  EXPECT_EQ(plan.send_count(), 5u);
  EXPECT_EQ(plan.recv_count(), 5u);
  const std::vector<double> a{1, -0.0, 3, std::nan("7"), 5};
  std::vector<double> b, c;
  plan.forward(a, b);
  plan.reverse(b, c);
  ASSERT_EQ(c.size(), a.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), 5 * sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(a.data(), c.data(), 5 * sizeof(double)), 0);
  EXPECT_THROW(plan.build(self, std::vector<int>{0, 1}), std::invalid_argument);
}

} // namespace
