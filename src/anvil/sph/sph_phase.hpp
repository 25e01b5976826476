// The paper's SPH decomposition (cycle step 2): particles live on their own dynamic RCB
// decomposition, independent of the FE mesh's. Each rank holds the particles that were
// inside its RCB box at the last list rebuild (ascending global id) for the whole cycle:
// the particle phase, the velocity and position updates and contact all work on them
// where they are.
//
// Every cycle: (1) upkeep: one reduction tells the largest particle count (the RCB is
// recut incrementally when max/mean exceeds the threshold, and every particle migrates
// to its new owner), whether any particle left its box (on a rebuild those migrate to
// the rank whose box now holds them), the largest h and the largest displacement since
// the candidate lists were built; (2) ghosts: on a rebuild (after a recut, or when a
// particle may have come within the support of one its lists miss) every particle whose box of the
// candidate radius (2 h_max plus a skin) reaches beyond its rank's box is copied to each
// rank whose box it overlaps (Rcb::overlapping), by a Migration plan kept until the next
// rebuild; every cycle the copies' state moves along it; (3) on a rebuild, candidate
// lists by cell lists; (4) pass 1 (the neighbours among the candidates, kinematics,
// stresses) on own particles; (5) the ghosts' new stresses, densities and wave speeds
// along the same plan; (6) pass 2 (forces). Ghost copies hold the same bits as their
// originals and every neighbour sum runs in ascending global id over exactly the pairs
// within the support, so the results depend neither on the number of ranks (DESIGN.md
// section 3) nor on when the lists were built.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "anvil/core/timer.hpp"
#include "anvil/io/config.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/parallel/migration.hpp"
#include "anvil/parallel/rcb.hpp"
#include "anvil/sph/forces.hpp"
#include "anvil/sph/neighbours.hpp"
#include "anvil/sph/particles.hpp"

namespace anvil::sph {

struct SphStats {
  std::int64_t cycles = 0;
  std::int64_t rebalances = 0; // RCB recuts (the first partition included)
  std::int64_t migrations = 0; // cycles on which escaped particles moved
  std::int64_t ghosts = 0;     // ghost copies received, this rank, last cycle
  std::int64_t pairs = 0; // neighbour pairs with an own particle (each once), this rank, last cycle
  std::int64_t list_builds = 0; // cycles on which the candidate lists and ghost plan were built
  double imbalance = 1;         // last cycle's max/mean particle count
  double imbalance_max = 1;     // the largest seen
  double seconds_rebalance = 0; // this rank: RCB recuts
  double seconds_migrate = 0;   // this rank: moving particles to new owners
  double seconds_ghosts = 0;    // this rank: ghost selection and both exchanges
  double seconds_compute = 0;   // this rank: neighbour search and the two passes
};

class SphPhase {
public:
  // Generates every particle set of the deck on every rank (deterministic), keeps an
  // even share by global id, partitions by RCB and moves each particle to its box's
  // rank. material(set) gives the material of a particle set (not owned, outlives this).
  // Throws InputError (every rank) for inconsistent sets. Collective.
  SphPhase(const Config& config, const std::function<const Material*(int)>& material,
           const Comm& comm);

  // Cycle step 2: decomposition upkeep, ghosts, both passes; fills particles().f (N)
  // at the current positions from velocities v(n-1/2), advancing density, stress and
  // energy over dt_prev (s). Reports the stable step and failures in result() (local;
  // the caller reduces). Collective.
  void forces(double dt_prev, PhaseTimers& timers);

