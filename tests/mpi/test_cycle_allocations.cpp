// The whole cycle allocates nothing in steady state (the rule for the hot cycle): after
// warm-up cycles, during which buffers grow to their working size, further steps of an
// FE model in contact (element forces, external loads (a pressure and nodal forces), corner
// exchange, the contact decomposition's transfers, search and penalty forces, forces back
// to the owners, rigid wall, update) make no C++ allocation. Tolerance: zero.
//
// The model must be steady for that to mean anything: a buffer that follows the model
// (pairs, ghosted faces, a rank's share of the contact items) grows each
// time the model passes its largest size so far, and a crush that keeps growing its
// contact region (the blocks driven together) would keep doing so, on three or four ranks
// hundreds of cycles later than on one. Here the upper block, its top face held, is thrown
// down at 20 m/s onto the lower one, which rests on a rigid wall; both are elastic, so
// they bounce against each other indefinitely (a period of about 60 cycles), and the
// contact opens and closes every period: the counted cycles hold cycles with and without
// pairs, with sizes that the warm-up has already seen. The warm-up is 400 cycles: on 4
// ranks the last growth is at cycle 285. The warm-up holds full contact cycles (on one
// rank only the first; plan rebuilds in the counted cycles are the next test's); the
// counted cycles are lazy: each
// face's bound follows its own reference (translations exactly), and these blocks
// oscillate well inside the lists' skin, so neither the lists nor the destinations need
// rebuilding in steady state.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>

#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

#include "allocation_counter.hpp"

