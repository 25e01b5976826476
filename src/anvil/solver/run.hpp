// `anvil run`: a deck from start to end with its outputs.
#pragma once

#include <string>

#include "anvil/io/config.hpp"
#include "anvil/parallel/comm.hpp"

namespace anvil {

struct RunOptions {
  std::string output_dir = "out";
  bool progress = true;
  std::string restart;          // checkpoint to continue from (empty: start at t = 0)
  long long stop_at_cycle = -1; // stop as if by SIGTERM once cycle N is done (testing)
};

// Runs the model to its termination time or cycle count, writing the outputs. Returns
// the exit status: 0 when it completes, 3 when it fails physically (after writing the
// state it failed in and the summary), 128 + signal when SIGTERM or SIGINT stopped it
// (after a checkpoint, OUTDIR/checkpoint.anvil, and the outputs). Checkpoints are also
// written every `checkpoint.every` seconds of the deck and at the end. Bad input throws
// InputError. Collective.
int run(const Config& config, const RunOptions& options, const Comm& comm);

} // namespace anvil
