// The contact phase allocates nothing in steady state (the rule for the hot cycle): on
// the can crush once the block is on the rim (pairs found), further detections and force
// passes (packing, plans, search over the candidate lists, penalty forces, return to the
// owners) make no C++ allocation. The state is not advanced, so the lists and plans are
// reused; their rebuilds reuse the buffers too but may legitimately grow them. Tolerance:
// zero allocations.
#include <gtest/gtest.h>

#include <cstdlib>
#include <new>

#include "anvil/contact/contact_phase.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/solver/can_crush.hpp"
#include "anvil/solver/simulation.hpp"

// Counts C++ allocations of this executable (MPI's own mallocs are not counted).
std::size_t g_allocations = 0;
void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}

namespace {

using namespace anvil;

TEST(ContactAllocations, SteadyStateContactPhaseAllocatesNothing) {
  CanCrushOptions o;
  o.ranks = 1; // the same one-rank model on every rank count
  const Comm world = Comm::world();
  Simulation sim(can_crush_config(o), world);
  for (int c = 0; c < 450; ++c) sim.step();
  ContactPhase& phase = *sim.contact();
  const NodeState& n = sim.nodes();
  std::array<std::vector<double>, 3> force;
  for (auto& f : force) f.assign(n.size(), 0.0);
  const ContactNodes view{{n.x[0].data(), n.x[1].data(), n.x[2].data()},
                          {n.v[0].data(), n.v[1].data(), n.v[2].data()},
                          n.mass.data(),
                          {force[0].data(), force[1].data(), force[2].data()}};
  PhaseTimers timers;
  const double dt = sim.clock().dt;
  phase.detect(view, dt, timers);
  phase.forces(view, dt, timers);
  const std::size_t before = g_allocations;
  for (int c = 0; c < 20; ++c) {
    phase.detect(view, dt, timers);
    phase.forces(view, dt, timers);
  }
  const std::size_t made = g_allocations - before;
  EXPECT_EQ(made, 0u) << "allocations in 20 steady-state contact phases on rank " << world.rank();
  EXPECT_GT(phase.stats().pairs, 0);
}

} // namespace
