// The whole cycle allocates nothing in steady state (the rule for the hot cycle): after
// warm-up cycles, during which buffers grow to their working size, further steps of an
// FE model in contact (element forces, corner exchange, the contact decomposition's
// transfers, search and penalty forces, forces back to the owners, rigid wall, update)
// make no C++ allocation. The blocks are pressed together from the first cycle (the top
// of the upper one driven down), so that the contact pairs are present when counting. Tolerance:
// zero. The warm-up is 120 cycles: the contact phase's lazy cycles (ContactStats::lazy_cycles)
// leave the search's buffers at their size until the next full cycle, and the first full
// cycles after the start, where they grow, come at cycles 44 to 96 on two ranks. The
// counted cycles hold both kinds.
#include <gtest/gtest.h>

#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

#include "allocation_counter.hpp"

namespace {

using namespace anvil;

TEST(CycleAllocations, SteadyStateStepAllocatesNothing) {
  const char* deck = R"(
termination: {cycles: 1000}
materials:
  steel: {model: j2_plasticity, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3,
          yield_stress: 2.0e8}
parts:
  a:
    mesh: {generate: box, min: [0, 0, 0], max: [0.01, 0.01, 0.01], divisions: [6, 6, 6]}
    material: steel
  b:
    mesh: {generate: box, min: [0.002, 0.003, 0.01], max: [0.009, 0.011, 0.02], divisions: [5, 6, 6]}
    material: steel
initial_conditions:
  - {part: b, velocity: [0, 0, -20.0]}
boundary_conditions:
  - {set: b.zmax, velocity: [0, 0, -20.0]}
rigid_walls:
  - {point: [0, 0, 0], normal: [0, 0, 1]}
contact:
  - {type: general, parts: all}
probes:
  - {name: p, at: [0.005, 0.005, 0.01]}
)";
  const Config config = test::deck(deck);
  const Comm world = Comm::world();
  Simulation sim(config, world);
  for (int c = 0; c < 120; ++c) sim.step();
  const std::int64_t lazy = sim.contact()->stats().lazy_cycles;
  const std::size_t before = g_allocations;
  for (int c = 0; c < 80; ++c) sim.step();
  const std::size_t made = g_allocations - before;
  EXPECT_EQ(made, 0u) << "allocations in 80 steady-state cycles on rank " << world.rank();
  EXPECT_GT(sim.contact()->stats().pairs, 0) << "the blocks are in contact";
  const std::int64_t counted_lazy = sim.contact()->stats().lazy_cycles - lazy;
  EXPECT_GT(counted_lazy, 0) << "the counted cycles include lazy ones";
  EXPECT_LT(counted_lazy, 80) << "and full ones";
}

} // namespace
