// Particle-to-mesh contact (the paper's coupling of SPH to the FE mesh; Attaway,
// Heinstein and Swegle 1994): an SPH copper sphere (radius 2 mm, spacing 0.4 mm, 500
// particles) strikes a free FE steel plate (10 x 10 x 2 mm, 10 x 10 x 4 hexahedra) at
// 200 m/s; the particles are contact nodes against the plate's faces, with penalty forces
// returned to them. Nothing holds the plate, so the total momentum (nodes and particles)
// is conserved: penalty pair forces are equal and opposite (Newton's third law, the
// node's force against -N_a F on the face's nodes), the element and SPH pair forces sum
// to zero. Tolerances (stated before the run): total momentum conserved to 1e-10 of the
// initial momentum (round-off); the plate takes at least 5% of the momentum (the contact
// acted); no particle gets through the plate (all above its mid-plane); energy balance
// error below 2%. Run on 1 and 3 ranks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

TEST(SphImpact, ProjectileOnPlateConservesMomentum) {
  const char* deck = R"(
termination: {time: 8.0e-6}
materials:
  copper: {model: j2_plasticity, density: 8930, youngs_modulus: 117.0e9,
           poissons_ratio: 0.35, yield_stress: 0.4e9, hardening_modulus: 0.1e9}
  steel: {model: elastic, density: 7830, youngs_modulus: 200.0e9, poissons_ratio: 0.29}
parts:
  plate:
    mesh: {generate: box, min: [-0.005, -0.005, -0.002], max: [0.005, 0.005, 0.0], divisions: [10, 10, 4]}
    material: steel
particles:
  ball: {generate: {shape: sphere, center: [0, 0, 2.1e-3], radius: 2.0e-3, spacing: 4.0e-4},
         material: copper, smoothing_ratio: 1.3}
initial_conditions:
  - {part: ball, velocity: [0, 0, -200.0]}
contact:
  - {type: general, parts: all, penalty_scale: 0.1}
)";
  const Config config = test::deck(deck);
  const Comm world = Comm::world();
  Simulation sim(config, world);
  // Momentum of owned nodes and own particles; [3] the plate's z part.
  auto momentum = [&](double P[4]) {
    for (int k = 0; k < 4; ++k) P[k] = 0;
    const auto& nd = sim.nodes();
    for (std::size_t n = 0; n < nd.size(); ++n)
      if (sim.fe().node_owned[n]) {
        for (int k = 0; k < 3; ++k) P[k] += nd.mass[n] * nd.v[k][n];
        P[3] += nd.mass[n] * nd.v[2][n];
      }
    const auto& pt = sim.sph()->particles();
    for (std::size_t i = 0; i < pt.size(); ++i)
      for (int k = 0; k < 3; ++k) P[k] += pt.mass[i] * pt.v[k][i];
    world.sum(std::span<double>(P, 4));
  };
  double P0[4], P[4];
  momentum(P0);
  double worst = 0;
  while (!sim.finished()) {
    sim.step();
    momentum(P);
    for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(P[k] - P0[k]) / std::abs(P0[2]));
  }
  double lowest = 1e300;
  const auto& pt = sim.sph()->particles();
  for (std::size_t i = 0; i < pt.size(); ++i) lowest = std::min(lowest, pt.x[2][i]);
  lowest = world.min(lowest);
  const Sample s = sim.sample();
  const double balance = sim.balance_error(s);
  if (world.rank() == 0)
    std::printf(
        "sph impact: momentum drift %.2e of P0, plate took %.1f%%, lowest particle %.3f mm, "
        "contact pairs %lld, energy balance error %.2e, cycles %lld\n",
        worst, 100 * P[3] / P0[2], lowest * 1e3,
        static_cast<long long>(sim.contact()->stats().pairs), balance,
        static_cast<long long>(sim.clock().cycle));
  EXPECT_LT(worst, 1e-10);
  EXPECT_GT(P[3] / P0[2], 0.05);
  EXPECT_GT(lowest, -1.0e-3);
  EXPECT_LT(balance, 0.02);
}

// Light particles on a stiff face: an ideal gas (50 kg/m^3, 0.5 mm spacing: 6e-9 kg a
// particle) at 100 m/s onto a clamped 1 mm steel plate. The face's penalty stiffness
// (0.1 K A^2 / V = 1.6e7 N/m) gives k dt^2 / m = 21 at the gas's step, past central
// difference's limit of 4: the contact rang and created energy (balance error 0.87,
// measured before the stiffness cap of penalty.hpp). Reference: conservation of energy;
// tolerance 2% on the balance error (the cap dissipates nothing by itself). Run on 1 and
// 3 ranks.
TEST(SphImpact, GasOnClampedPlateStaysStable) {
  const char* deck = R"(
termination: {time: 2.0e-5}
materials:
  gas: {model: ideal_gas, density: 50.0, gamma: 1.4, specific_energy: 2.0e5}
  steel: {model: elastic, density: 7830, youngs_modulus: 200.0e9, poissons_ratio: 0.29}
parts:
  plate:
    mesh: {generate: box, min: [-0.004, -0.004, -0.001], max: [0.004, 0.004, 0.0], divisions: [8, 8, 1]}
    material: steel
    hourglass: {model: stiffness, coefficient: 0.05}
particles:
  g: {generate: {shape: box, min: [-0.003, -0.003, 0.0002], max: [0.003, 0.003, 0.0032], spacing: 5.0e-4},
      material: gas, smoothing_ratio: 1.3, artificial_stress: {epsilon: 0.0}}
initial_conditions:
  - {part: g, velocity: [0, 0, -100.0]}
boundary_conditions:
  - {set: plate.zmin, fix: all}
contact:
  - {type: general, parts: all, penalty_scale: 0.1, friction: 0.1}
)";
  const Comm world = Comm::world();
  Simulation sim(test::deck(deck), world);
  double worst = 0;
  while (!sim.finished()) {
    sim.step();
    worst = std::max(worst, sim.balance_error(sim.sample()));
  }
  if (world.rank() == 0)
    std::printf("gas on plate: worst energy balance error %.2e over %lld cycles\n", worst,
                static_cast<long long>(sim.clock().cycle));
  EXPECT_LT(worst, 0.02);
}

} // namespace
