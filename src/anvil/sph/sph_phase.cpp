#include "anvil/sph/sph_phase.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <fmt/format.h>

#include "anvil/core/simd.hpp"
#include "anvil/sph/lattice.hpp"

namespace anvil::sph {

namespace {
double seconds_since(PhaseTimers::clock::time_point t0) {
  return std::chrono::duration<double>(PhaseTimers::clock::now() - t0).count();
}
// The particles of set `ps`: its lattice, or its list (then `volume` is unused: each
// particle has its own mass or volume) with LS-DYNA's spacing (lattice.hpp); `notes` gains
// what the user should know of it.
Lattice set_points(const ParticleSetConfig& ps, int dimensions, std::vector<std::string>& notes) {
  if (ps.list) {
    const SourceLocation& h_at = ps.smoothing_where.file.empty() ? ps.where : ps.smoothing_where;
    if (dimensions != 3)
      throw InputError(ps.where, "particles given one by one need a three-dimensional model");
    Lattice out;
    out.points = ps.list->x;
    const CloudSpacing c = cloud_spacing(out.points);
    if (c.a >= 0) {
      const auto& id = ps.list->id;
      throw InputError(ps.where,
                       fmt::format("particles {} and {} of set '{}' are at the same point",
                                   id[static_cast<std::size_t>(std::min(c.a, c.b))],
                                   id[static_cast<std::size_t>(std::max(c.a, c.b))], ps.name));
    }
    if (out.points.empty())
      throw InputError(ps.where, fmt::format("particle set '{}' holds no particle", ps.name));
    if (c.spacing == 0 && !(ps.smoothing_length > 0))
      throw InputError(h_at, fmt::format("particle set '{}' holds a single particle, which "
                                         "has no spacing to take its smoothing length "
                                         "from: give the smoothing length",
                                         ps.name));
    if (ps.smoothing_length > 0 && c.spacing > 0) {
      const double ratio = ps.smoothing_length / c.spacing;
      if (!(ratio >= 0.8 && ratio <= 3))
        throw InputError(h_at, fmt::format("particle set '{}': the smoothing length {:.6g} m "
                                           "is {:.3g} times the particles' spacing {:.6g} m "
                                           "(the largest distance from a particle to its "
                                           "nearest neighbour); it must be between 0.8 and 3 "
                                           "times",
                                           ps.name, ps.smoothing_length, ratio, c.spacing));
    }
    // One stray particle (a typo in a coordinate) sets the spacing, and h0, of the whole
    // set by LS-DYNA's rule (QA round 32: one particle 1 m off made h0 1.18 m, every
    // particle every other's neighbour).
    if (c.spacing > 4 * c.median && !(ps.smoothing_length > 0)) {
      const auto f = static_cast<std::size_t>(c.farthest);
      notes.push_back(fmt::format(
          "{}: particle set '{}': its spacing, the largest distance from a particle to its "
          "nearest neighbour (LS-DYNA's rule for h0), is {:.6g} m, {:.3g} times the median "
          "{:.6g} m, from particle {} at [{:g}, {:g}, {:g}]: a stray particle? h0 = {:.6g} m "
          "for the whole set",
          ps.where.str(), ps.name, c.spacing, c.spacing / c.median, c.median, ps.list->id[f],
          out.points[f].x, out.points[f].y, out.points[f].z, ps.smoothing_ratio * c.spacing));
    }
    out.spacing = c.spacing > 0 ? c.spacing : ps.smoothing_length / ps.smoothing_ratio;
    return out;
  }
  const LatticeSpec& ls = ps.lattice;
  if (dimensions == 1 && ls.shape != LatticeSpec::Shape::box)
    throw InputError(ps.where, "a one-dimensional particle model takes boxes only");
  if (dimensions == 2 && ls.shape == LatticeSpec::Shape::cylinder && ls.axis != 2)
    throw InputError(ps.where, "in two dimensions a cylinder's axis must be z");
  Lattice out;
  try {
    out = generate_lattice(ls, dimensions);
  } catch (const std::bad_alloc&) {
    throw InputError(ps.where, "the particle lattice does not fit in memory");
  } catch (const std::length_error&) {
    throw InputError(ps.where, "the particle lattice does not fit in memory");
  }
  if (out.points.empty())
    throw InputError(ps.where, "the particle set's shape holds no lattice point: "
                               "make the spacing smaller than the shape");
  return out;
}
} // namespace

SphPhase::SphPhase(const Config& config, const std::function<const Material*(int)>& material,
                   const Comm& comm)
    : comm_(comm), rcb_(comm, config.decomposition.scale),
      threshold_(config.sph.rebalance_threshold) {
  const auto& psets = config.particles;
  for (std::size_t s = 0; s < psets.size(); ++s) {
    const auto& ps = psets[s];
    if (ps.kernel != psets[0].kernel)
      throw InputError({ps.where.file, ps.where.line, ps.where.key + ".kernel"},
                       "every particle set must use the same kernel");
  }
  if (!psets.empty())
    kernel_ = psets[0].kernel == ParticleSetConfig::Kernel::wendland_c2 ? KernelType::wendland_c2
                                                                        : KernelType::cubic_spline;
  // Every rank generates every lattice (deterministic), or takes every list, and keeps
  // its share of ids.
  std::vector<Lattice> lattices;
  set_offsets_.assign(1, 0);
  for (std::size_t s = 0; s < psets.size(); ++s) {
    const ParticleSetConfig& ps = psets[s];
    lattices.push_back(set_points(ps, config.sph.dimensions, notes_));
    set_offsets_.push_back(set_offsets_.back() +
                           static_cast<std::int64_t>(lattices.back().points.size()));
    const Material* m = material(static_cast<int>(s));
    SetParams sp;
    sp.material = m;
    sp.rho0 = m->elastic().density;
    const double spacing = lattices.back().spacing;
    sp.h0 = ps.smoothing_length > 0 ? ps.smoothing_length : ps.smoothing_ratio * spacing;
    sp.h_min = ps.h_min * sp.h0;
    sp.h_max = ps.h_max * sp.h0;
    sp.alpha = ps.viscosity_linear;
    sp.beta = ps.viscosity_quadratic;
    sp.epsilon = ps.artificial_stress;
    sp.exponent = ps.artificial_stress_exponent;
    sp.w_spacing =
        kernel_shape(kernel_, ps.smoothing_length > 0 ? spacing / sp.h0 : 1.0 / ps.smoothing_ratio);
    sp.corrected = ps.corrected_gradient;
    sp.summation = ps.summation_density;
    sp.dimensions = config.sph.dimensions;
    sets_.push_back(sp);
  }
  global_count_ = set_offsets_.back();
  const std::int64_t P = comm_.size(), r = comm_.rank();
  const std::int64_t first = global_count_ * r / P, last = global_count_ * (r + 1) / P;
  const auto n = static_cast<std::size_t>(last - first);
  p_.gid.resize(n);
  p_.set.resize(n);
  for (auto& a : p_.x) a.resize(n);
  for (auto& a : p_.v) a.assign(n, 0.0);
  p_.mass.resize(n);
  p_.rho.resize(n);
  p_.h.resize(n);
  for (auto& a : p_.f) a.assign(n, 0.0);
  for (auto& a : p_.stress) a.assign(n, 0.0);
  p_.energy.resize(n);
  p_.plastic_strain.assign(n, 0.0);
  p_.temperature.resize(n);
  p_.wave_speed.resize(n);
  p_.constrained.assign(n, 0);
  for (auto& a : p_.v_bc) a.assign(n, 0.0);
  for (auto& a : p_.bc_source) a.assign(n, -1);
  for (auto& a : p_.bc_holders) a.assign(n, 0);
  p_.last_face.assign(n, -1);
  std::size_t k = 0;
  for (std::int64_t g = first; g < last; ++g, ++k) {
    const auto s = static_cast<std::size_t>(
        std::upper_bound(set_offsets_.begin(), set_offsets_.end(), g) - set_offsets_.begin() - 1);
    const Vec3& x = lattices[s].points[static_cast<std::size_t>(g - set_offsets_[s])];
    const SetParams& sp = sets_[s];
    p_.gid[k] = g;
    p_.set[k] = static_cast<int>(s);
    for (int i = 0; i < 3; ++i) p_.x[i][k] = x[i];
    const std::size_t j = static_cast<std::size_t>(g - set_offsets_[s]);
    const ParticleList* list = psets[s].list.get();
    p_.mass[k] = list && list->mass[j] > 0
                     ? list->mass[j]
                     : sp.rho0 * (list ? list->volume[j] : lattices[s].volume);
    p_.rho[k] = sp.rho0;
    p_.h[k] = sp.h0;
    const double p0 = sp.material->initial_pressure();
    for (int i = 0; i < 3; ++i) p_.stress[i][k] = -p0;
    p_.energy[k] = sp.material->initial_energy();
    p_.temperature[k] = sp.material->initial_temperature();
    p_.wave_speed[k] = std::sqrt(sp.material->elastic().plane_wave_modulus() / sp.rho0);
  }
  p_.x0 = p_.x;

  // The first partition, and every particle to its box.
  redistribute();
}

double SphPhase::initial_step() const {
  double dt = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < p_.size(); ++i) {
    const SetParams& sp = sets_[static_cast<std::size_t>(p_.set[i])];
    const double c = p_.wave_speed[i];
    double d = courant * p_.h[i] / (c + 1.2 * sp.alpha * c);
    const double v2 = p_.v[0][i] * p_.v[0][i] + p_.v[1][i] * p_.v[1][i] + p_.v[2][i] * p_.v[2][i];
    if (v2 > 0) d = std::min(d, max_move * p_.h[i] / std::sqrt(v2));
    dt = std::min(dt, d);
  }
  return comm_.min(dt);
}

