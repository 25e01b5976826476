// The anvil command line: a few lines over the library (DESIGN.md section 4).
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <exception>

#include "anvil/core/error.hpp"
#include "anvil/io/input.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/solver/run.hpp"
#include "anvil/solver/simulation.hpp"
#include "anvil/version.hpp"

namespace {

// What the deck reader accepted but could not take over exactly, on rank 0.
void print_warnings(const anvil::Config& config, const anvil::Comm& comm) {
  if (comm.rank() != 0) return;
  for (const auto& w : config.warnings) std::fprintf(stderr, "anvil: warning: %s\n", w.c_str());
}

int check(const std::string& deck, const anvil::Comm& comm) {
  const anvil::Config config = anvil::read_input(deck);
  print_warnings(config, comm);
  anvil::Simulation sim(config, comm);
  const double dt = sim.stable_time_step();
  if (comm.rank() != 0) return 0;
  std::printf("deck        %s%s\n", deck.c_str(),
              config.title.empty() ? "" : fmt::format("  ({})", config.title).c_str());
  std::printf("ranks       %d\n", comm.size());
  std::printf("nodes       %lld\n", static_cast<long long>(sim.global_nodes()));
  std::printf("elements    %lld\n", static_cast<long long>(sim.global_elements()));
  for (std::size_t i = 0; i < config.parts.size(); ++i)
    std::printf("  part %-16s material %-16s mass %.6g kg\n", config.parts[i].name.c_str(),
                config.parts[i].material.c_str(), sim.part_masses()[i]);
  std::printf("stable dt   %.6g s (element kernel at t = 0), step %.6g s with scale %g\n", dt,
              dt * config.time_step_scale, config.time_step_scale);
  if (std::isfinite(config.end_time))
    std::printf("end time    %.6g s, about %.0f cycles at the initial step\n", config.end_time,
                std::ceil(config.end_time / (dt * config.time_step_scale)));
  std::printf("deck and mesh are valid\n");
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  anvil::MpiSession mpi(&argc, &argv);
  const anvil::Comm comm = anvil::Comm::world();
  const bool root = comm.rank() == 0;

  CLI::App app{"anvil: parallel transient solid dynamics (explicit FE, SPH, contact)"};
  app.set_version_flag("--version", std::string("anvil ") + anvil::version);
  app.require_subcommand(1);
  std::string deck, outdir = "out";
  bool quiet = false;
  auto* run = app.add_subcommand("run", "run a deck (under mpirun -np P for P ranks)");
  run->add_option("deck", deck, "the deck: YAML, or LS-DYNA keyword (.k, .key, .dyn)")->required();
  run->add_option("-o,--output", outdir, "output directory")->capture_default_str();
  run->add_flag("-q,--quiet", quiet, "no progress line");
  std::string format;
  run->add_option("--format", format,
                  "field output format, overriding the deck's output.format (a keyword deck "
                  "has none)")
      ->check(CLI::IsMember({"vtu", "exodus", "both"}));
  auto* chk =
      app.add_subcommand("check", "validate a deck and its mesh; print counts, masses, stable dt");
  chk->add_option("deck", deck, "the deck: YAML, or LS-DYNA keyword (.k, .key, .dyn)")->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    if (root) app.exit(e);
    return 0;
  } catch (const CLI::CallForAllHelp& e) {
    if (root) app.exit(e);
    return 0;
  } catch (const CLI::CallForVersion& e) {
    if (root) app.exit(e);
    return 0;
  } catch (const CLI::ParseError& e) {
    if (root) {
      app.exit(e);
    }
    return anvil::exit_bad_input;
  }

  try {
    if (*run) {
      anvil::Config config = anvil::read_input(deck);
      print_warnings(config, comm);
      if (format == "vtu") config.output_format = anvil::OutputFormat::vtu;
      if (format == "exodus") config.output_format = anvil::OutputFormat::exodus;
      if (format == "both") config.output_format = anvil::OutputFormat::both;
      return anvil::run(config, {outdir, !quiet}, comm);
    }
    if (*chk) return check(deck, comm);
  } catch (const anvil::InputError& e) {
    if (root) std::fprintf(stderr, "anvil: error: %s\n", e.what());
    return anvil::exit_bad_input;
  } catch (const anvil::PhysicsError& e) {
    if (root) std::fprintf(stderr, "anvil: run failed: %s\n", e.what());
    return anvil::exit_physics;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "anvil: internal error on rank %d: %s\n", comm.rank(), e.what());
    comm.abort(1);
  }
  return 0;
}
