// The anvil command line: a few lines over the library (DESIGN.md section 4).
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <new>
#include <span>
#include <vector>

#include "anvil/core/error.hpp"
#include "anvil/io/decompose.hpp"
#include "anvil/io/input.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/solver/can_crush.hpp"
#include "anvil/solver/run.hpp"
#include "anvil/solver/simulation.hpp"
#include "anvil/version.hpp"

namespace {

// What the deck reader accepted but could not take over exactly, on rank 0.
void print_warnings(const anvil::Config& config, const anvil::Comm& comm) {
  if (comm.rank() != 0) return;
  for (const auto& w : config.warnings) std::fprintf(stderr, "anvil: warning: %s\n", w.c_str());
}

// One line of `check` per boundary condition, as history.csv numbers their reactions
// (bcN.fx ...): its selection and what it holds.
// "1 node", "2 nodes".
std::string count_of(std::int64_t n, const char* thing) {
  return fmt::format("{} {}{}", n, thing, n == 1 ? "" : "s");
}

// A birth/death window as `check` shows it ("" when it is the whole run).
std::string describe_window(double birth, double death) {
  if (birth == 0 && std::isinf(death)) return {};
  return std::isinf(death) ? fmt::format(" from t = {:g} s", birth)
                           : fmt::format(" from t = {:g} to {:g} s", birth, death);
}

// A selection as `check` shows it: its name, or its part and box.
std::string describe_selection(const anvil::Selection& s) {
  std::string where = s.name;
  if (where.empty()) {
    where = s.part ? "part " + *s.part : "all";
    if (s.box)
      where += fmt::format(" in box [{:g}, {:g}, {:g}]-[{:g}, {:g}, {:g}]", s.box->lo.x,
                           s.box->lo.y, s.box->lo.z, s.box->hi.x, s.box->hi.y, s.box->hi.z);
  }
  return where;
}

std::string describe_condition(std::size_t n, const anvil::BoundaryCondition& bc) {
  const std::string where = describe_selection(bc.nodes);
  const auto& on = bc.prescribed ? bc.components : bc.fix;
  const auto& spin_on = bc.prescribed ? bc.spin_components : bc.fix_spin;
  std::string comps, spins;
  for (int i = 0; i < 3; ++i) {
    if (on[static_cast<std::size_t>(i)]) comps += "xyz"[i];
    // (A rigid body's rotations: `fix: all` names them for nodes too, which have none.)
    if (spin_on[static_cast<std::size_t>(i)] && (bc.rotations || bc.prescribed))
      spins += fmt::format(" r{}", "xyz"[i]);
  }
  const bool all = !bc.prescribed && comps == "xyz" && bc.fix_spin[0] && bc.fix_spin[1] &&
                   bc.fix_spin[2] && !bc.rotations;
  std::string what = all ? "fix all" : "fix " + comps + spins;
  if (bc.prescribed) {
    const bool moved = bc.motion == anvil::BoundaryCondition::Motion::displacement;
    what.clear();
    if (!comps.empty())
      what = fmt::format("{} {} [{:g}, {:g}, {:g}]", moved ? "displacement" : "velocity", comps,
                         bc.value.x, bc.value.y, bc.value.z);
    if (!spins.empty())
      what += fmt::format("{}angular velocity{} [{:g}, {:g}, {:g}] rad/s", what.empty() ? "" : ", ",
                          spins, bc.spin.x, bc.spin.y, bc.spin.z);
    if (bc.curve)
      what += fmt::format(" x curve of {}",
                          count_of(static_cast<std::int64_t>(bc.curve->t.size()), "point"));
  }
  return fmt::format("  bc{:<3} {:<24} {}{}", n, where, what, describe_window(bc.birth, bc.death));
}

// One line of `check` per external load: what it applies, and where.
std::string describe_load(std::size_t n, const anvil::Load& load, std::int64_t targets,
                          double area) {
  std::string what = load.kind == anvil::Load::Kind::force
                         ? fmt::format("force [{:g}, {:g}, {:g}] N on each of {}", load.force.x,
                                       load.force.y, load.force.z, count_of(targets, "node"))
                         : fmt::format("pressure {:g} Pa on {} ({:.4g} m^2)", load.pressure,
                                       count_of(targets, "face"), area);
  if (load.curve)
    what += fmt::format(" x curve of {}",
                        count_of(static_cast<std::int64_t>(load.curve->t.size()), "point"));
  return fmt::format("  load{:<2} {:<24} {}{}", n, describe_selection(load.target), what,
                     describe_window(load.birth, load.death));
}

int check(const std::string& deck, const anvil::Comm& comm) {
  const anvil::Config config = anvil::read_input(deck);
  print_warnings(config, comm);
  anvil::Simulation sim(config, comm);
  if (comm.rank() == 0)
    for (const auto& w : sim.warnings()) std::fprintf(stderr, "anvil: warning: %s\n", w.c_str());
  std::int64_t controlling = -1;
  const double dt = sim.stable_time_step(&controlling);
  // The particles' first step if no pair approaches (a reduction, as the masses below).
  const double dt_particles =
      sim.sph() ? sim.sph()->initial_step() : std::numeric_limits<double>::infinity();
  // Particle sets: mass per set (a reduction: before rank 0 prints alone).
  std::vector<double> set_mass(config.particles.size(), 0.0);
  if (const auto* sph = sim.sph()) {
    const auto& pt = sph->particles();
    for (std::size_t i = 0; i < pt.size(); ++i)
      set_mass[static_cast<std::size_t>(pt.set[i])] += pt.mass[i];
    comm.sum(std::span<double>(set_mass));
  }
  const std::vector<std::int64_t> load_targets = sim.load_targets();
  const std::vector<double> pressed_area = sim.pressed_area();
  // Elements by shape (hexahedra, wedges, pyramids, tetrahedra: mesh.hpp's Shape order).
  std::array<std::int64_t, 4> shapes{};
  for (const auto& b : sim.blocks())
    for (std::size_t e = 0; e < static_cast<std::size_t>(b.size()); ++e) {
      anvil::Hex h;
      for (int a = 0; a < 8; ++a) h[a] = b.conn[a][e];
      ++shapes[static_cast<std::size_t>(anvil::shape_of(h))];
    }
  comm.sum(std::span<std::int64_t>(shapes));
  if (comm.rank() != 0) return 0;
  std::printf("deck        %s%s\n", deck.c_str(),
              config.title.empty() ? "" : fmt::format("  ({})", config.title).c_str());
  std::printf("ranks       %d\n", comm.size());
  std::printf("nodes       %lld\n", static_cast<long long>(sim.global_nodes()));
  std::string by_shape; // "(250 wedges, 720 tetrahedra)" unless all are hexahedra
  if (shapes[0] < sim.global_elements())
    for (const anvil::Shape k : {anvil::Shape::hexahedron, anvil::Shape::wedge,
                                 anvil::Shape::pyramid, anvil::Shape::tetrahedron})
      if (const auto n = shapes[static_cast<std::size_t>(k)]; n > 0)
        by_shape +=
            fmt::format("{}{} {}", by_shape.empty() ? " (" : ", ", n, anvil::shape_name(k, n != 1));
  if (!by_shape.empty()) by_shape += ")";
  std::printf("elements    %lld%s\n", static_cast<long long>(sim.global_elements()),
              by_shape.c_str());
  const std::vector<int> leads = anvil::rigid_body_leads(config.parts);
  for (std::size_t i = 0; i < config.parts.size(); ++i) {
    const double added = sim.part_added_masses()[i];
    std::printf("  part %-16s material %-16s mass %.6g kg%s%s\n", config.parts[i].name.c_str(),
                config.parts[i].material.c_str(), sim.part_masses()[i],
                added > 0 ? fmt::format(" + {:.6g} kg mass scaling ({:.3g}%)", added,
                                        100 * added / sim.part_masses()[i])
                                .c_str()
                          : "",
                !config.parts[i].rigid ? ""
                : config.parts[i].merge_with.empty()
                    ? "  rigid body"
                    : fmt::format("  rigid, in the body of {}",
                                  config.parts[static_cast<std::size_t>(leads[i])].name)
                          .c_str());
  }
  if (config.mass_scaling_step > 0) {
    double added = 0, mass = 0;
    for (std::size_t i = 0; i < config.parts.size(); ++i) {
      added += sim.part_added_masses()[i];
      mass += sim.part_masses()[i];
    }
    std::printf("mass scaling step %g s: %lld elements scaled, %.6g kg added (%.3g%% of the "
                "elements' mass)\n",
                config.mass_scaling_step, static_cast<long long>(sim.mass_scaled_elements()), added,
                100 * added / mass);
  }
  if (const auto* sph = sim.sph()) {
    const auto& off = sph->set_offsets();
    std::printf("particles   %lld\n", static_cast<long long>(sph->global_count()));
    for (std::size_t i = 0; i < config.particles.size(); ++i)
      std::printf("  set  %-16s material %-16s mass %.6g kg, %lld particles\n",
                  config.particles[i].name.c_str(), config.particles[i].material.c_str(),
                  set_mass[i], static_cast<long long>(off[i + 1] - off[i]));
  }
  if (!config.boundary_conditions.empty()) {
    const bool moments =
        std::any_of(config.boundary_conditions.begin(), config.boundary_conditions.end(),
                    [](const anvil::BoundaryCondition& bc) { return bc.holds_spin(); });
    std::printf("conditions  %zu (history.csv: bcN.fx, bcN.fy, bcN.fz%s)\n",
                config.boundary_conditions.size(),
                moments ? "; bcN.mx, bcN.my, bcN.mz of those that hold rotations" : "");
    for (std::size_t b = 0; b < config.boundary_conditions.size(); ++b)
      std::printf("%s\n", describe_condition(b, config.boundary_conditions[b]).c_str());
  }
  for (const auto& g : config.body_loads) {
    std::string line = fmt::format("gravity     [{:g}, {:g}, {:g}] m/s^2", g.acceleration.x,
                                   g.acceleration.y, g.acceleration.z);
    if (g.curve)
      line += fmt::format(" x curve of {}",
                          count_of(static_cast<std::int64_t>(g.curve->t.size()), "point"));
    std::printf("%s\n", line.c_str());
  }
  if (!config.loads.empty()) {
    std::printf("loads       %zu\n", config.loads.size());
    for (std::size_t l = 0; l < config.loads.size(); ++l)
      std::printf("%s\n",
                  describe_load(l, config.loads[l], load_targets[l], pressed_area[l]).c_str());
  }
  if (sim.global_elements() > 0) {
    std::printf("stable dt   %.6g s (element kernel at t = 0), step %.6g s with scale %g\n", dt,
                dt * config.time_step_scale, config.time_step_scale);
    // (QA round 36: one 1 um element among 200,000 set a step 2,500 times smaller, unnamed.)
    if (controlling >= 0)
      std::printf("            set by %s\n", sim.describe_element(controlling).c_str());
  }
  if (sim.sph())
    std::printf("%s%.6g s for the particles at rest (0.3 h / (c (1 + 1.2 alpha)), and 0.3 h "
                "/ |v|; their first cycle sets it), step %.6g s\n",
                sim.global_elements() > 0 ? "            " : "stable dt   ", dt_particles,
                dt_particles * config.time_step_scale);
  const double step = std::min(sim.global_elements() > 0 ? dt : dt_particles, dt_particles) *
                      config.time_step_scale;
  if (config.mass_scaling_step > 0 &&
      dt * config.time_step_scale < config.mass_scaling_step * (1 - 1e-9))
    std::printf("            below the mass-scaling step %g s: elements that the initial "
                "velocities compress (bulk viscosity) take a smaller one, as mass scaling "
                "looks at the elements at rest\n",
                config.mass_scaling_step);
  if (std::isfinite(config.end_time))
    std::printf("end time    %.6g s, about %.0f cycles at the initial step\n", config.end_time,
                std::ceil(config.end_time / step));
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
  std::string restart;
  long long stop_at = -1;
  run->add_option("--restart", restart, "continue from a checkpoint (any number of ranks)");
  run->add_option("--stop-at-cycle", stop_at, "stop as if by SIGTERM at this cycle (testing)")
      ->group("");
  std::string format;
  run->add_option("--format", format,
                  "field output format, overriding the deck's output.format (a keyword deck "
                  "has none)")
      ->check(CLI::IsMember({"vtu", "exodus", "both"}));
  auto* chk =
      app.add_subcommand("check", "validate a deck and its mesh; print counts, masses, stable dt");
  chk->add_option("deck", deck, "the deck: YAML, or LS-DYNA keyword (.k, .key, .dyn)")->required();

  auto* dec =
      app.add_subcommand("decompose", "under mpirun: the decompositions at t = 0, as VTU and JSON");
  dec->add_option("deck", deck, "the deck: YAML, or LS-DYNA keyword (.k, .key, .dyn)")->required();
  dec->add_option("-o,--output", outdir, "output directory")->required();
  auto* bench = app.add_subcommand("bench", "benchmarks");
  bench->require_subcommand(1);
  auto* can =
      bench->add_subcommand("can-crush", "the paper's scaled can crush for the current rank count");
  anvil::CanCrushOptions cc;
  std::string bench_out = "bench_can_crush";
  bool write_deck = false;
  can->add_option("--elements-per-rank", cc.elements_per_rank, "one-rank model size")
      ->capture_default_str()
      ->check(CLI::Range(200, 10000000));
  // Bounded here: the deck's own limit, which would name a line of a generated deck.
  can->add_option("--cycles", cc.cycles, "stop after this many cycles (default: run to 3.2 ms)")
      ->check(CLI::Range(1LL, 9000000000000000LL));
  can->add_option("-o,--output", bench_out, "output directory")->capture_default_str();
  std::string wall = "thick_shell";
  can->add_option("--wall", wall,
                  "the can's wall element: thick_shell (3 points through the wall) or one_point "
                  "(the paper's hexahedron, viscous hourglass control)")
      ->check(CLI::IsMember({"thick_shell", "one_point"}))
      ->capture_default_str();
  std::string decomposition = "paper";
  can->add_option("--decomposition", decomposition,
                  "paper (METIS for the elements, contact RCB cutting the longest direction) or "
                  "sectors (RCBs cutting along the can's axis, in both decompositions)")
      ->check(CLI::IsMember({"paper", "sectors"}))
      ->capture_default_str();
  can->add_flag("--print-deck", write_deck, "print the deck for this rank count and exit");
  can->add_flag("-q,--quiet", quiet, "no progress line");

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
    // `anvil frob` or `anvil --versoin`: CLI11 would only say that a subcommand is
    // required; name the word it did not know.
    const auto extra = app.remaining();
    if (root && app.get_subcommands().empty() && !extra.empty())
      std::fprintf(stderr, "anvil: error: unknown subcommand or option '%s' (see anvil --help)\n",
                   extra.front().c_str());
    else if (root)
      app.exit(e);
    return anvil::exit_bad_input;
  }

