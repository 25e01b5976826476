#include "anvil/io/outputs.hpp"

#include <unistd.h>

#include <cstdlib>
#include <cstring>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "anvil/io/files.hpp"
#include "anvil/version.hpp"

namespace anvil {

// Both pieces reserve every array (each would otherwise hold up to twice its size while it
// grows) and move the arrays into the piece (a braced list copies them): the piece is the
// one copy of the fields an output holds (QA round 20).
VtuPiece fe_piece(const Simulation& sim) {
  VtuPiece p;
  const auto& nd = sim.nodes();
  const std::size_t nn = nd.size();
  p.points.resize(3 * nn);
  VtuArray disp{"displacement", 3}, vel{"velocity", 3}, nid{"node_id", 1};
  nid.is_int = true;
  disp.f64.resize(3 * nn);
  vel.f64.resize(3 * nn);
  nid.i64.resize(nn);
  for (std::size_t n = 0; n < nn; ++n) {
    for (int i = 0; i < 3; ++i) {
      p.points[3 * n + i] = nd.x[i][n];
      disp.f64[3 * n + i] = nd.x[i][n] - nd.x0[i][n];
      vel.f64[3 * n + i] = nd.v[i][n];
    }
    nid.i64[n] = sim.node_file_id(n);
  }
  p.point_data.reserve(3);
  p.point_data.push_back(std::move(disp));
  p.point_data.push_back(std::move(vel));
  p.point_data.push_back(std::move(nid));

  std::size_t nc = 0;
  bool any_temp = false;
  for (const HexBlock& b : sim.blocks()) {
    nc += static_cast<std::size_t>(b.size());
    any_temp = any_temp || (b.size() > 0 && !b.temperature.empty());
  }
  // Every rank must list the same arrays: temperature appears when any part has it.
  const bool temp_anywhere = sim.comm().max(static_cast<std::int64_t>(any_temp)) > 0;
  VtuArray stress{"stress", 6}, vm{"von_mises", 1}, pres{"pressure", 1}, ep{"plastic_strain", 1},
      temp{"temperature", 1}, rank{"fe_rank", 1}, eid{"element_id", 1}, part{"part", 1};
  rank.is_int = eid.is_int = part.is_int = true;
  p.connectivity.reserve(8 * nc);
  p.offsets.reserve(nc);
  p.types.reserve(nc);
  stress.f64.reserve(6 * nc);
  for (auto* v : {&vm.f64, &pres.f64, &ep.f64}) v->reserve(nc);
  if (temp_anywhere) temp.f64.reserve(nc);
  for (auto* v : {&rank.i64, &eid.i64, &part.i64}) v->reserve(nc);
  for (std::size_t bi = 0; bi < sim.blocks().size(); ++bi) {
    const HexBlock& b = sim.blocks()[bi];
    for (int e = 0; e < b.size(); ++e) {
      for (int a = 0; a < 8; ++a) p.connectivity.push_back(b.conn[a][e]);
      p.offsets.push_back(static_cast<std::int64_t>(p.connectivity.size()));
      p.types.push_back(12);
      double s[6];
      for (int k = 0; k < 6; ++k) {
        s[k] = b.stress[k][e];
        stress.f64.push_back(s[k]);
      }
      const double m = (s[0] + s[1] + s[2]) / 3;
      const double j2 =
          0.5 * ((s[0] - m) * (s[0] - m) + (s[1] - m) * (s[1] - m) + (s[2] - m) * (s[2] - m)) +
          s[3] * s[3] + s[4] * s[4] + s[5] * s[5];
      vm.f64.push_back(std::sqrt(3 * j2));
      pres.f64.push_back(-m);
      ep.f64.push_back(b.plastic_strain.empty() ? 0.0 : b.plastic_strain[e]);
      if (temp_anywhere) temp.f64.push_back(b.temperature.empty() ? 0.0 : b.temperature[e]);
      rank.i64.push_back(sim.comm().rank());
      eid.i64.push_back(sim.element_file_id(bi, static_cast<std::size_t>(e)));
      part.i64.push_back(b.part);
    }
  }
  p.cell_data.reserve(10);
  for (auto* a : {&stress, &vm, &pres, &ep}) p.cell_data.push_back(std::move(*a));
  if (temp_anywhere) p.cell_data.push_back(std::move(temp));
  p.cell_data.push_back(std::move(rank));
  // Contact decomposition: the RCB rank of the element's (first) exterior face, -1 for
  // elements without one.
  if (sim.contact()) {
    VtuArray contact_rank{"contact_rank", 1, true};
    contact_rank.i64.reserve(nc);
    for (const auto& per_block : sim.contact()->element_contact_rank(sim.blocks()))
      for (int r : per_block) contact_rank.i64.push_back(r);
    p.cell_data.push_back(std::move(contact_rank));
  }
  // Eroded elements (1), when any part erodes: threshold them away in ParaView.
  const auto& parts = sim.config().parts;
  if (std::any_of(parts.begin(), parts.end(),
                  [](const PartConfig& q) { return q.erosion.enabled(); })) {
    VtuArray er{"eroded", 1, true};
    er.i64.reserve(nc);
    for (const auto& b : sim.blocks())
      for (int e = 0; e < b.size(); ++e) er.i64.push_back(b.alive[e] == 0.0 ? 1 : 0);
    p.cell_data.push_back(std::move(er));
  }
  p.cell_data.push_back(std::move(eid));
  p.cell_data.push_back(std::move(part));
  return p;
}

VtuPiece particle_piece(const Simulation& sim) {
  VtuPiece p;
  const auto& pt = sim.sph()->particles();
  const std::size_t n = pt.size();
  // Every rank must list the same arrays: temperature where some particle has a thermal
  // model (QA round 18: Johnson-Cook heating of particles was not in the outputs); a
  // thermal model starts its particles at room temperature.
  bool any_temp = false;
  for (std::size_t i = 0; i < n && !any_temp; ++i) any_temp = pt.temperature[i] > 0;
  const bool temp_anywhere = sim.comm().max(static_cast<std::int64_t>(any_temp)) > 0;
  p.points.resize(3 * n);
  VtuArray disp{"displacement", 3}, vel{"velocity", 3}, rho{"density", 1}, pres{"pressure", 1},
      stress{"stress", 6}, vm{"von_mises", 1}, ep{"plastic_strain", 1}, energy{"energy", 1},
      h{"smoothing_length", 1}, rank{"sph_rank", 1, true}, pid{"particle_id", 1, true},
      set{"particle_set", 1, true}, temp{"temperature", 1};
  for (auto* v : {&disp.f64, &vel.f64}) v->reserve(3 * n);
  stress.f64.reserve(6 * n);
  for (auto* v : {&rho.f64, &pres.f64, &vm.f64, &ep.f64, &energy.f64, &h.f64}) v->reserve(n);
  if (temp_anywhere) temp.f64.reserve(n);
  for (auto* v : {&rank.i64, &pid.i64, &set.i64, &p.connectivity, &p.offsets}) v->reserve(n);
  p.types.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      p.points[3 * i + k] = pt.x[k][i];
      disp.f64.push_back(pt.x[k][i] - pt.x0[k][i]);
      vel.f64.push_back(pt.v[k][i]);
    }
    double s[6];
    for (int k = 0; k < 6; ++k) {
      s[k] = pt.stress[k][i];
      stress.f64.push_back(s[k]);
    }
    const double m = (s[0] + s[1] + s[2]) / 3;
    const double j2 =
        0.5 * ((s[0] - m) * (s[0] - m) + (s[1] - m) * (s[1] - m) + (s[2] - m) * (s[2] - m)) +
        s[3] * s[3] + s[4] * s[4] + s[5] * s[5];
    rho.f64.push_back(pt.rho[i]);
    pres.f64.push_back(-m);
    vm.f64.push_back(std::sqrt(3 * j2));
    ep.f64.push_back(pt.plastic_strain[i]);
    if (temp_anywhere) temp.f64.push_back(pt.temperature[i]);
    energy.f64.push_back(pt.energy[i]);
    h.f64.push_back(pt.h[i]);
    rank.i64.push_back(sim.comm().rank());
    pid.i64.push_back(pt.gid[i] + 1);
    set.i64.push_back(pt.set[i]);
    // One vertex cell (VTK type 1) per particle.
    p.connectivity.push_back(static_cast<std::int64_t>(i));
    p.offsets.push_back(static_cast<std::int64_t>(i + 1));
    p.types.push_back(1);
  }
  p.point_data.reserve(13);
  for (auto* a : {&disp, &vel, &rho, &pres, &stress, &vm, &ep})
    p.point_data.push_back(std::move(*a));
  if (temp_anywhere) p.point_data.push_back(std::move(temp));
  for (auto* a : {&energy, &h, &rank, &pid, &set}) p.point_data.push_back(std::move(*a));
  return p;
}

