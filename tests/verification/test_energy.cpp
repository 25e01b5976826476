// Free elastic vibration conserves energy. A free, unconstrained elastic block is given
// a non-uniform initial velocity (halves moving apart, the tip twisting); with the conservative
// (stiffness) hourglass control and no artificial viscosity the continuous problem
// conserves kinetic + internal + hourglass energy exactly, and central difference keeps
// it to O((omega dt)^2) (Belytschko, Liu and Moran, "Nonlinear Finite Elements for
// Continua and Structures", 2000, section 6.2.3). Tolerance: the total energy stays
// within 0.5% of its initial value over about 4 periods of the lowest mode, with no drift
// (the last period's mean within 0.1% of the first's).
#include <gtest/gtest.h>

#include <cmath>

#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

TEST(Energy, FreeVibrationConservesEnergy) {
  const char* deck = R"(
termination: {time: 4.0e-4}
materials:
  aluminium: {model: elastic, density: 2700, youngs_modulus: 70.0e9, poissons_ratio: 0.33}
parts:
  block:
    mesh: {generate: box, min: [0, -0.005, -0.005], max: [0.08, 0.005, 0.005], divisions: [16, 3, 3]}
    material: aluminium
    hourglass: {model: stiffness, coefficient: 0.05}
    bulk_viscosity: {linear: 0, quadratic: 0}
node_sets:
  right: {part: block, box: {min: [0.0399, -1, -1], max: [1, 1, 1]}}
  tip: {part: block, box: {min: [0.0599, -1, -1], max: [1, 1, 1]}}
initial_conditions:
  - {part: block, velocity: [0, 2.0, 1.0]}
  - {set: right, velocity: [0, -2.0, -1.0]}
  - {set: tip, velocity: [0, -2.0, -1.0], angular_velocity: [800.0, 0, 0], center: [0, 0, 0]}
)";
  const Comm world = Comm::world();
  Simulation sim(test::deck(deck), world);
  std::vector<double> t, e;
  while (!sim.finished()) {
    sim.step();
    const Sample s = sim.sample();
    t.push_back(s.time);
    e.push_back(s.total());
    ASSERT_EQ(s.external_work, 0.0);
  }
  const double e0 = e.front();
  double worst = 0;
  for (double v : e) worst = std::max(worst, std::abs(v - e0) / e0);
  EXPECT_LT(worst, 5e-3) << "largest relative deviation of the total energy";
  // Drift: compare the mean over the first and the last 10% of the run.
  const std::size_t w = e.size() / 10;
  double first = 0, last = 0;
  for (std::size_t k = 0; k < w; ++k) {
    first += e[k];
    last += e[e.size() - 1 - k];
  }
  EXPECT_LT(std::abs(last - first) / first, 1e-3) << "energy drift";
  // The motion really exchanged energy between kinetic and internal forms.
  const Sample s = sim.sample();
  EXPECT_GT(s.internal + s.hourglass, 0.05 * e0);
  if (world.rank() == 0)
    std::printf("energy: %zu cycles, largest deviation %.3e, drift %.3e, final KE %.4g J IE %.4g J "
                "HG %.4g J\n",
                e.size(), worst, (last - first) / first, s.kinetic, s.internal, s.hourglass);
}

} // namespace