void SphPhase::redistribute() {
  const RcbPoints pts{p_.x[0], p_.x[1], p_.x[2], p_.gid, {}};
  rcb_.partition(pts);
  ++stats_.rebalances;
  dest_.assign(rcb_.destinations().begin(), rcb_.destinations().end());
  migrate(dest_);
}

int SphPhase::find(std::int64_t gid) const {
  const std::size_t n = p_.size();
  const auto it =
      std::lower_bound(p_.gid.begin(), p_.gid.begin() + static_cast<std::ptrdiff_t>(n), gid);
  return it != p_.gid.begin() + static_cast<std::ptrdiff_t>(n) && *it == gid
             ? static_cast<int>(it - p_.gid.begin())
             : -1;
}

// Moves every field of every own particle to dest[i], then restores ascending gid.
void SphPhase::migrate(std::span<const int> dest) {
  lists_valid_ = false; // local indices change
  move_plan_.build(comm_, dest);
  const std::size_t nr = move_plan_.recv_count();
  auto move = [&](auto& field) {
    using T = typename std::decay_t<decltype(field)>::value_type;
    std::vector<T>* tmp = scratch<T>();
    tmp->resize(nr);
    move_plan_.forward(std::span<const T>(field), std::span<T>(*tmp));
    field.swap(*tmp);
  };
  p_.for_each_field(move);
  sort_by_gid();
}