double next_output_time(double next, double every, double t) {
  const double bound = t * (1 + 1e-12);
  // A few intervals by repeated addition, as the series always advanced: an ordinary
  // deck's output times keep their bits. Past that, a jump.
  for (int i = 0; i < 16 && next <= bound; ++i) next += every;
  if (next > bound) return next;
  const double jump = (std::floor(bound / every) + 1) * every; // inf if every is subnormal
  if (std::isfinite(jump) && jump > next) next = jump;
  return next > bound ? next : std::nextafter(bound, std::numeric_limits<double>::infinity());
}

Outputs::Outputs(const Simulation& sim, OutputOptions options)
    : sim_(sim), opt_(std::move(options)) {
  // Rank 0 creates the directories; the others wait for it.
  collective_write(sim_.comm(), [&] {
    if (sim_.comm().rank() != 0) return;
    make_directories(opt_.directory);
    if (sim_.config().output_format != OutputFormat::exodus || sim_.sph())
      make_directories(opt_.directory + "/fields");
    // Temporaries a killed run left behind (every file is written as NAME.tmp, then
    // renamed): never a complete output, so they go.
    for (const std::string& dir : {opt_.directory, opt_.directory + "/fields"}) {
      std::error_code ec;
      for (const auto& entry : std::filesystem::directory_iterator(dir, ec))
        if (entry.path().extension() == ".tmp") std::filesystem::remove(entry.path(), ec);
    }
  });
  // Under mpirun, OpenMPI gives rank 0 a pseudo-terminal whatever mpirun's own output is
  // (a log file too): there, periodic lines are the safe choice.
  tty_ = sim_.comm().rank() == 0 && ::isatty(STDOUT_FILENO) &&
         std::getenv("OMPI_COMM_WORLD_SIZE") == nullptr;
}

