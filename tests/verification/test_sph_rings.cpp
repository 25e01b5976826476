// Colliding rubber rings (Gray, Monaghan and Swift 2001, "SPH elastic dynamics", CMAME
// 190, section 6.2): two elastic rings, inner radius 3 cm, outer radius 4 cm, E = 1e7 Pa,
// nu = 0.4, rho = 1200 kg/m^3, each approaching the other at 0.059 c0 (c0 the bulk sound
// speed sqrt(K / rho): 6.96 m/s), in plane strain (`sph: {dimensions: 2}`), spacing
// 2 mm (5 particles across a ring, 1,100 particles), h = 1.3 spacing, viscosity alpha 1,
// beta 1, Monaghan's artificial stress epsilon 0.3, n 4 (without it the rings fracture
// through the tensile instability of Swegle, Hicks and Attaway 1995, which is the point
// of the test). Run to 14 ms: contact, rebound, separation.
// Tolerances (stated before the run): the rings bounce apart (their centre-of-mass
// velocities reversed); no fracture: no particle ends with fewer than half the
// same-ring neighbours (within 2 h0) it started with; energy (kinetic + internal, which
// holds the viscous heat) conserved within 1% of the initial kinetic energy.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

// All particles (x, y, set) on every rank (an allgather in rank order; small problem).
std::vector<double> all_positions(const Simulation& sim) {
  const Comm& comm = sim.comm();
  const auto& pt = sim.sph()->particles();
  std::vector<double> mine;
  for (std::size_t i = 0; i < pt.size(); ++i)
    mine.insert(mine.end(), {static_cast<double>(pt.gid[i]), pt.x[0][i], pt.x[1][i],
                             static_cast<double>(pt.set[i])});
  const auto counts = comm.allgather(static_cast<std::int64_t>(mine.size()));
  std::vector<double> all;
  for (int r = 0; r < comm.size(); ++r) {
    std::vector<double> b = r == comm.rank() ? mine : std::vector<double>(counts[r]);
    comm.broadcast(b, r);
    all.insert(all.end(), b.begin(), b.end());
  }
  // Ordered by gid, so that index = gid.
  std::vector<double> out(all.size());
  for (std::size_t k = 0; k < all.size(); k += 4) {
    const auto g = static_cast<std::size_t>(all[k]);
    std::copy(all.begin() + k, all.begin() + k + 4, out.begin() + 4 * g);
  }
  return out;
}

// Same-set neighbours within radius r of every particle.
std::vector<int> neighbour_counts(const std::vector<double>& p, double r) {
  const std::size_t n = p.size() / 4;
  std::vector<int> c(n, 0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      if (i == j || p[4 * i + 3] != p[4 * j + 3]) continue;
      const double dx = p[4 * i + 1] - p[4 * j + 1], dy = p[4 * i + 2] - p[4 * j + 2];
      if (dx * dx + dy * dy < r * r) ++c[i];
    }
  return c;
}

TEST(SphRings, RubberRingsBounceWithoutFracture) {
  const char* deck = R"(
termination: {time: 1.4e-2}
sph: {dimensions: 2}
materials:
  rubber: {model: elastic, density: 1200, youngs_modulus: 1.0e7, poissons_ratio: 0.4}
particles:
  ring_a: {generate: {shape: cylinder, origin: [-0.043, 0, 0], radius: 0.04, inner_radius: 0.03,
                      length: 0.002, axis: z, spacing: 0.002},
           material: rubber, smoothing_ratio: 1.3, viscosity: {linear: 1.0, quadratic: 1.0},
           artificial_stress: {epsilon: 0.3, exponent: 4}}
  ring_b: {generate: {shape: cylinder, origin: [0.043, 0, 0], radius: 0.04, inner_radius: 0.03,
                      length: 0.002, axis: z, spacing: 0.002},
           material: rubber, smoothing_ratio: 1.3, viscosity: {linear: 1.0, quadratic: 1.0},
           artificial_stress: {epsilon: 0.3, exponent: 4}}
initial_conditions:
  - {part: ring_a, velocity: [6.96, 0, 0]}
  - {part: ring_b, velocity: [-6.96, 0, 0]}
)";
  const Config config = test::deck(deck);
  const Comm world = Comm::world();
  Simulation sim(config, world);
  const double h0 = 1.3 * 0.002;
  const auto before = neighbour_counts(all_positions(sim), 2 * h0);
  double worst_balance = 0;
  while (!sim.finished()) {
    sim.step();
    if (sim.clock().cycle % 200 == 0)
      worst_balance = std::max(worst_balance, sim.balance_error(sim.sample()));
  }
  const Sample s = sim.sample();
  worst_balance = std::max(worst_balance, sim.balance_error(s));
  const auto after = neighbour_counts(all_positions(sim), 2 * h0);

  // Centre-of-mass velocity of each ring.
  const auto& pt = sim.sph()->particles();
  double m[4] = {0, 0, 0, 0};
  for (std::size_t i = 0; i < pt.size(); ++i) {
    m[2 * pt.set[i]] += pt.mass[i];
    m[2 * pt.set[i] + 1] += pt.mass[i] * pt.v[0][i];
  }
  world.sum(std::span<double>(m, 4));
  const double va = m[1] / m[0], vb = m[3] / m[2];
  double worst_ratio = 1e300;
  for (std::size_t i = 0; i < before.size(); ++i)
    worst_ratio = std::min(worst_ratio, static_cast<double>(after[i]) / before[i]);
  if (world.rank() == 0)
    std::printf("rings: centre velocities %.3f and %.3f m/s (from +-6.96), restitution %.3f, "
                "fewest neighbours kept %.2f, worst energy balance error %.2e, cycles %lld\n",
                va, vb, (vb - va) / (2 * 6.96), worst_ratio, worst_balance,
                static_cast<long long>(sim.clock().cycle));
  EXPECT_LT(va, 0.0);
  EXPECT_GT(vb, 0.0);
  EXPECT_GE(worst_ratio, 0.5);
  EXPECT_LT(worst_balance, 0.01);
}

} // namespace
