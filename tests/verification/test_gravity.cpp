// Body loads (deck `gravity`, LS-DYNA *LOAD_BODY_X/Y/Z; docs/deck.md).
// 1. Free fall from rest (an FE block and an SPH cube). Reference: x(t) = x0 + g t^2 / 2,
//    v(t) = g t. Central difference with a constant step integrates a constant
//    acceleration exactly (x(n) = g (n dt)^2 / 2), so the tolerance is the round-off of the
//    position sums, cycles * ulp(largest coordinate); the kinetic energy equals the body
//    force's work m g . (x(n) - x(0)) at every row but the t = 0 row, the last included
//    (whose step is shortened to land on the end time, and whose v(n), the mean of the
//    half-step velocities around two unequal steps, is not g t: positions and velocities are
//    checked before it): tolerance the round-off of the work's sum, cycles * 2^-52 of the
//    kinetic energy, and for the velocity the round-off of its sums, cycles * ulp(g t).
// 2. A column standing on a fixed base, loaded by gravity that ramps up along a curve.
//    Reference: Newton's second law summed over the nodes, the internal forces cancelling:
//    over each step (the base's reaction + the weight) times the velocity interval is the
//    change of momentum, to round-off (tolerance 1e-9 of the weight's impulse per step).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>

#include "anvil/core/error.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

TEST(Gravity, FreeFallIsExactToRoundOff) {
  const double g = -9.81;
  const Comm world = Comm::world();
  Simulation sim(test::deck(R"(
termination: {time: 1.0e-3}
materials:
  steel: {model: elastic, density: 7800, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  block:
    mesh: {generate: box, min: [0, 0, 0], max: [0.01, 0.01, 0.01], divisions: [2, 2, 2]}
    material: steel
particles:
  cube: {generate: {shape: box, min: [0.02, 0, 0], max: [0.024, 0.004, 0.004], spacing: 1.0e-3},
         material: steel}
gravity: [0, 0, -9.81]
probes:
  - {name: node, at: [0, 0, 0]}
  - {name: particle, at: [0.0205, 0.0005, 0.0005]}
)"),
                 world);
  double worst_x = 0, worst_v = 0, worst_energy = 0, x_max = 0;
  std::int64_t cycles = 0;
  double last_energy = 0; // the last row's (its step shortened): the bookkeeping holds there too
  while (!sim.finished()) {
    sim.step();
    if (sim.finished()) {
      const Sample s = sim.sample();
      last_energy = std::abs(s.kinetic - s.external_work) / s.kinetic;
      break; // (the shortened last step: see the header)
    }
    const Sample s = sim.sample();
    // (t = 0: history.csv gives the deck's energies, and its probe velocities average the
    // deck's with the first step's, docs/deck.md "output".)
    if (s.cycle == 0) continue;
    cycles = s.cycle + 1;
    for (int p = 0; p < 2; ++p) {
      worst_x = std::max(worst_x, std::abs(s.probes[6 * p + 2] - 0.5 * g * s.time * s.time));
      worst_v = std::max(worst_v, std::abs(s.probes[6 * p + 5] - g * s.time));
    }
    x_max = std::max(x_max, std::abs(0.5 * g * s.time * s.time));
    worst_energy =
        std::max(worst_energy, std::abs(s.kinetic - s.external_work) / std::max(s.kinetic, 1e-300));
  }
  const double bound = static_cast<double>(cycles) * (std::nextafter(0.024, 1.0) - 0.024);
  EXPECT_LT(worst_x, bound);
  EXPECT_LT(worst_v, static_cast<double>(cycles) * (std::nextafter(0.01, 1.0) - 0.01));
  EXPECT_LT(worst_energy, static_cast<double>(cycles) * 0x1p-52);
  EXPECT_LT(last_energy, static_cast<double>(cycles) * 0x1p-52);
  if (world.rank() == 0)
    std::printf("free fall: %lld cycles, position error %.2e m (bound %.2e m, fall %.2e m), "
                "velocity error %.2e m/s, kinetic energy against the body force's work %.2e\n",
                static_cast<long long>(cycles), worst_x, bound, x_max, worst_v, worst_energy);
}

TEST(Gravity, BaseReactionAndWeightBalanceMomentum) {
  const Comm world = Comm::world();
  Simulation sim(test::deck(R"(
termination: {time: 2.0e-4}
materials:
  steel: {model: elastic, density: 7800, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  column:
    mesh: {generate: box, min: [0, 0, 0], max: [0.01, 0.01, 0.1], divisions: [2, 2, 20]}
    material: steel
boundary_conditions:
  - {set: column.zmin, fix: all}
gravity: {acceleration: [0, 0, -9.81], curve: [[0, 0], [5.0e-5, 1]]}
)"),
                 world);
  const double weight = 7800 * 0.01 * 0.01 * 0.1 * 9.81;
  double worst = 0, largest = 0, last_reaction = 0;
  while (!sim.finished()) {
    const double p0 = test::node_momentum(sim)[2], dt_before = sim.clock().dt, t = sim.clock().time;
    sim.step();
    const double dt_avg = 0.5 * (dt_before + sim.clock().dt);
    const Sample s = sim.sample();
    const double g = -9.81 * std::min(t / 5e-5, 1.0);
    const double impulse = (s.reaction[2] + g * weight / 9.81) * dt_avg;
    worst = std::max(worst, std::abs(impulse - (test::node_momentum(sim)[2] - p0)));
    largest = std::max(largest, weight * dt_avg);
    last_reaction = s.reaction[2];
  }
  EXPECT_LT(worst, 1e-9 * largest);
  if (world.rank() == 0)
    std::printf("gravity on a column: momentum balance %.2e N s (weight's impulse per step "
                "%.2e N s); base reaction at the end %.4g N, weight %.4g N\n",
                worst, largest, last_reaction, weight);
}

// A step that no longer advances the time stops the run with exit status 3 (QA round 23c:
// particles under a gravity of 1e308 looped for ever at a step of 0 s; minimum_fraction,
// 0 by default, was the only guard).
TEST(Gravity, AStepThatNoLongerAdvancesTheTimeStopsTheRun) {
  const Comm world = Comm::world();
  Simulation sim(test::deck(R"(
termination: {time: 1.0e-3}
materials:
  steel: {model: elastic, density: 7800, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
particles:
  cube: {generate: {shape: box, min: [0, 0, 0], max: [0.002, 0.002, 0.002], spacing: 1.0e-3},
         material: steel}
gravity: [0, 0, 1.0e308]
)"),
                 world);
  std::string message;
  try {
    for (int k = 0; k < 100000 && !sim.finished(); ++k) sim.step();
  } catch (const PhysicsError& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("too small to advance the time"), std::string::npos) << message;
}

} // namespace