Outputs::~Outputs() {
  if (history_) std::fclose(history_);
}

double Outputs::loop_seconds() const {
  return wall_seconds() - start_wall_;
}

std::string Outputs::history_header() const {
  const Config& c = sim_.config();
  std::string h = "time,cycle,dt,kinetic,internal,hourglass,contact,external_work,total";
  for (const auto& p : c.probes)
    for (const char* f : {"ux", "uy", "uz", "vx", "vy", "vz"})
      h += fmt::format(",{}.{}", p.name, f);
  for (const auto& p : c.element_probes)
    for (const char* f : {"sxx", "syy", "szz", "sxy", "syz", "szx", "plastic_strain"})
      h += fmt::format(",{}.{}", p.name, f);
  for (std::size_t w = 0; w < c.rigid_walls.size(); ++w) h += fmt::format(",wall{}.force", w);
  for (std::size_t b = 0; b < c.boundary_conditions.size(); ++b)
    for (const char* f : {"fx", "fy", "fz"}) h += fmt::format(",bc{}.{}", b, f);
  for (std::size_t b = 0; b < c.boundary_conditions.size(); ++b)
    if (c.boundary_conditions[b].holds_spin())
      for (const char* f : {"mx", "my", "mz"}) h += fmt::format(",bc{}.{}", b, f);
  for (const auto& p : c.parts)
    if (p.rigid && p.merge_with.empty()) // a body, named after its lead
      for (const char* f : {"ux", "uy", "uz", "vx", "vy", "vz", "wx", "wy", "wz"})
        h += fmt::format(",rigid.{}.{}", p.name, f);
  if (c.part_energies) {
    std::vector<std::string> names;
    for (const auto& p : c.parts) names.push_back(p.name);
    for (const auto& p : c.particles) names.push_back(p.name);
    for (const auto& n : names)
      for (const char* f : {"kinetic", "internal", "hourglass"})
        h += fmt::format(",part.{}.{}", n, f);
  }
  return h;
}

void Outputs::begin() {
  start_wall_ = last_progress_wall_ = wall_seconds();
  const Config& c = sim_.config();
  if (sim_.comm().rank() == 0) {
    history_ = std::fopen((opt_.directory + "/history.csv").c_str(), "w");
    if (!history_) throw InputError("cannot write " + opt_.directory + "/history.csv");
    std::fprintf(history_, "%s\n", history_header().c_str());
    std::fflush(history_);
  }
  // The t = 0 row is written once the first step has completed it (after_step()); the
  // state the deck gave stands in if no step completes (collective).
  initial_ = sim_.sample();
  initial_row_due_ = true;
  ScopedPhase t(output_timer_, Phase::output); // (the t = 0 fields: QA round 20)
  if (c.output_format != OutputFormat::vtu) open_exodus("results");
  write_fields();
  next_fields_ = c.fields_every > 0 ? c.fields_every : std::numeric_limits<double>::infinity();
  next_history_ = c.history_every;
}