void SphPhase::sort_by_gid() {
  const std::size_t n = p_.size();
  if (std::is_sorted(p_.gid.begin(), p_.gid.end())) return;
  perm_.resize(n);
  std::iota(perm_.begin(), perm_.end(), 0);
  std::sort(perm_.begin(), perm_.end(), [&](int a, int b) {
    return p_.gid[static_cast<std::size_t>(a)] < p_.gid[static_cast<std::size_t>(b)];
  });
  auto apply = [&](auto& field) {
    using T = typename std::decay_t<decltype(field)>::value_type;
    std::vector<T>& out = *scratch<T>();
    out.resize(n);
    for (std::size_t k = 0; k < n; ++k) out[k] = field[static_cast<std::size_t>(perm_[k])];
    field.swap(out);
  };
  p_.for_each_field(apply);
}

void SphPhase::resize_neighbour_fields(std::size_t n) {
  p_.gid.resize(n);
  p_.set.resize(n);
  for (auto& a : p_.x) a.resize(n);
  for (auto& a : p_.v) a.resize(n);
  p_.mass.resize(n);
  p_.rho.resize(n);
  p_.h.resize(n);
  p_.wave_speed.resize(n);
}

void SphPhase::exchange_ghosts_in() {
  const std::size_t n = p_.size();
  in_send_.resize(ghost_src_.size());
  for (std::size_t k = 0; k < ghost_src_.size(); ++k) {
    const auto i = static_cast<std::size_t>(ghost_src_[k]);
    GhostIn& g = in_send_[k];
    g.gid = p_.gid[i];
    g.set = p_.set[i];
    for (int d = 0; d < 3; ++d) {
      g.x[d] = p_.x[d][i];
      g.v[d] = p_.v[d][i];
    }
    g.mass = p_.mass[i];
    g.rho = p_.rho[i];
    g.h = p_.h[i];
  }
  ghost_plan_.forward(in_send_, in_recv_);
  const std::size_t ng = in_recv_.size();
  resize_neighbour_fields(n + ng);
  for (std::size_t k = 0; k < ng; ++k) {
    const GhostIn& g = in_recv_[k];
    const std::size_t i = n + k;
    p_.gid[i] = g.gid;
    p_.set[i] = g.set;
    for (int d = 0; d < 3; ++d) {
      p_.x[d][i] = g.x[d];
      p_.v[d][i] = g.v[d];
    }
    p_.mass[i] = g.mass;
    p_.rho[i] = g.rho;
    p_.h[i] = g.h;
  }
}

