// `anvil run`: a deck from start to end with its outputs.
#pragma once

#include <string>

#include "anvil/io/config.hpp"
#include "anvil/parallel/comm.hpp"

namespace anvil {

struct RunOptions {
  std::string output_dir = "out";
  bool progress = true;
};

// Runs the model to its termination time or cycle count, writing the outputs. Returns
// the exit status: 0 when it completes, 3 when it fails physically (after writing the
// state it failed in and the summary). Bad input throws InputError. Collective.
int run(const Config& config, const RunOptions& options, const Comm& comm);

} // namespace anvil
