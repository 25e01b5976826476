#include "anvil/solver/run.hpp"

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>

#include <fmt/format.h>

#include "anvil/io/checkpoint.hpp"
#include "anvil/io/outputs.hpp"
#include "anvil/solver/simulation.hpp"

namespace anvil {

namespace {

// The signal that asked the run to stop (0: none). A signal handler can only set a flag;
// this is the one piece of global state in anvil, read once per cycle.
volatile std::sig_atomic_t stop_signal = 0;

extern "C" void on_stop_signal(int sig) {
  stop_signal = sig;
}

// Installs the handlers for SIGTERM and SIGINT for its lifetime.
class StopSignals {
public:
  StopSignals() {
    stop_signal = 0;
    struct sigaction sa {};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGTERM, &sa, &old_term_);
    sigaction(SIGINT, &sa, &old_int_);
  }
  ~StopSignals() {
    sigaction(SIGTERM, &old_term_, nullptr);
    sigaction(SIGINT, &old_int_, nullptr);
  }

private:
  struct sigaction old_term_ {
  }, old_int_{};
};

} // namespace

int run(const Config& config, const RunOptions& options, const Comm& comm) {
  // From the start: a signal during the set-up (a large mesh's partition) stops the run
  // after its first cycle, with a checkpoint, instead of killing it without one.
  StopSignals signals;
  Simulation sim(config, comm);
  if (comm.rank() == 0 && options.restart.empty())
    for (const auto& w : sim.warnings()) std::fprintf(stderr, "anvil: warning: %s\n", w.c_str());
  // A checkpoint is read and checked before the output directory is made: a refused
  // restart leaves nothing behind.
  std::optional<Checkpoint> restored;
  if (!options.restart.empty()) {
    restored = read_checkpoint(options.restart); // every rank reads it
    sim.restore(*restored);
    // A checkpoint at the end of the run this deck asks for (the final one a finished run
    // writes) has nothing left to run: continuing "zero steps" would rewrite the outputs
    // from a state whose energies no step has computed (QA round 33: a finished run's
    // summary.json rewritten with time 0 and the initial kinetic energy).
    if (sim.finished())
      throw InputError(fmt::format(
          "checkpoint '{}' is at the end of the run this deck asks for (t = {:.9g} s, cycle "
          "{}): nothing to continue; give a later termination to run on",
          options.restart, sim.clock().time, sim.clock().cycle));
  }
  Outputs out(sim, {options.output_dir, options.progress});
  const std::string checkpoint_path = options.output_dir + "/checkpoint.anvil";
  double next_checkpoint = config.checkpoint_every > 0 ? config.checkpoint_every
                                                       : std::numeric_limits<double>::infinity();
  if (restored) {
    out.resume(restored->outputs, std::filesystem::path(options.restart).parent_path().string());
    if (config.checkpoint_every > 0) next_checkpoint = restored->outputs.next_checkpoint;
    restored.reset(); // (its copy of the state is not needed during the run)
  } else {
    out.begin();
  }
  auto checkpoint = [&] {
    ScopedPhase t(out.output_timer(), Phase::output); // (summary.json: `output`)
    OutputState st = out.state();
    st.next_checkpoint = next_checkpoint;
    const Checkpoint c = capture(sim, st);
    // Rank 0 writes; a failure (disk full, directory gone) stops every rank with its
    // message instead of leaving the others waiting in the next collective.
    std::string error;
    if (comm.rank() == 0) {
      try {
        write_checkpoint(checkpoint_path, c);
      } catch (const InputError& e) {
        error = e.what();
      }
    }
    comm.broadcast(error, 0);
    if (!error.empty()) throw InputError(error); // (on every rank: see the catch below)
  };

  try {
    while (!sim.finished()) {
      // The request travels with the coming step's reduction, so --stop-at-cycle N asks
      // before the step that completes cycle N (N = 0 stops after the first cycle).
      const bool stop_here =
          options.stop_at_cycle >= 0 && sim.clock().cycle + 1 >= options.stop_at_cycle;
      if (stop_signal != 0 || stop_here) sim.request_stop();
      sim.step();
      out.after_step();
      const bool by_time = sim.clock().time >= next_checkpoint * (1 - 1e-12);
      const bool by_cycle = config.checkpoint_every_cycles > 0 &&
                            sim.clock().cycle % config.checkpoint_every_cycles == 0;
      if ((by_time || by_cycle) && !sim.finished()) {
        if (by_time)
          next_checkpoint =
              next_output_time(next_checkpoint, config.checkpoint_every, sim.clock().time);
        checkpoint();
      }
      if (sim.stop_requested() && !sim.finished()) {
        const int sig = stop_signal != 0 ? static_cast<int>(stop_signal) : SIGTERM;
        checkpoint();
        if (comm.rank() == 0)
          std::fprintf(stderr,
                       "\nanvil: stopped by signal %d at t = %.9g s (cycle %lld); checkpoint %s\n",
                       sig, sim.clock().time, static_cast<long long>(sim.clock().cycle),
                       checkpoint_path.c_str());
        out.finish(128 + sig, "stopped by a signal; restart with --restart " + checkpoint_path);
        return 128 + sig;
      }
    }
  } catch (const PhysicsError& e) {
    if (comm.rank() == 0) std::fprintf(stderr, "\nanvil: run failed: %s\n", e.what());
    out.finish(exit_physics, e.what());
    return exit_physics;
  } catch (const InputError& e) {
    // A checkpoint or field output that could not be written (a full disk): every rank
    // stops (those writes are collective), and the outputs say why where they can: the
    // last fields and a failed summary.
    try {
      out.finish(exit_bad_input, e.what());
    } catch (const InputError&) {
      // The outputs could not be written either: the first error is the one to report.
    }
    throw;
  }
  if (config.checkpoint_every > 0 || config.checkpoint_every_cycles > 0)
    checkpoint(); // the final state, for continuing later
  out.finish(exit_ok, "");
  return exit_ok;
}

} // namespace anvil
