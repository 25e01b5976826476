// Wall-clock timers, one per phase of the cycle (DESIGN.md section 1) plus setup and
// output. Reported in summary.json; never asserted in a test.
#pragma once

#include <array>
#include <chrono>
#include <string_view>

namespace anvil {

enum class Phase {
  fe,             // 1. element kernel and nodal gather
  sph,            // 2. particle forces
  predict,        // 3. v(n+1/2), x*
  contact_search, // 4. global search + detailed check
  contact_force,  // 5. penalty forces and correction
  update,         // 6. positions, time, stable dt (includes its reduction)
  rebalance,      // RCB recomputation
  transfer,       // data moved between decompositions
  halo,           // FE shared-node exchange (part of step 1, timed apart)
  output,         // fields, history, progress
  count
};

inline constexpr std::array<std::string_view, static_cast<int>(Phase::count)> phase_names = {
    "fe",     "sph",       "predict",  "contact_search", "contact_force",
    "update", "rebalance", "transfer", "halo",           "output"};

class PhaseTimers {
public:
  using clock = std::chrono::steady_clock;

  void add(Phase p, double seconds) { seconds_[static_cast<int>(p)] += seconds; }
  double seconds(Phase p) const { return seconds_[static_cast<int>(p)]; }
  const std::array<double, static_cast<int>(Phase::count)>& all() const { return seconds_; }
  void reset() { seconds_.fill(0.0); }

private:
  std::array<double, static_cast<int>(Phase::count)> seconds_{};
};

// Adds the lifetime of the scope to one phase.
class ScopedPhase {
public:
  ScopedPhase(PhaseTimers& timers, Phase phase)
      : timers_(timers), phase_(phase), start_(PhaseTimers::clock::now()) {}
  ~ScopedPhase() {
    timers_.add(phase_, std::chrono::duration<double>(PhaseTimers::clock::now() - start_).count());
  }
  ScopedPhase(const ScopedPhase&) = delete;
  ScopedPhase& operator=(const ScopedPhase&) = delete;

private:
  PhaseTimers& timers_;
  Phase phase_;
  PhaseTimers::clock::time_point start_;
};

inline double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

} // namespace anvil