  Particles& particles() { return p_; }
  const Particles& particles() const { return p_; }
  // Energy rate of viscosity and artificial stress per own particle (J/(kg s)), from the
  // last forces(): the caller adds rate * (velocity step) to the specific energy.
  std::span<const double> energy_rate() const { return energy_rate_; }
  const SphResult& result() const { return result_; }
  const SphStats& stats() const { return stats_; }
  std::span<const SetParams> sets() const { return sets_; }
  const Rcb& rcb() const { return rcb_; }
  std::int64_t global_count() const { return global_count_; }
  // First global id of each set, and the total at the end.
  const std::vector<std::int64_t>& set_offsets() const { return set_offsets_; }
  // What the setup found that the user should know (warnings, the same on every rank).
  const std::vector<std::string>& notes() const { return notes_; }
  // The step the particles take at their first cycle if no pair approaches (Monaghan's
  // bound at rest, and 0.3 h / |v|), the least over all of them (collective): what
  // `anvil check` estimates the cycles with.
  double initial_step() const;
  // Local index of a particle by global id, or -1 if this rank does not hold it.
  int find(std::int64_t gid) const;
  // Partitions afresh by RCB at the particles' current positions and moves each particle
  // to its box's rank: after particles() was overwritten with a checkpoint's state, whose
  // positions may lie outside this rank's box. The results do not depend on the
  // decomposition, so this one need not be the interrupted run's. Collective.
  void redistribute();

private:
  // Moves every field of own particle i to rank dest[i] (collective), then restores
  // ascending gid. Own arrays only (not extended by ghosts).
  void migrate(std::span<const int> dest);
  // Reorders every field of the own particles by ascending gid (no-op when sorted).
  void sort_by_gid();
  // Sends what pass 1 reads (gid, set, x, v, mass, rho, h) of the ghost_src_ particles to
  // ghost_dest_ along ghost_plan_ and appends the received copies after the own
  // particles (extends the neighbour-read arrays). Collective.
  void exchange_ghosts_in();
  // Sends what pass 2 reads (stress, artificial stress, new rho, wave speed) along the
  // same plan into the ghosts' records (work_.read2: P's first six components, rho, mass,
  // c) and the ghost part of S678_, R_, rho and wave_speed. Collective.
  void exchange_ghosts_out();
  // Sizes the arrays that neighbours read to n entries (own + ghosts, or own only);
  // capacity is kept.
  void resize_neighbour_fields(std::size_t n);
  // The reusable scratch vector for fields of type T (moves and reorders swap with it,
  // so both keep their capacity: no allocation in steady state).
  template <class T>
  std::vector<T>* scratch() {
    if constexpr (std::is_same_v<T, double>)
      return &tmp_d_;
    else if constexpr (std::is_same_v<T, std::int64_t>)
      return &tmp_l_;
    else if constexpr (std::is_same_v<T, int>)
      return &tmp_i_;
    else if constexpr (std::is_same_v<T, std::uint64_t>)
      return &tmp_q_;
    else
      return &tmp_u_;
  }

  const Comm& comm_;
  Rcb rcb_;
  Particles p_;
  std::vector<SetParams> sets_;
  KernelType kernel_ = KernelType::cubic_spline;
  double threshold_ = 1.2;
  double hmax_ = 0; // largest smoothing length over all particles, this cycle
  std::int64_t global_count_ = 0;
  std::vector<std::int64_t> set_offsets_;
  std::vector<std::string> notes_;

  // Ghost copies of this cycle: local particle and destination rank per copy.
  std::vector<int> ghost_src_, ghost_dest_;
  Migration ghost_plan_, move_plan_;
  struct GhostIn {
    std::int64_t gid;
    int set;
    double x[3], v[3], mass, rho, h;
  };
  struct GhostOut {
    double S[9], R[6], rho, c;
  };
  std::vector<GhostIn> in_send_, in_recv_;
  std::vector<GhostOut> out_send_, out_recv_;
  std::vector<double> S678_[3], R_[6], energy_rate_;
  std::vector<int> ranks_, dest_, perm_;
  std::vector<double> tmp_d_;
  std::vector<std::int64_t> tmp_l_;
  std::vector<int> tmp_i_;
  std::vector<std::uint8_t> tmp_u_;
  std::vector<std::uint64_t> tmp_q_;
  NeighbourWorkspace nwork_;
  // Candidate (Verlet) lists, kept with the ghost plan until a particle could have come
  // within the support of one it does not list: every pair closer than radius_ =
  // 2 h_max (1 + skin) at the build (positions x_build_ of the own particles). The
  // results do not depend on when they were built (neighbours.hpp).
  static constexpr double skin = 0.2;
  NeighbourList candidates_;
  std::array<std::vector<double>, 3> x_build_;
  double radius_ = 0;
  bool lists_valid_ = false;
  SphWorkspace work_;
  SphResult result_;
  SphStats stats_;
};

} // namespace anvil::sph
