// SPH neighbour lists (src/anvil/sph/neighbours.hpp): the neighbours filtered from the
// candidate (Verlet) half lists are exactly the pairs with r_ij < h_i + h_j at the current
// positions that concern an own particle, each once in the row of its lower global id,
// rows and entries in ascending global id, whatever the positions and the radius of the
// candidates' build (as long as the candidates hold every such pair). This is what makes
// the particle phase's results independent of when the lists were built (a restart builds
// them afresh) and of the rank count. Reference: a brute-force search over all pairs.
// Tolerance: exact equality of the lists.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "anvil/core/simd.hpp"
#include "anvil/sph/neighbours.hpp"

namespace {

using namespace anvil::sph;

struct alignas(32) Xh {
  double x[3], h;
};

struct Cloud {
  std::vector<double> x, y, z, h;
  std::vector<std::int64_t> gid;
  std::vector<Xh> xh;
  void pack() {
    xh.resize(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) xh[i] = {{x[i], y[i], z[i]}, h[i]};
  }
};

// A jittered lattice of n^3 particles, spacing 1, h about 1.2, ids shuffled.
Cloud make_cloud(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3), hs(1.1, 1.3);
  Cloud c;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        c.x.push_back(i + jitter(rng));
        c.y.push_back(j + jitter(rng));
        c.z.push_back(k + jitter(rng));
        c.h.push_back(hs(rng));
      }
  c.gid.resize(c.x.size());
  for (std::size_t i = 0; i < c.gid.size(); ++i) c.gid[i] = static_cast<std::int64_t>(i);
  std::shuffle(c.gid.begin(), c.gid.end(), rng);
  c.pack();
  return c;
}

// Brute force: the pairs within the support of which i or j is own (i < n_own), in the
// row of the lower gid; rows (in ascending gid) and entries in ascending gid.
struct Rows {
  std::vector<int> particle;
  std::vector<std::vector<int>> list;
};
Rows brute(const Cloud& c, std::size_t n_own) {
  const std::size_t n = c.x.size();
  Rows rows;
  for (std::size_t i = 0; i < n; ++i) rows.particle.push_back(static_cast<int>(i));
  auto by_gid = [&](int a, int b) {
    return c.gid[static_cast<std::size_t>(a)] < c.gid[static_cast<std::size_t>(b)];
  };
  std::sort(rows.particle.begin(), rows.particle.end(), by_gid);
  for (const int ii : rows.particle) {
    const auto i = static_cast<std::size_t>(ii);
    std::vector<int> row;
    for (std::size_t j = 0; j < n; ++j) {
      if (c.gid[j] <= c.gid[i] || (i >= n_own && j >= n_own)) continue;
      const double dx = c.x[i] - c.x[j], dy = c.y[i] - c.y[j], dz = c.z[i] - c.z[j];
      const double s = c.h[i] + c.h[j];
      if (dx * dx + dy * dy + dz * dz < s * s) row.push_back(static_cast<int>(j));
    }
    std::sort(row.begin(), row.end(), by_gid);
    rows.list.push_back(row);
  }
  return rows;
}

void expect_lists(const NeighbourList& nl, const Rows& ref) {
  ASSERT_EQ(nl.len.size(), ref.list.size());
  ASSERT_EQ(nl.row, ref.particle);
  std::size_t total = 0;
  for (std::size_t r = 0; r < ref.list.size(); ++r) {
    const int i = ref.particle[r];
    ASSERT_EQ(nl.start[r] % anvil::simd::width, 0);
    ASSERT_EQ(nl.len[r], static_cast<int>(ref.list[r].size())) << "particle " << i;
    for (std::size_t k = 0; k < ref.list[r].size(); ++k)
      ASSERT_EQ(nl.index[static_cast<std::size_t>(nl.start[r]) + k], ref.list[r][k])
          << "particle " << i;
    // Padding: the particle itself, up to the next row.
    for (auto k = nl.start[r] + nl.len[r]; k < nl.start[r + 1]; ++k)
      ASSERT_EQ(nl.index[static_cast<std::size_t>(k)], i);
    ASSERT_LT(nl.start[r + 1] - nl.start[r] - nl.len[r], anvil::simd::width);
    total += ref.list[r].size();
  }
  EXPECT_EQ(nl.pairs(), total);
}

TEST(SphNeighbours, FilteredCandidatesAreTheExactPairsInGidOrder) {
  Cloud c = make_cloud(9, 1);
  const std::size_t n_own = c.x.size() - 100; // the rest act as ghosts
  const double hmax = *std::max_element(c.h.begin(), c.h.end());
  NeighbourWorkspace work;
  NeighbourList cand, nl;
  find_candidates(c.x, c.y, c.z, c.gid, n_own, 2 * hmax * 1.2, work, cand);
  filter_neighbours(c.xh.data()->x, 4, cand, nl);
  expect_lists(nl, brute(c, n_own));
}

// Candidates built at other positions, with other radii, give the same neighbours once
// filtered at the current positions: the lists do not depend on when they were built.
TEST(SphNeighbours, IndependentOfTheBuild) {
  const Cloud now = make_cloud(8, 2);
  const std::size_t n_own = now.x.size() - 50;
  const auto ref = brute(now, n_own);
  const double hmax = *std::max_element(now.h.begin(), now.h.end());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> move(-0.1, 0.1);
  for (const double skin : {0.15, 0.2, 0.5}) {
    // The build's positions: each particle up to 0.1 * sqrt(3) away from its current one.
    Cloud then = now;
    for (std::size_t i = 0; i < then.x.size(); ++i) {
      then.x[i] += move(rng);
      then.y[i] += move(rng);
      then.z[i] += move(rng);
    }
    const double dmax = 0.1 * std::sqrt(3.0);
    const double radius = std::max(2 * hmax * (1 + skin), 2 * hmax + 2 * dmax);
    NeighbourWorkspace work;
    NeighbourList cand, nl;
    find_candidates(then.x, then.y, then.z, then.gid, n_own, radius, work, cand);
    filter_neighbours(now.xh.data()->x, 4, cand, nl);
    expect_lists(nl, ref);
  }
}

} // namespace