void SphPhase::exchange_ghosts_out() {
  using Rec = NeighbourRead2;
  const std::size_t n = p_.stress[0].size(); // own particles (not extended)
  out_send_.resize(ghost_src_.size());
  for (std::size_t k = 0; k < ghost_src_.size(); ++k) {
    const auto i = static_cast<std::size_t>(ghost_src_[k]);
    const double* r = work_.read2[i].a; // pass 1 wrote S0-S5, rho and c there
    GhostOut& g = out_send_[k];
    for (int c = 0; c < 6; ++c) g.S[c] = r[Rec::S + c];
    for (int c = 0; c < 3; ++c) g.S[6 + c] = S678_[c][i];
    for (int c = 0; c < 6; ++c) g.R[c] = R_[c][i];
    g.rho = r[Rec::rho];
    g.c = r[Rec::c];
  }
  ghost_plan_.forward(out_send_, out_recv_);
  for (std::size_t k = 0; k < out_recv_.size(); ++k) {
    const GhostOut& g = out_recv_[k];
    const std::size_t i = n + k;
    // Into the ghost's record (pass 1 wrote its x, h, v and volume) and the rest's arrays.
    double* r = work_.read2[i].a;
    for (int c = 0; c < 6; ++c) r[Rec::S + c] = g.S[c];
    r[Rec::rho] = g.rho;
    r[Rec::mass] = p_.mass[i];
    r[Rec::c] = g.c;
    for (int c = 0; c < 3; ++c) S678_[c][i] = g.S[6 + c];
    for (int c = 0; c < 6; ++c) R_[c][i] = g.R[c];
    p_.rho[i] = g.rho;
    p_.wave_speed[i] = g.c;
  }
}