namespace {

using namespace anvil;

TEST(CycleAllocations, SteadyStateStepAllocatesNothing) {
  const char* deck = R"(
termination: {cycles: 2000}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
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
  - {set: b.zmax, velocity: [0, 0, 0]}
loads:
  - {surface: a.xmax, pressure: 1.0e5, curve: [[0, 0], [1.0e-5, 1]]}
  - {set: a.ymin, force: [0, 1.0e-3, 0]}
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
  for (int c = 0; c < 400; ++c) sim.step();
  const ContactStats start = sim.contact()->stats();
  std::int64_t most_pairs = 0, fewest_pairs = -1;
  const std::size_t before = g_allocations;
  for (int c = 0; c < 400; ++c) {
    sim.step();
    const std::int64_t p = sim.contact()->stats().pairs;
    most_pairs = std::max(most_pairs, p);
    fewest_pairs = fewest_pairs < 0 ? p : std::min(fewest_pairs, p);
  }
  const std::size_t made = g_allocations - before;
  EXPECT_EQ(made, 0u) << "allocations in 400 steady-state cycles on rank " << world.rank();
  const ContactStats& end = sim.contact()->stats();
  EXPECT_GT(most_pairs, 0) << "the blocks come into contact";
  EXPECT_EQ(fewest_pairs, 0) << "and separate";
  const std::int64_t counted_lazy = end.lazy_cycles - start.lazy_cycles;
  EXPECT_GT(counted_lazy, 0) << "the counted cycles include lazy ones";
  EXPECT_LT(start.lazy_cycles, 400) << "the warm-up full ones";
}

// The full contact cycle allocates nothing either. The test above counts lazy cycles only:
// its blocks oscillate inside the lists' skin. Here the counted cycles rebuild the
// candidate lists (a full cycle: every capture box, the exact search, budgets back to the
// senders, subset plans) and, on several ranks, the destinations and migration plans:
// the upper block, its top face held in y and z, shuttles along x over the lower one
// between two rigid walls (x = 0 and x = 12 mm: 0.6 mm of travel; thrown at 50 m/s, about
// 20 m/s after the first impacts, a round trip every few hundred cycles), so its nodes
// slide past the lower block's faces by several skins per traverse and cross the contact
// RCB's cuts. The facing surfaces are 0.05 mm apart, less than the lists' skin, and no
// pair forms (the penalty forces are the test above's). (In touch, the bounce against the lower
// block and the shuttle are two incommensurate motions, and the pairs' per-rank counts, with them
// the force plan's size, kept passing their largest so far thousands of cycles in; apart, the sizes
// follow the shuttle alone and the last growth is at cycle 332 on 4 ranks.) The lower block's
// bottom and the upper block's top are held in y, else the blocks drift sideways and the sizes
// never settle. Warm-up 800 cycles, 400 counted.
TEST(CycleAllocations, SlidingFullCyclesAllocateNothing) {
  const char* deck = R"(
termination: {cycles: 2000}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  a:
    mesh: {generate: box, min: [0, 0, 0], max: [0.012, 0.01, 0.005], divisions: [8, 6, 4]}
    material: steel
  b:
    mesh: {generate: box, min: [0.0003, 0.002, 0.00505], max: [0.0117, 0.008, 0.0101], divisions: [10, 4, 4]}
    material: steel
initial_conditions:
  - {part: b, velocity: [50.0, 0, 0]}
boundary_conditions:
  - {set: a.zmin, fix: [y]}
  - {set: b.zmax, velocity: [0, 0, 0], components: [y, z]}
rigid_walls:
  - {point: [0, 0, 0], normal: [0, 0, 1]}
  - {point: [0, 0, 0], normal: [1, 0, 0]}
  - {point: [0.012, 0, 0], normal: [-1, 0, 0]}
contact:
  - {type: general, parts: all}
probes:
  - {name: p, at: [0.006, 0.005, 0.01]}
)";
  const Config config = test::deck(deck);
  const Comm world = Comm::world();
  Simulation sim(config, world);
  for (int c = 0; c < 800; ++c) sim.step();
  const ContactStats start = sim.contact()->stats();
  const std::size_t before = g_allocations;
  for (int c = 0; c < 400; ++c) sim.step();
  const std::size_t made = g_allocations - before;
  EXPECT_EQ(made, 0u) << "allocations in 400 sliding cycles on rank " << world.rank();
  const ContactStats& end = sim.contact()->stats();
  const std::int64_t counted_lazy = end.lazy_cycles - start.lazy_cycles;
  EXPECT_LT(counted_lazy, 400) << "the counted cycles include full ones";
  EXPECT_GT(end.list_builds, start.list_builds) << "and list rebuilds on rank " << world.rank();
  if (world.size() > 1) EXPECT_GT(end.plan_builds, start.plan_builds) << "and plan rebuilds";
}
// Rigid bodies: the cycle's gathers of their points (one in predict, one more in correct
// with contact) allocate nothing once their buffers have their size (QA round 29: 800
// allocations in 400 cycles, Comm::allgatherv_bytes's counts, before). A rigid striker
// spins 0.1 mm above a deformable block in general contact: both gathers run every cycle,
// and the contact's own buffers, which grow with the pairs (the first test's subject),
// keep their size. Warm-up 200 cycles, 200 counted. Tolerance: zero.
TEST(CycleAllocations, RigidBodiesAllocateNothing) {
  const char* deck = R"(
termination: {cycles: 1000}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  block:
    mesh: {generate: box, min: [0, 0, 0], max: [0.01, 0.01, 0.004], divisions: [5, 5, 2]}
    material: steel
  striker:
    mesh: {generate: box, min: [0.003, 0.003, 0.0041], max: [0.007, 0.007, 0.008], divisions: [2, 2, 2]}
    material: steel
    rigid: true
initial_conditions:
  - {part: striker, velocity: [0, 0, 0], angular_velocity: [0, 0, 100.0],
     center: [0.005, 0.005, 0.006]}
boundary_conditions:
  - {set: block.zmin, fix: [z]}
contact:
  - {type: general}
)";
  const Comm world = Comm::world();
  Simulation sim(test::deck(deck), world);
  for (int c = 0; c < 200; ++c) sim.step();
  const std::size_t before = g_allocations;
  for (int c = 0; c < 200; ++c) sim.step();
  EXPECT_EQ(g_allocations - before, 0u) << "allocations in 200 cycles on rank " << world.rank();
}

} // namespace