void Outputs::resume(const OutputState& state, const std::string& from) {
  start_wall_ = last_progress_wall_ = wall_seconds();
  next_fields_ = state.next_fields;
  next_history_ = state.next_history;
  field_count_ = state.field_count;
  pvd_ = state.pvd;
  particle_pvd_ = state.particle_pvd;
  // Restarted into another directory: the series' earlier entries are the checkpoint
  // directory's files, referenced from here.
  namespace fs = std::filesystem;
  const fs::path from_dir = from.empty() ? fs::path(".") : fs::path(from);
  std::error_code e1, e2, e3;
  fs::path old_dir = fs::weakly_canonical(from_dir, e1);
  const fs::path new_dir = fs::weakly_canonical(opt_.directory, e2);
  if (e1) old_dir = from_dir;
  if (!e1 && !e2 && old_dir != new_dir) {
    const fs::path up = fs::relative(old_dir, new_dir, e3);
    if (!e3)
      for (auto* series : {&pvd_, &particle_pvd_})
        for (auto& [t, file] : *series) file = (up / file).lexically_normal().generic_string();
  }
  last_field_cycle_ = sim_.clock().cycle; // the fields at the checkpoint were written then
  start_cycle_ = sim_.clock().cycle;
  start_fraction_ = last_progress_fraction_ = fraction_done();
  // A restart may run on another number of ranks, so the Exodus files of the first run
  // cannot be extended: the continuation goes to results-sCYCLE.exo[.P.R], starting with
  // the checkpoint's state (the earlier files stay as they were).
  if (sim_.config().output_format != OutputFormat::vtu) {
    ScopedPhase t(output_timer_, Phase::output);
    open_exodus(fmt::format("results-s{:06d}", sim_.clock().cycle));
    VtuPiece piece = fe_piece(sim_);
    if (exodus_)
      collective_write(sim_.comm(), [&] { exodus_->write_step(sim_.clock().time, piece); });
  }
  if (sim_.comm().rank() != 0) return;
  // Keep the history rows before the restart time (a killed run may have written rows past
  // its last checkpoint), then append.
  const std::string path = opt_.directory + "/history.csv";
  const std::string old_path = (old_dir / "history.csv").string();
  std::vector<std::string> keep;
  // What the checkpoint's directory lacks (a checkpoint copied alone elsewhere) is said,
  // and left out of the series.
  auto warn = [](const std::string& w) { std::fprintf(stderr, "anvil: warning: %s\n", w.c_str()); };
  if (!fs::exists(old_path) && sim_.clock().cycle > 0)
    warn(fmt::format("restart: {} does not exist; history.csv starts at the checkpoint", old_path));
  for (auto [series, name] : {std::pair{&pvd_, "results.pvd"}, {&particle_pvd_, "particles.pvd"}}) {
    const auto n = series->size();
    std::erase_if(*series, [&](const auto& entry) {
      return !fs::exists(fs::path(opt_.directory) / entry.second);
    });
    if (series->size() < n)
      warn(fmt::format("restart: {} of {}'s outputs before the checkpoint are not in {}; it "
                       "lists those that are",
                       n - series->size(), name, old_dir.string()));
  }
  std::string old_header;
  bool have_old = false;
  if (std::FILE* in = std::fopen(old_path.c_str(), "r")) {
    have_old = true;
    char* line = nullptr;
    std::size_t cap = 0;
    bool header = true;
    while (getline(&line, &cap, in) > 0) {
      std::string l(line);
      if (!l.empty() && l.back() == '\n') l.pop_back();
      if (header) {
        header = false;
        old_header = l;
        continue;
      }
      if (std::strtod(l.c_str(), nullptr) < sim_.clock().time) keep.push_back(l);
    }
    std::free(line);
    std::fclose(in);
  }
  // The end-of-run row of the run that wrote the checkpoint, off its series, is not a row
  // of the run continued (QA rounds 29, 30: a restart from a cycle-limit stop kept it).
  if (have_old && state.history_rows >= 0 &&
      static_cast<std::int64_t>(keep.size()) > state.history_rows &&
      (state.history_rows == 0 ||
       keep[static_cast<std::size_t>(state.history_rows - 1)] == state.history_last))
    keep.resize(static_cast<std::size_t>(state.history_rows));
  // The rows must be the checkpoint's run's: a later run in that directory (another deck,
  // or the same one run again from the start past it) wrote over its history and fields
  // (QA round 12: copied as this run's, without a word).
  if (have_old && state.history_rows >= 0 &&
      (static_cast<std::int64_t>(keep.size()) != state.history_rows ||
       (!keep.empty() && keep.back() != state.history_last))) {
    warn(fmt::format("restart: {} is not the history of the run that wrote the checkpoint (its "
                     "rows before t = {:.9g} s differ: a later run wrote over that directory); "
                     "history.csv and the field series start at the checkpoint",
                     old_path, sim_.clock().time));
    keep.clear();
    pvd_.clear();
    particle_pvd_.clear();
    std::error_code ignored; // (the series files list the later run's fields)
    fs::remove(fs::path(opt_.directory) / "results.pvd", ignored);
    fs::remove(fs::path(opt_.directory) / "particles.pvd", ignored);
  }
  // The run's energies so far (external_work and total, the 8th and 9th column of every
  // row), the scale of its balance error.
  for (const auto& l : keep) {
    std::istringstream row(l);
    std::string cell;
    for (int column = 0; std::getline(row, cell, ','); ++column)
      if (column == 7 || column == 8) note_energy(std::strtod(cell.c_str(), nullptr));
  }
  // Other columns (the deck's probes or rigid walls changed): the earlier rows keep their
  // own header in a file of their own, history.csv starts at the checkpoint.
  if (!keep.empty() && old_header != history_header()) {
    const std::string before =
        fmt::format("{}/history-before-s{:06d}.csv", opt_.directory, sim_.clock().cycle);
    std::string text = old_header + "\n";
    for (const auto& l : keep) text += l + "\n";
    write_file_atomic(before, text);
    warn(fmt::format("restart: the deck's history columns (probes, rigid walls, boundary "
                     "conditions) differ from "
                     "those of the run that wrote the checkpoint: history.csv starts at the "
                     "checkpoint, its {} earlier rows are in {}",
                     keep.size(), before));
    keep.clear();
  }
  std::string text = history_header() + "\n";
  for (const auto& l : keep) text += l + "\n";
  history_rows_ = static_cast<std::int64_t>(keep.size());
  history_last_ = keep.empty() ? std::string() : keep.back();
  write_file_atomic(path, text);
  history_ = std::fopen(path.c_str(), "a");
  if (!history_) throw InputError("cannot write " + path);
  // Drop what a killed run may have listed past its checkpoint (as for the history).
  if (!pvd_.empty()) write_pvd(opt_.directory + "/results.pvd", pvd_);
  if (!particle_pvd_.empty()) write_pvd(opt_.directory + "/particles.pvd", particle_pvd_);
}