void SphPhase::forces(double dt_prev, PhaseTimers& timers) {
  ++stats_.cycles;
  const int me = comm_.rank();
  std::size_t n = p_.size();

  // (1) Upkeep: one reduction of the largest count, the escape flag, the largest h and
  // the largest displacement since the candidate lists were built.
  bool rebuild = false;
  {
    ScopedPhase t(timers, Phase::sph);
    const Box3 box = rcb_.box(me);
    // simd::width particles at a time, then the rest one at a time: the same test and
    // maxima (a maximum is exact in any order; a NaN is skipped by both forms, and fails
    // Box3::contains as it fails the lanes' comparisons).
    using simd::vdouble;
    constexpr std::size_t w = simd::width;
    const bool moved = lists_valid_ && x_build_[0].size() == n;
    vdouble out_v = 0.0, hmax_v = 0.0, d2max_v = 0.0;
    std::size_t i0 = 0;
    for (; i0 + w <= n; i0 += w) {
      const vdouble x = simd::load(p_.x[0].data() + i0), y = simd::load(p_.x[1].data() + i0),
                    z = simd::load(p_.x[2].data() + i0), h = simd::load(p_.h.data() + i0);
      const auto in = x >= box.lo.x && x <= box.hi.x && y >= box.lo.y && y <= box.hi.y &&
                      z >= box.lo.z && z <= box.hi.z;
      simd::stdx::where(!in, out_v) = 1.0;
      simd::stdx::where(hmax_v < h, hmax_v) = h;
      if (!moved) continue;
      const vdouble dx = x - simd::load(x_build_[0].data() + i0),
                    dy = y - simd::load(x_build_[1].data() + i0),
                    dz = z - simd::load(x_build_[2].data() + i0);
      const vdouble d2 = dx * dx + dy * dy + dz * dz;
      simd::stdx::where(d2max_v < d2, d2max_v) = d2;
    }
    double escaped = 0, hmax = 0, d2max = 0;
    for (std::size_t l = 0; l < w; ++l) {
      escaped = std::max(escaped, static_cast<double>(out_v[l]));
      hmax = std::max(hmax, static_cast<double>(hmax_v[l]));
      d2max = std::max(d2max, static_cast<double>(d2max_v[l]));
    }
    for (std::size_t i = i0; i < n; ++i) {
      const Vec3 x{p_.x[0][i], p_.x[1][i], p_.x[2][i]};
      escaped = box.contains(x) ? escaped : 1.0;
      hmax = std::max(hmax, p_.h[i]);
      if (!moved) continue;
      const double dx = p_.x[0][i] - x_build_[0][i], dy = p_.x[1][i] - x_build_[1][i],
                   dz = p_.x[2][i] - x_build_[2][i];
      d2max = std::max(d2max, dx * dx + dy * dy + dz * dz);
    }
    if (!moved) d2max = std::numeric_limits<double>::infinity();
    double red[4] = {static_cast<double>(n), escaped, hmax, d2max};
    comm_.max(std::span<double>(red, 4));
    const double mean = static_cast<double>(global_count_) / comm_.size();
    stats_.imbalance = mean > 0 ? red[0] / mean : 1.0;
    stats_.imbalance_max = std::max(stats_.imbalance_max, stats_.imbalance);
    // The candidate lists hold every pair closer than radius_ at the build; a pair within
    // the support now (r < h_i + h_j <= 2 h_max) was closer than 2 h_max + 2 d_max then.
    // The margin covers the round-off of these sums. Every rank decides alike (the
    // inputs are reduced); the results do not depend on the decision (neighbours.hpp).
    const bool moved_far = !(2 * red[2] + 2 * std::sqrt(red[3]) < (1 - 1e-9) * radius_);
    if (stats_.imbalance > threshold_) {
      const auto t0 = PhaseTimers::clock::now();
      {
        ScopedPhase tr(timers, Phase::rebalance);
        const RcbPoints pts{std::span<const double>(p_.x[0]),
                            std::span<const double>(p_.x[1]),
                            std::span<const double>(p_.x[2]),
                            std::span<const std::int64_t>(p_.gid),
                            {}};
        rcb_.repartition(pts);
        ++stats_.rebalances;
      }
      stats_.seconds_rebalance += seconds_since(t0);
      const auto t1 = PhaseTimers::clock::now();
      {
        ScopedPhase tr(timers, Phase::transfer);
        dest_.assign(rcb_.destinations().begin(), rcb_.destinations().end());
        migrate(dest_);
      }
      stats_.seconds_migrate += seconds_since(t1);
      rebuild = true;
    } else if (moved_far) {
      rebuild = true;
    }
    // Particles that left their box move to the rank whose box holds them on a rebuild
    // only (as LAMMPS moves atoms on re-neighbouring steps): until then the ghost plan
    // still brings every neighbour of an escaped particle to its rank, since the
    // particle was inside the box at the build.
    if (rebuild && red[1] > 0 && !(stats_.imbalance > threshold_)) {
      const auto t1 = PhaseTimers::clock::now();
      ScopedPhase tr(timers, Phase::transfer);
      dest_.resize(n);
      for (std::size_t i = 0; i < n; ++i)
        dest_[i] = rcb_.owner({p_.x[0][i], p_.x[1][i], p_.x[2][i]});
      migrate(dest_);
      ++stats_.migrations;
      stats_.seconds_migrate += seconds_since(t1);
    }
    n = p_.size();
    hmax_ = red[2];
  }

  // (2) Ghosts: on a rebuild, copies of the particles within the candidate radius of
  // another rank's box (a plan kept until the next rebuild); every cycle, their state.
  {
    const auto t0 = PhaseTimers::clock::now();
    ScopedPhase t(timers, Phase::transfer);
    if (rebuild) {
      radius_ = 2 * support_factor * hmax_ / 2 * (1 + skin);
      const double reach = radius_ * (1 + 1e-9);
      const Box3 box = rcb_.box(me);
      ghost_src_.clear();
      ghost_dest_.clear();
      for (std::size_t i = 0; i < n; ++i) {
        const Vec3 x{p_.x[0][i], p_.x[1][i], p_.x[2][i]};
        const Box3 b{{x.x - reach, x.y - reach, x.z - reach},
                     {x.x + reach, x.y + reach, x.z + reach}};
        if (b.lo.x > box.lo.x && b.lo.y > box.lo.y && b.lo.z > box.lo.z && b.hi.x < box.hi.x &&
            b.hi.y < box.hi.y && b.hi.z < box.hi.z)
          continue;
        rcb_.overlapping(b, ranks_);
        for (int r : ranks_)
          if (r != me) {
            ghost_src_.push_back(static_cast<int>(i));
            ghost_dest_.push_back(r);
          }
      }
      ghost_plan_.build(comm_, ghost_dest_);
    }
    exchange_ghosts_in();
    stats_.ghosts = static_cast<std::int64_t>(in_recv_.size());
    stats_.seconds_ghosts += seconds_since(t0);
  }

  const std::size_t na = p_.gid.size();
  for (auto& a : S678_) a.resize(na);
  for (auto& a : R_) a.resize(na);
  for (auto& a : p_.f) a.resize(n);
  energy_rate_.resize(n);
  SphView view;
  view.n_local = n;
  view.n_all = na;
  view.gid = p_.gid.data();
  view.set = p_.set.data();
  for (int d = 0; d < 3; ++d) {
    view.x[d] = p_.x[d].data();
    view.v[d] = p_.v[d].data();
    view.force[d] = p_.f[d].data();
  }
  view.mass = p_.mass.data();
  view.h = p_.h.data();
  view.rho = p_.rho.data();
  for (int c = 0; c < 6; ++c) {
    view.stress[c] = p_.stress[c].data();
    view.R[c] = R_[c].data();
  }
  for (int c = 0; c < 3; ++c) view.S678[c] = S678_[c].data();
  view.energy = p_.energy.data();
  view.plastic_strain = p_.plastic_strain.data();
  view.temperature = p_.temperature.data();
  view.wave_speed = p_.wave_speed.data();
  view.energy_rate = energy_rate_.data();

  // (3)-(4) Neighbours and pass 1.
  {
    const auto t0 = PhaseTimers::clock::now();
    ScopedPhase t(timers, Phase::sph);
    if (rebuild) {
      find_candidates(p_.x[0], p_.x[1], p_.x[2], p_.gid, n, radius_, nwork_, candidates_);
      for (int d = 0; d < 3; ++d) x_build_[d].assign(p_.x[d].begin(), p_.x[d].begin() + n);
      lists_valid_ = true;
      ++stats_.list_builds;
    }
    sph_kinematics(view, sets_, kernel_, candidates_, dt_prev, work_);
    stats_.pairs = static_cast<std::int64_t>(work_.nl.pairs());
    stats_.seconds_compute += seconds_since(t0);
  }
  // (5) The ghosts' new state.
  {
    const auto t0 = PhaseTimers::clock::now();
    ScopedPhase t(timers, Phase::transfer);
    exchange_ghosts_out();
    stats_.seconds_ghosts += seconds_since(t0);
  }
  // (6) Pass 2, then the smoothing lengths for the next cycle.
  {
    const auto t0 = PhaseTimers::clock::now();
    ScopedPhase t(timers, Phase::sph);
    result_ = SphResult{};
    sph_forces(view, sets_, kernel_, work_, result_);
    resize_neighbour_fields(n);
    smoothing_lengths(sets_, p_.set.data(), p_.rho.data(), n, p_.h.data());
    stats_.seconds_compute += seconds_since(t0);
  }
}

} // namespace anvil::sph
