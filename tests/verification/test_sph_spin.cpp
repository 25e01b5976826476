// A free elastic SPH ball spinning about its centre (QA round 14). Reference: with no
// external moment the angular momentum is conserved, and a rigid rotation strains nothing,
// so the only stress is the centrifugal one, of order rho w^2 R^2 (a solid sphere's
// largest, (3 + nu) / 8 rho w^2 R^2, is 0.41 of that). The normalised gradient
// (`corrected_gradient: true`, Randles and Libersky 1996) reproduces the linear velocity
// field of a rotation at every particle, the free surface included (Bonet and Lok 1999).
// Aluminium ball, R 5 mm, spacing 1 mm (552 particles), w 1e4 rad/s, run 0.15 ms (1.5 rad).
// Tolerances (stated before the run): L_z within 1e-4 of its initial value (the half-step
// offset of v against x aside, the pair forces conserve it); the largest von Mises stress
// below rho w^2 R^2 = 6.75 MPa.
// The plain gradient is run beside it to record the limit docs/sph.md states (and the
// setup warns of): measured 0.35 L0 left at 0.15 ms, von Mises ~300 MPa. The test checks
// that it still loses at least 10% of L0, so that a change that cures the plain gradient
// shows up here and the docs' limit and the warning are revisited.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

struct SpinResult {
  double l0, l, max_von_mises;
  std::size_t warnings;
};

SpinResult spin(bool corrected) {
  const std::string deck = std::string(R"(
termination: {time: 1.5e-4}
materials:
  al: {model: elastic, density: 2700, youngs_modulus: 70.0e9, poissons_ratio: 0.3}
particles:
  ball:
    generate: {shape: sphere, center: [0, 0, 0], radius: 5.0e-3, spacing: 1.0e-3}
    material: al
    corrected_gradient: )") +
                           (corrected ? "true" : "false") + R"(
initial_conditions:
  - {part: ball, angular_velocity: [0, 0, 10000.0], center: [0, 0, 0]}
)";
  const Comm world = Comm::world();
  Simulation sim(test::deck(deck), world);
  auto angular_momentum = [&] {
    const auto& pt = sim.sph()->particles();
    double l = 0;
    for (std::size_t i = 0; i < pt.size(); ++i)
      l += pt.mass[i] * (pt.x[0][i] * pt.v[1][i] - pt.x[1][i] * pt.v[0][i]);
    return world.sum(l);
  };
  SpinResult r{angular_momentum(), 0, 0, sim.warnings().size()};
  while (!sim.finished()) sim.step();
  r.l = angular_momentum();
  const auto& pt = sim.sph()->particles();
  for (std::size_t i = 0; i < pt.size(); ++i) {
    const auto& s = pt.stress;
    const double vm = std::sqrt(0.5 * ((s[0][i] - s[1][i]) * (s[0][i] - s[1][i]) +
                                       (s[1][i] - s[2][i]) * (s[1][i] - s[2][i]) +
                                       (s[2][i] - s[0][i]) * (s[2][i] - s[0][i])) +
                                3 * (s[3][i] * s[3][i] + s[4][i] * s[4][i] + s[5][i] * s[5][i]));
    r.max_von_mises = std::max(r.max_von_mises, vm);
  }
  r.max_von_mises = world.max(r.max_von_mises);
  if (world.rank() == 0)
    std::printf("sph spin (%s gradient): L/L0 = %.9f, largest von Mises %.3g MPa\n",
                corrected ? "normalised" : "plain", r.l / r.l0, r.max_von_mises * 1e-6);
  return r;
}

TEST(SphSpin, NormalisedGradientKeepsTheSpin) {
  const SpinResult r = spin(true);
  EXPECT_LT(std::abs(r.l / r.l0 - 1), 1e-4);
  EXPECT_LT(r.max_von_mises, 2700 * 1e8 * 25e-6);
  EXPECT_EQ(r.warnings, 0u);
}

TEST(SphSpin, PlainGradientLosesTheSpinAndWarns) {
  const SpinResult r = spin(false);
  EXPECT_LT(r.l / r.l0, 0.9);
  EXPECT_EQ(r.warnings, 1u);
}

} // namespace
