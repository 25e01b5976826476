// The particle phase allocates nothing in steady state (the rule for the hot cycle):
// after a few warm-up cycles, during which buffers grow to their working size, further
// calls of the SPH phase (upkeep, ghosts on P ranks, neighbours, both passes, material
// updates) for a particle model of two sets with plasticity and artificial stress make no
// C++ allocation. Particles that leave their box would legitimately grow the arrays that
// receive them, so the motion is slow. Tolerance: zero allocations.
// (test_cycle_allocations measures the whole step of an FE model in contact.)
#include <gtest/gtest.h>

#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

#include "allocation_counter.hpp"

namespace {

using namespace anvil;

TEST(SphAllocations, SteadyStateParticlePhaseAllocatesNothing) {
  const char* deck = R"(
termination: {cycles: 1000}
materials:
  rubber: {model: elastic, density: 1200, youngs_modulus: 1.0e7, poissons_ratio: 0.4}
  metal: {model: j2_plasticity, density: 7800, youngs_modulus: 2.0e11, poissons_ratio: 0.3,
          yield_stress: 1.0e6}
particles:
  a: {generate: {shape: box, min: [0, 0, 0], max: [0.01, 0.01, 0.01], spacing: 0.001},
      material: rubber}
  b: {generate: {shape: sphere, center: [0.005, 0.005, 0.0151], radius: 0.005, spacing: 0.001},
      material: metal, artificial_stress: {epsilon: 0.3}}
initial_conditions:
  - {part: b, velocity: [0, 0, -0.01]}
boundary_conditions:
  - {set: {part: a, box: {min: [-1, -1, -1], max: [1, 1, 0.001]}}, fix: all}
rigid_walls:
  - {point: [0, 0, -0.0001], normal: [0, 0, 1]}
probes:
  - {name: p, at: [0.005, 0.005, 0.01]}
)";
  const Config config = test::deck(deck);
  const Comm world = Comm::world();
  Simulation sim(config, world);
  for (int c = 0; c < 5; ++c) sim.step();
  PhaseTimers timers;
  sph::SphPhase& phase = *sim.sph();
  const double dt = sim.clock().dt_prev;
  phase.forces(dt, timers);
  const std::size_t before = g_allocations;
  for (int c = 0; c < 20; ++c) phase.forces(dt, timers);
  const std::size_t made = g_allocations - before;
  EXPECT_EQ(made, 0u) << "allocations in 20 steady-state particle phases on rank " << world.rank();
  EXPECT_GT(sim.sph()->stats().pairs, 0);
}

} // namespace