OutputState Outputs::state() const {
  return {next_fields_, next_history_, 0.0,           field_count_,
          pvd_,         particle_pvd_, history_rows_, history_last_};
}

void Outputs::note_energy(double e) {
  if (std::isfinite(e)) energy_scale_ = std::max(energy_scale_, std::abs(e));
}

void Outputs::write_history_row(const Sample& s, bool scheduled) {
  note_energy(s.total());
  note_energy(s.external_work);
  if (!history_) return;
  std::string row = fmt::format(
      "{:.17g},{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}", s.time, s.cycle, s.dt,
      s.kinetic, s.internal, s.hourglass, s.contact, s.external_work, s.total());
  for (double v : s.probes) row += fmt::format(",{:.17g}", v);
  for (double v : s.element_probes) row += fmt::format(",{:.17g}", v);
  for (double v : s.wall_force) row += fmt::format(",{:.17g}", v);
  for (double v : s.reaction) row += fmt::format(",{:.17g}", v);
  for (double v : s.reaction_moment) row += fmt::format(",{:.17g}", v);
  for (double v : s.rigid_bodies) row += fmt::format(",{:.17g}", v);
  for (double v : s.part_energies) row += fmt::format(",{:.17g}", v);
  std::fprintf(history_, "%s\n", row.c_str());
  std::fflush(history_);
  if (!scheduled) return;
  ++history_rows_;
  history_last_ = std::move(row);
}

void Outputs::after_step() {
  ScopedPhase t(output_timer_, Phase::output);
  const Config& c = sim_.config();
  const Clock& clk = sim_.clock();
  const double t_sample = clk.time - clk.dt; // the step's forces were at t(n)
  const bool last = sim_.finished();
  // A step completes the sample of the time it started from, t(n): velocities are the
  // mean of v(n-1/2) and the corrected v(n+1/2), and the walls' forces include the
  // impulses of that step. So the first step gives the t = 0 row's probes and wall forces
  // (a body that starts on a wall is stopped by it there, and the row holds that
  // impulse). Its energies stay those the deck gave, E0: the first step's kinetic energy
  // already holds what the viscous forces at t = 0 take, whose internal energy the next
  // stress update books (a balance error of 1.5e-4 in the Taylor bar's t = 0 row).
  if (initial_row_due_) {
    initial_row_due_ = false;
    Sample s = sim_.sample();
    s.kinetic = initial_.kinetic;
    s.internal = initial_.internal;
    s.hourglass = initial_.hourglass;
    s.contact = initial_.contact;
    s.external_work = initial_.external_work;
    last_sample_ = s;
    have_sample_ = true;
    write_history_row(last_sample_);
  } else if (const bool due = t_sample >= next_history_ * (1 - 1e-12); due || last) {
    last_sample_ = sim_.sample();
    have_sample_ = true;
    write_history_row(last_sample_, due);
    if (due && c.history_every > 0)
      next_history_ = next_output_time(next_history_, c.history_every, t_sample);
  }
  if (clk.time >= next_fields_ * (1 - 1e-12) || last) {
    write_fields();
    if (c.fields_every > 0) next_fields_ = next_output_time(next_fields_, c.fields_every, clk.time);
  }
  // Contact about to lose a node (QA round 36: a punch at 3 km/s went through a block three
  // elements thick, unflagged): said once, when it happens, on a line of its own.
  if (const ContactPhase* cp = sim_.contact();
      cp != nullptr && !deep_warned_ && cp->stats().max_penetration_of_depth >= 1.0) {
    deep_warned_ = true;
    if (sim_.comm().rank() == 0)
      std::fprintf(stderr,
                   "%sanvil: warning: t = %.6g s: a contact node is %.0f%% of its face's contact "
                   "depth behind the face (the deepest so far: %.3g mm): new pairs are taken only "
                   "to 100%% and a pair is "
                   "released past 200%%, so nodes may pass through faces unseen (tunnelling); "
                   "raise the contact's penalty_scale or lower time_step.scale "
                   "(docs/contact.md, \"Tunnelling\")\n",
                   tty_ && opt_.progress ? "\n" : "", t_sample,
                   100 * cp->stats().max_penetration_of_depth, 1e3 * cp->stats().max_penetration);
  }
  progress(last);
}

