// The results of a run in OUTDIR (DESIGN.md section 4): results.pvd with a .pvtu and
// per-rank .vtu pieces per field output and/or Exodus II files (exodus.hpp), as the deck's
// output.format says, history.csv (energies and probes), and summary.json; plus the
// progress line on rank 0. Every method is collective.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "anvil/core/error.hpp"
#include "anvil/io/checkpoint.hpp"
#include "anvil/io/exodus.hpp"
#include "anvil/io/vtu.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"

namespace anvil {

// The next due time of a series written every `every` seconds (> 0), past the time `t`
// just written: `next` advanced by whole intervals beyond t (1 + 1e-12). Bounded work
// whatever the interval: an interval too small to advance t in floating point
// (every = 1e-300) gives the next double past the bound, a row or field output per cycle.
double next_output_time(double next, double every, double t);

// Runs `write` on every rank; if it fails on any, every rank throws the InputError of the
// lowest failing rank (a write error on one rank must not leave the others waiting).
template <class F>
void collective_write(const Comm& comm, F&& write) {
  std::string err;
  try {
    write();
  } catch (const InputError& e) {
    err = e.what();
  }
  const std::int64_t failed = comm.min(err.empty() ? static_cast<std::int64_t>(comm.size())
                                                   : static_cast<std::int64_t>(comm.rank()));
  if (failed == comm.size()) return;
  comm.broadcast(err, static_cast<int>(failed));
  throw InputError(err);
}

struct OutputOptions {
  std::string directory = "out";
  bool progress = true; // progress line on rank 0
};

class Outputs {
public:
  Outputs(const Simulation& sim, OutputOptions options);
  ~Outputs();

  // Writes the initial fields (t = 0) and opens the history.
  void begin();
  // Continues the series of a checkpointed run instead of begin(); `from` is the
  // directory the checkpoint was written in (its history and field series; when it is
  // not this run's, they are copied and referenced from here).
  void resume(const OutputState& state, const std::string& from);
  // Where the series stands (for checkpoints; next_checkpoint is the run loop's).
  OutputState state() const;
  // After each step: history row and fields when due, progress line.
  void after_step();
  // Final fields (unless just written) and summary.json. `status` is the exit status,
  // `message` the failure (empty on success).
  void finish(int status, const std::string& message);

  // The `output` phase's timer: the run loop counts its checkpoints there.
  PhaseTimers& output_timer() { return output_timer_; }

  double loop_seconds() const;
  double fraction_done() const; // of the run to its end time or cycle count

private:
  void write_fields();
  std::string history_header() const;
  void write_particles(const std::string& stem);
  void write_series(const std::string& name, const VtuPiece& piece,
                    std::vector<std::pair<double, std::string>>& series, const std::string& pvd);
  void open_exodus(const std::string& stem);
  // `scheduled`: a row of the history_every series (the end of a run's is not, unless it
  // falls on the series: a restart from the run's last checkpoint drops it).
  void write_history_row(const Sample& s, bool scheduled = true);
  void write_summary(int status, const std::string& message);
  void progress(bool last);

  const Simulation& sim_;
  OutputOptions opt_;
  std::vector<std::pair<double, std::string>> pvd_;
  std::vector<std::pair<double, std::string>> particle_pvd_;
  std::unique_ptr<ExodusWriter> exodus_; // this rank's Exodus file, when the format asks

  std::FILE* history_ = nullptr;
  double next_fields_ = 0, next_history_ = 0;
  std::int64_t last_field_cycle_ = -1;
  int field_count_ = 0;
  std::int64_t history_rows_ = 0; // scheduled rows of history.csv (rank 0), and the last
  std::string history_last_;
  // The largest |total| and |external_work| of the run's history rows (and of the kept
  // rows of a restart): the scale of summary.json's balance_error.
  double energy_scale_ = 0;
  void note_energy(double e);
  double start_wall_ = 0, last_progress_wall_ = 0, last_progress_fraction_ = 0;
  std::int64_t start_cycle_ = 0; // the cycle this run started from (its checkpoint's)
  double start_fraction_ = 0;    // the fraction done at that cycle
  bool tty_ = false;
  bool deep_warned_ = false; // a contact node went past its face's contact depth (said once)
  PhaseTimers output_timer_;
  Sample last_sample_;
  bool have_sample_ = false;
  // The state the deck gave, for the t = 0 row of a run that stops before its first step
  // completes (the row is otherwise the first step's sample: see after_step()).
  Sample initial_;
  bool initial_row_due_ = false;
};

// The field piece of this rank: points, hexahedra and their nodal and element fields.
VtuPiece fe_piece(const Simulation& sim);
// The particle piece of this rank (SPH decomposition): one vertex cell per particle.
VtuPiece particle_piece(const Simulation& sim);

} // namespace anvil