  try {
    if (*run) {
      anvil::Config config = anvil::read_input(deck);
      print_warnings(config, comm);
      if (format == "vtu") config.output_format = anvil::OutputFormat::vtu;
      if (format == "exodus") config.output_format = anvil::OutputFormat::exodus;
      if (format == "both") config.output_format = anvil::OutputFormat::both;
      return anvil::run(config, {outdir, !quiet, restart, stop_at}, comm);
    }
    if (*chk) return check(deck, comm);
    if (*dec) {
      anvil::write_decomposition(anvil::read_input(deck), outdir, comm);
      return 0;
    }
    if (*can) {
      cc.ranks = comm.size();
      cc.wall = wall == "one_point" ? anvil::CanCrushOptions::Wall::one_point
                                    : anvil::CanCrushOptions::Wall::thick_shell;
      cc.decomposition = decomposition == "sectors" ? anvil::CanCrushOptions::Decomposition::sectors
                                                    : anvil::CanCrushOptions::Decomposition::paper;
      if (write_deck) {
        if (root) std::printf("%s", anvil::can_crush_deck(cc).c_str());
        return 0;
      }
      return anvil::run(anvil::can_crush_config(cc), {bench_out, !quiet, "", -1}, comm);
    }
  } catch (const anvil::InputError& e) {
    if (root) std::fprintf(stderr, "anvil: error: %s\n", e.what());
    return anvil::exit_bad_input;
  } catch (const anvil::PhysicsError& e) {
    if (root) std::fprintf(stderr, "anvil: run failed: %s\n", e.what());
    return anvil::exit_physics;
  } catch (const std::bad_alloc&) {
    // One rank may run out alone: the others cannot be told, hence the abort.
    std::fprintf(stderr, "anvil: error: the model does not fit in memory (rank %d)\n", comm.rank());
    comm.abort(anvil::exit_bad_input);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "anvil: internal error on rank %d: %s\n", comm.rank(), e.what());
    comm.abort(1);
  }
  return 0;
}