void Outputs::open_exodus(const std::string& stem) {
  // Exodus holds the mesh; particles go to particles.pvd whatever the format.
  if (sim_.global_elements() == 0) {
    if (sim_.comm().rank() == 0)
      std::fprintf(stderr, "anvil: warning: the model has no elements, so no Exodus II file is "
                           "written (the particles are in particles.pvd)\n");
    return;
  }
  const VtuPiece layout = fe_piece(sim_); // collective: every rank lists the same arrays
  collective_write(sim_.comm(), [&] {
    exodus_ = std::make_unique<ExodusWriter>(
        exodus_path(opt_.directory, sim_.comm().size(), sim_.comm().rank(), stem), sim_, layout);
  });
}

void Outputs::write_fields() {
  const Clock& clk = sim_.clock();
  if (last_field_cycle_ == clk.cycle) return;
  last_field_cycle_ = clk.cycle;
  VtuPiece piece = fe_piece(sim_);
  piece.time = clk.time;
  if (exodus_) collective_write(sim_.comm(), [&] { exodus_->write_step(clk.time, piece); });
  const std::string stem = fmt::format("step_{:06d}", field_count_++);
  // Particles have no place in the Exodus files: they are always written as VTU.
  if (sim_.sph()) write_particles(stem);
  if (sim_.config().output_format == OutputFormat::exodus) return;
  write_series(stem, piece, pvd_, "results.pvd");
}

// One output of a VTU series: this rank's piece fields/NAME_rRRRR.vtu, then on rank 0
// fields/NAME.pvtu and the series' .pvd. Every piece is complete before the index names
// it; a rank that cannot write its piece stops every rank with its message (alone, it
// left the others waiting in the next collective: QA round 20).
void Outputs::write_series(const std::string& name, const VtuPiece& piece,
                           std::vector<std::pair<double, std::string>>& series,
                           const std::string& pvd) {
  collective_write(sim_.comm(), [&] {
    write_vtu(fmt::format("{}/fields/{}_r{:04d}.vtu", opt_.directory, name, sim_.comm().rank()),
              piece);
  });
  collective_write(sim_.comm(), [&] {
    if (sim_.comm().rank() != 0) return;
    std::vector<std::string> pieces;
    for (int r = 0; r < sim_.comm().size(); ++r)
      pieces.push_back(fmt::format("{}_r{:04d}.vtu", name, r));
    write_pvtu(fmt::format("{}/fields/{}.pvtu", opt_.directory, name), pieces, piece);
    series.emplace_back(piece.time, fmt::format("fields/{}.pvtu", name));
    write_pvd(opt_.directory + "/" + pvd, series);
  });
}

// The particles of the same output as their own series (particles.pvd): one .vtu piece
// per rank of the SPH decomposition, vertices only.
void Outputs::write_particles(const std::string& stem) {
  const Clock& clk = sim_.clock();
  VtuPiece piece = particle_piece(sim_);
  piece.time = clk.time;
  write_series("particles_" + stem, piece, particle_pvd_, "particles.pvd");
}

double Outputs::fraction_done() const {
  const Config& c = sim_.config();
  const Clock& clk = sim_.clock();
  double frac = 0;
  if (std::isfinite(c.end_time)) frac = clk.time / c.end_time;
  if (c.end_cycles < std::numeric_limits<std::int64_t>::max())
    frac = std::max(frac, static_cast<double>(clk.cycle) /
                              static_cast<double>(std::max<std::int64_t>(c.end_cycles, 1)));
  return std::min(frac, 1.0);
}

