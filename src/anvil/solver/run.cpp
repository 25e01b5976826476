#include "anvil/solver/run.hpp"

#include <cstdio>

#include "anvil/io/outputs.hpp"
#include "anvil/solver/simulation.hpp"

namespace anvil {

int run(const Config& config, const RunOptions& options, const Comm& comm) {
  Simulation sim(config, comm);
  Outputs out(sim, {options.output_dir, options.progress});
  out.begin();
  try {
    while (!sim.finished()) {
      sim.step();
      out.after_step();
    }
  } catch (const PhysicsError& e) {
    if (comm.rank() == 0) std::fprintf(stderr, "\nanvil: run failed: %s\n", e.what());
    out.finish(exit_physics, e.what());
    return exit_physics;
  }
  out.finish(exit_ok, "");
  return exit_ok;
}

} // namespace anvil