void Outputs::progress(bool last) {
  if (!opt_.progress || sim_.comm().rank() != 0) return;
  const Clock& clk = sim_.clock();
  const double frac = fraction_done();
  const double now = wall_seconds();
  const bool due = tty_
                       ? (now - last_progress_wall_ >= 0.25)
                       : (frac - last_progress_fraction_ >= 0.1 || now - last_progress_wall_ >= 30);
  if (!due && !last) return;
  last_progress_wall_ = now;
  last_progress_fraction_ = frac;
  const double elapsed = now - start_wall_;
  // This run's own progress: a restarted run counts from its checkpoint.
  const double done = frac - start_fraction_;
  const double eta = done > 0 ? elapsed * (1 - frac) / done : 0;
  const double n =
      static_cast<double>(sim_.global_elements() + (sim_.sph() ? sim_.sph()->global_count() : 0));
  const std::int64_t cycles = clk.cycle - start_cycle_;
  const double grind = cycles > 0 ? elapsed / static_cast<double>(cycles) / n * 1e6 : 0;
  const std::string line =
      fmt::format("cycle {:>8}  t {:.4e} s  dt {:.3e} s  {:5.1f}%  left {:6.1f} s  grind {:.4f} us",
                  clk.cycle, clk.time, clk.dt, 100 * frac, eta, grind);
  if (tty_)
    std::printf("\r%s%s", line.c_str(), last ? "\n" : "");
  else
    std::printf("%s\n", line.c_str());
  std::fflush(stdout);
}

void Outputs::finish(int status, const std::string& message) {
  if (initial_row_due_) { // no step completed: the state the deck gave
    initial_row_due_ = false;
    write_history_row(initial_);
  }
  // A run stopped by a signal may be killed soon after (mpirun kills its ranks about a
  // second after passing the signal on): its summary goes first, the last fields after.
  const bool stopping = status >= 128;
  if (stopping) write_summary(status, message);
  {
    ScopedPhase t(output_timer_, Phase::output);
    write_fields();
  }
  if (!stopping) write_summary(status, message);
}

void Outputs::write_summary(int status, const std::string& message) {
  const Comm& comm = sim_.comm();
  const double wall = loop_seconds();
  const auto& timers = sim_.timers().all();
  std::vector<double> tmax(timers.begin(), timers.end());
  tmax[static_cast<int>(Phase::output)] += output_timer_.seconds(Phase::output);
  std::vector<double> tsum = tmax;
  // Each rank's own seconds by phase (rank-major), to tell work from waits.
  std::vector<double> by_rank(tmax.size() * static_cast<std::size_t>(comm.size()));
  comm.allgather_bytes(tmax.data(), tmax.size() * sizeof(double), by_rank.data());
  comm.max(std::span<double>(tmax));
  comm.sum(std::span<double>(tsum));
  const Sample s = have_sample_ ? last_sample_ : sim_.sample();
  const ContactStats contact_stats = sim_.contact() ? sim_.contact()->stats() : ContactStats{};
  const double bytes_max = comm.max(contact_stats.bytes_sent);
  const std::int64_t list_builds_max = comm.max(contact_stats.list_builds);
  const std::int64_t eroded = comm.sum(sim_.eroded_local());
  const sph::SphStats sph_stats = sim_.sph() ? sim_.sph()->stats() : sph::SphStats{};
  double sph_seconds[4] = {sph_stats.seconds_compute, sph_stats.seconds_ghosts,
                           sph_stats.seconds_migrate, sph_stats.seconds_rebalance};
  comm.max(std::span<double>(sph_seconds, 4));
  const std::int64_t particles = sim_.sph() ? sim_.sph()->global_count() : 0;
  if (comm.rank() != 0) return;
  using nlohmann::json;
  const Clock& clk = sim_.clock();
  const double n = static_cast<double>(sim_.global_elements() + particles);
  // The wall time is this run's (a restarted run's own), so are the cycles it divides.
  const double cycles = static_cast<double>(std::max<std::int64_t>(clk.cycle - start_cycle_, 1));
  json j;
  j["anvil_version"] = std::string(version);
  j["title"] = sim_.config().title;
  j["deck"] = sim_.config().deck_file;
  // A run stopped by a signal (exit 128 + N, a checkpoint written) can go on: "stopped".
  j["status"] = status == 0 ? "completed" : status >= 128 ? "stopped" : "failed";
  j["exit_status"] = status;
  if (!message.empty()) j["message"] = message;
  j["ranks"] = comm.size();
  j["nodes"] = sim_.global_nodes();
  j["elements"] = sim_.global_elements();
  j["particles"] = particles;
  j["cycles"] = clk.cycle;
  if (start_cycle_ > 0) j["restart_cycle"] = start_cycle_; // wall time and grind: from here
  j["eroded_elements"] = eroded;
  j["time"] = clk.time;
  j["dt_initial"] = clk.dt_initial;
  j["dt_final"] = clk.dt;
  j["wall_seconds"] = wall;
  // (A run that took no cycle has no grind time: 0, not its setup's wall time.)
  const double per = clk.cycle > start_cycle_ && n > 0 ? 1e6 / cycles / n : 0.0;
  j["grind_us"] = wall * per;
  j["grind_us_compute"] = (wall - tmax[static_cast<int>(Phase::output)]) * per;
  json t, imb;
  for (std::size_t p = 0; p < tmax.size(); ++p) t[std::string(phase_names[p])] = tmax[p];
  j["timers"] = t;
  json tr;
  for (std::size_t p = 0; p < tmax.size(); ++p) {
    json col = json::array();
    for (int r = 0; r < comm.size(); ++r)
      col.push_back(by_rank[static_cast<std::size_t>(r) * tmax.size() + p]);
    tr[std::string(phase_names[p])] = col;
  }
  j["timers_by_rank"] = tr;
  auto ratio = [&](Phase p) {
    const double mean = tsum[static_cast<int>(p)] / comm.size();
    return mean > 0 ? tmax[static_cast<int>(p)] / mean : 1.0;
  };
  imb["fe"] = ratio(Phase::fe);
  imb["sph"] = ratio(Phase::sph);
  {
    const double cmax = tmax[static_cast<int>(Phase::contact_search)] +
                        tmax[static_cast<int>(Phase::contact_force)];
    const double cmean = (tsum[static_cast<int>(Phase::contact_search)] +
                          tsum[static_cast<int>(Phase::contact_force)]) /
                         comm.size();
    imb["contact"] = cmean > 0 ? cmax / cmean : 1.0;
  }
  j["imbalance"] = imb;
  if (contact_stats.cycles > 0) {
    j["contact"] = {{"cycles", contact_stats.cycles},
                    {"rebalances", contact_stats.rebalances},
                    {"pairs_last_cycle", contact_stats.pairs},
                    {"load_imbalance_last", contact_stats.imbalance},
                    {"load_imbalance_max", contact_stats.imbalance_max},
                    {"max_penetration", contact_stats.max_penetration},
                    {"max_penetration_resisted", contact_stats.max_penetration_resisted},
                    {"max_penetration_of_depth", contact_stats.max_penetration_of_depth},
                    {"candidate_list_builds_max", list_builds_max},
                    {"plan_builds", contact_stats.plan_builds},
                    {"lazy_cycles", contact_stats.lazy_cycles},
                    {"bytes_sent_per_rank_per_cycle_max",
                     bytes_max / static_cast<double>(contact_stats.cycles)}};
  }
  if (sph_stats.cycles > 0) {
    // Seconds are the largest over ranks; rebalances count RCB cuts, the first included.
    j["sph"] = {{"cycles", sph_stats.cycles},
                {"rebalances", sph_stats.rebalances},
                {"migrations", sph_stats.migrations},
                {"list_builds", sph_stats.list_builds},
                {"count_imbalance_last", sph_stats.imbalance},
                {"count_imbalance_max", sph_stats.imbalance_max},
                {"seconds_compute", sph_seconds[0]},
                {"seconds_ghosts", sph_seconds[1]},
                {"seconds_migrate", sph_seconds[2]},
                {"seconds_rebalance", sph_seconds[3]}};
  }
  j["energy"] = {{"time", s.time},
                 {"initial", sim_.initial_energy()},
                 {"kinetic", s.kinetic},
                 {"internal", s.internal},
                 {"hourglass", s.hourglass},
                 {"contact", s.contact},
                 {"external_work", s.external_work},
                 {"total", s.total()},
                 {"balance_error", sim_.balance_error(s, energy_scale_)}};
  json parts = json::array();
  for (const auto& p : sim_.config().parts) parts.push_back(p.name);
  j["parts"] = parts; // part index in the `part` cell field -> name
  json masses = json::object();
  for (std::size_t i = 0; i < sim_.config().parts.size(); ++i)
    masses[sim_.config().parts[i].name] = sim_.part_masses()[i];
  j["part_mass"] = masses;
  if (sim_.config().mass_scaling_step > 0) {
    json added = json::object();
    double total = 0;
    for (std::size_t i = 0; i < sim_.config().parts.size(); ++i) {
      added[sim_.config().parts[i].name] = sim_.part_added_masses()[i];
      total += sim_.part_added_masses()[i];
    }
    j["mass_scaling"] = {{"step", sim_.config().mass_scaling_step},
                         {"elements", sim_.mass_scaled_elements()},
                         {"added_mass", total},
                         {"part_added_mass", added}};
  }
  write_file_atomic(opt_.directory + "/summary.json", json_text(j, 2) + "\n");
}

} // namespace anvil
