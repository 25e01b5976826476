// The particles' part of Simulation: selections and conditions on particles, and the
// particles' share of the cycle's owner phases (predict, contact, update). The particle
// forces themselves are the SPH decomposition's (sph/sph_phase.hpp). Particles are
// coupled to the mesh only through contact: each is a contact node (slave) against the
// exterior faces, with an id after every node and face id.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "anvil/io/checkpoint.hpp"
#include "anvil/solver/model.hpp"
#include "anvil/solver/simulation.hpp"

namespace anvil {

std::vector<std::uint8_t> Simulation::select_particles(const Selection& sel) const {
  std::vector<std::uint8_t> out;
  if (!sph_) return out;
  const auto& pt = sph_->particles();
  const std::size_t n = pt.size();
  out.assign(n, 0);
  if (!sel.name.empty()) {
    // Deck node sets are inline selections; generated PART.SET sets hold mesh nodes only;
    // a keyword deck's node sets may list particles of its particle lists.
    const auto it = config_.node_sets.find(sel.name);
    if (it != config_.node_sets.end()) return select_particles(it->second);
    const auto& offsets = sph_->set_offsets();
    for (std::size_t i = 0; i < n; ++i) {
      const auto s = static_cast<std::size_t>(pt.set[i]);
      const ParticleList* list = config_.particles[s].list.get();
      if (!list) continue;
      const auto m = list->sets.find(sel.name);
      if (m != list->sets.end() &&
          std::binary_search(m->second.begin(), m->second.end(), pt.gid[i] - offsets[s]))
        out[i] = 1;
    }
    return out;
  }
  int set = -1;
  if (sel.part) {
    set = config_.particle_set(*sel.part);
    if (set < 0) return out; // a finite-element part
  }
  // Below 3 dimensions every particle lies on the plane z = 0 (the line y = z = 0)
  // whatever z (y) range its set was given, so a box selects by the model's coordinates
  // only: a box drawn around the set's shape still selects it.
  const int dims = config_.sph.dimensions;
  auto inside = [&](std::size_t i) {
    for (int c = 0; c < dims; ++c)
      if (!(pt.x[c][i] >= sel.box->lo[c] && pt.x[c][i] <= sel.box->hi[c])) return false;
    return true;
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (set >= 0 && pt.set[i] != set) continue;
    if (sel.box && !inside(i)) continue;
    out[i] = 1;
  }
  return out;
}

std::vector<std::int64_t> Simulation::selected_nodes(const Mesh& mesh, const Selection& sel) const {
  if (!sph_) return resolve_selection(mesh, config_, sel);
  // A deck node set is an inline selection: resolved as one, so that its errors are its
  // own (a box that selects none of a particle set's particles, below).
  if (!sel.name.empty())
    if (const auto it = config_.node_sets.find(sel.name); it != config_.node_sets.end())
      return selected_nodes(mesh, it->second);
  std::vector<std::int64_t> ids;
  std::optional<InputError> error;
  const bool names_particles = sel.part && config_.particle_set(*sel.part) >= 0;
  if (!names_particles) {
    try {
      ids = resolve_selection(mesh, config_, sel);
    } catch (const InputError& e) {
      error = e;
    }
  }
  const auto mask = select_particles(sel);
  const std::int64_t particles =
      comm_.sum(static_cast<std::int64_t>(std::count(mask.begin(), mask.end(), 1)));
  if (ids.empty() && particles == 0) {
    // A particle set always holds particles: only its box can leave it empty.
    if (names_particles)
      throw InputError(sel.where,
                       fmt::format("the box selects no particle of set '{}'", *sel.part));
    // An unknown set is best told by the node resolution's own message.
    if (error && !(sel.name.empty() && !sel.part)) throw *error;
    throw InputError(sel.where, "the selection contains no nodes or particles");
  }
  return ids;
}

void Simulation::apply_particle_conditions() {
  if (!sph_) return;
  auto& pt = sph_->particles();
  for (const auto& ic : config_.initial_conditions) {
    const auto mask = select_particles(ic.nodes);
    for (std::size_t i = 0; i < pt.size(); ++i) {
      if (!mask[i]) continue;
      const Vec3 r = Vec3{pt.x[0][i], pt.x[1][i], pt.x[2][i]} - ic.center;
      const Vec3 v = ic.velocity + cross(ic.angular_velocity, r);
      for (int k = 0; k < 3; ++k) pt.v[k][i] = v[k];
    }
  }
}

double Simulation::particle_kinetic_energy() const {
  if (!sph_) return 0;
  const auto& pt = sph_->particles();
  double ke = 0;
  for (std::size_t i = 0; i < pt.size(); ++i)
    ke += 0.5 * pt.mass[i] *
          (pt.v[0][i] * pt.v[0][i] + pt.v[1][i] * pt.v[1][i] + pt.v[2][i] * pt.v[2][i]);
  return ke;
}

double Simulation::particle_internal_energy() const {
  if (!sph_) return 0;
  const auto& pt = sph_->particles();
  double e = 0;
  for (std::size_t i = 0; i < pt.size(); ++i) e += pt.mass[i] * pt.energy[i];
  return e;
}

// Boundary conditions on particles: fixed or prescribed velocity components, set up
// once; the masks, values and time histories travel with the particles.
void Simulation::apply_particle_boundary_conditions() {
  if (!sph_) return;
  auto& pt = sph_->particles();
  const auto& bcs = config_.boundary_conditions;
  for (std::size_t b = 0; b < bcs.size(); ++b) {
    const auto& bc = bcs[b];
    const auto mask = select_particles(bc.nodes);
    const bool any = comm_.sum(static_cast<std::int64_t>(
                         std::count(mask.begin(), mask.end(), std::uint8_t{1}))) > 0;
    if (any && b >= 64)
      throw InputError(bc.where, "a particle model takes at most 64 boundary conditions on its "
                                 "particles (this is the 65th item of the list)");
    for (std::size_t i = 0; i < pt.size(); ++i) {
      if (!mask[i]) continue;
      for (std::size_t k = 0; k < 3; ++k)
        if (bc.prescribed ? bc.components[k] : bc.fix[k]) pt.bc_holders[k][i] |= 1ull << b;
    }
  }
  // Plane strain (1-D: uniaxial strain): the out-of-model velocity components are held
  // at 0, so that every particle stays on the model's plane (line). An initial velocity
  // there is removed at t = 0 like any constrained component (external work).
  for (std::size_t i = 0; i < pt.size(); ++i)
    for (int k = config_.sph.dimensions; k < 3; ++k) {
      pt.constrained[i] |= static_cast<std::uint8_t>(1u << k);
      pt.v_bc[k][i] = 0.0;
      pt.bc_source[k][i] = -1; // (the model's plane, not a condition of the deck)
    }
  refresh_particle_constraints(); // those of the conditions active at t = 0
  for (std::size_t i = 0; i < pt.size(); ++i)
    for (int k = 0; k < 3; ++k)
      if (pt.constrained[i] & (1u << k)) {
        const double v = particle_bc_velocity(k, i);
        if (const int b = pt.bc_source[k][i]; b >= 0 && v != pt.v[k][i])
          initial_impulses_.push_back(
              {global_nodes_ + pt.gid[i], b, k, 0, pt.mass[i] * (v - pt.v[k][i])});
        pt.v[k][i] = v;
      }
}

// The components the deck's conditions hold on own particles over the current step: each
// held by the last condition that holds it and is active (bc_active_), as for nodes
// (refresh_node_constraints), or free while none is; the model's plane keeps its own.
void Simulation::refresh_particle_constraints() {
  if (!sph_) return;
  auto& pt = sph_->particles();
  std::uint64_t active = 0;
  for (std::size_t b = 0; b < std::min<std::size_t>(bc_active_.size(), 64); ++b)
    if (bc_active_[b]) active |= 1ull << b;
  const auto& bcs = config_.boundary_conditions;
  for (std::size_t i = 0; i < pt.size(); ++i)
    for (int k = 0; k < config_.sph.dimensions; ++k) { // (the plane's are held always)
      if (pt.bc_holders[k][i] == 0) continue;
      const std::uint64_t on = pt.bc_holders[k][i] & active;
      const auto bit = static_cast<std::uint8_t>(1u << k);
      if (on == 0) {
        pt.bc_source[k][i] = -1;
        pt.constrained[i] = static_cast<std::uint8_t>(pt.constrained[i] & ~bit);
        continue;
      }
      const int b = 63 - std::countl_zero(on); // the last in the deck
      const auto& bc = bcs[static_cast<std::size_t>(b)];
      pt.bc_source[k][i] = b;
      pt.v_bc[k][i] = bc.prescribed ? bc.value[k] : 0.0;
      pt.constrained[i] = static_cast<std::uint8_t>(pt.constrained[i] | bit);
    }
}

// A constrained particle component's velocity over the current step: its value, times
// its condition's time history factor (update_prescribed_motions; 1 without a curve).
double Simulation::particle_bc_velocity(int k, std::size_t i) const {
  const auto& pt = sph_->particles();
  const int b = pt.bc_source[k][i];
  return b < 0 ? pt.v_bc[k][i] : pt.v_bc[k][i] * motion_factor_[static_cast<std::size_t>(b)];
}

// Cycle step 3 for the particles: v(n+1/2) = v(n-1/2) + dt_avg f / m (prescribed
// components take their value), the specific energy gains the work of viscosity and
// artificial stress over the same interval; adds the kinetic energy at the mid-point
// velocity to `ke` and the work of the constraints' and the body force's impulses to
// `work` (J), as predict() does for nodes.
void Simulation::predict_particles(double dt_avg, double& ke, ImpulseWork& work) {
  auto& pt = sph_->particles();
  const std::size_t n = pt.size();
  const auto rate = sph_->energy_rate();
  for (int k = 0; k < 3; ++k) {
    pv_prev_[k].resize(n);
    p_reaction_[k].resize(n);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const double inv_m = 1.0 / pt.mass[i];
    double avg2 = 0;
    for (int k = 0; k < 3; ++k) {
      const double old = pt.v[k][i];
      pv_prev_[k][i] = old;
      const double free = old + (dt_avg * pt.f[k][i] * inv_m + dt_avg * gravity_[k]);
      double nv = free;
      if (pt.constrained[i] & (1u << k)) {
        nv = particle_bc_velocity(k, i);
        // (As for nodes: the reaction holds the body force, its work is all but the
        // forces'.)
        work.add(pt.mass[i] * (nv - (old + dt_avg * pt.f[k][i] * inv_m)), old, nv);
        p_reaction_[k][i] = pt.mass[i] * (nv - free) / dt_avg;
      } else if (gravity_[k] != 0.0) {
        work.add(pt.mass[i] * gravity_[k] * dt_avg, old, nv); // (predict())
      }
      pt.v[k][i] = nv;
      const double a = 0.5 * (old + nv);
      avg2 += a * a;
    }
    ke += 0.5 * pt.mass[i] * avg2;
    pt.energy[i] += rate[i] * dt_avg;
  }
  for (std::size_t p = 0; p < probe_particle_.size(); ++p) {
    if (probe_particle_[p] < 0) continue;
    // Only the rank holding the particle now writes; the one that held it before must
    // not keep its old values (the history sums the slots over ranks).
    for (int k = 0; k < 6; ++k) probe_local_[6 * p + k] = 0.0;
    const int q = sph_->find(probe_particle_[p]);
    if (q < 0) continue;
    for (int k = 0; k < 3; ++k) probe_local_[6 * p + k] = pt.x[k][q] - pt.x0[k][q];
  }
}

// The particle probes' velocity at t(n), once v(n+1/2) is corrected (the rank holding the
// particle; predict_particles() zeroed the slots of the others).
void Simulation::sample_particle_probe_velocities() {
  const auto& pt = sph_->particles();
  for (std::size_t p = 0; p < probe_particle_.size(); ++p) {
    if (probe_particle_[p] < 0) continue;
    const int q = sph_->find(probe_particle_[p]);
    if (q < 0) continue;
    for (int k = 0; k < 3; ++k) probe_local_[6 * p + 3 + k] = 0.5 * (pv_prev_[k][q] + pt.v[k][q]);
  }
}

// The contact items of the particles in contact this cycle (cycle step 4): predicted
// position x + dt v(n+1/2), id offset past the mesh's nodes and faces, held by this rank.
std::vector<ContactNodeItem>& Simulation::particle_contact_items(double dt) {
  const auto& pt = sph_->particles();
  particle_items_.clear();
  particle_item_index_.clear();
  const std::int64_t offset = contact_->extra_gid_offset();
  for (std::size_t i = 0; i < pt.size(); ++i) {
    if (!sph_contact_set_[static_cast<std::size_t>(pt.set[i])]) continue;
    ContactNodeItem it{};
    it.gid = offset + pt.gid[i];
    it.holders = comm_.rank(); // (holder group r: this rank alone)
    for (int k = 0; k < 3; ++k) {
      it.x[k] = pt.x[k][i] + dt * pt.v[k][i];
      it.v[k] = pt.v[k][i];
    }
    it.mass = pt.mass[i];
    it.last_face = pt.last_face[i];
    particle_items_.push_back(it);
    particle_item_index_.push_back(static_cast<int>(i));
  }
  return particle_items_;
}

// Cycle step 5 for the particles: the penalty forces the contact phase returned change
// v(n+1/2) by dt_avg f / m; their work is added to `contact_work` (J), the change of the
// kinetic energy at t(n) to `kinetic` (J) and the constraints' work against them to
// `reaction` (J), as for nodes.
void Simulation::correct_particles(double& contact_work, double& kinetic, double& reaction) {
  auto& pt = sph_->particles();
  const auto f = contact_->extra_forces();
  const auto faces = contact_->extra_faces();
  for (std::size_t k = 0; k < particle_item_index_.size(); ++k) {
    const auto i = static_cast<std::size_t>(particle_item_index_[k]);
    pt.last_face[i] = faces[k];
    const double inv_m = dt_avg_ / pt.mass[i];
    for (int d = 0; d < 3; ++d) {
      if (f[k][d] == 0.0) continue;
      if (pt.constrained[i] & (1u << d)) {
        // As for nodes: the constraint cancels the impulse, the contact force still works
        // on the particle and the constraint's reaction (external work) takes it back.
        contact_work += f[k][d] * dt_avg_ * pt.v[d][i];
        reaction -= f[k][d] * dt_avg_ * pt.v[d][i];
        p_reaction_[d][i] -= f[k][d];
        continue;
      }
      const double before = 0.5 * (pv_prev_[d][i] + pt.v[d][i]);
      pt.v[d][i] += inv_m * f[k][d];
      const double after = 0.5 * (pv_prev_[d][i] + pt.v[d][i]);
      contact_work += f[k][d] * dt_avg_ * after;
      kinetic += 0.5 * pt.mass[i] * (after * after - before * before);
    }
  }
}

// Cycle step 6 for the particles: x(n+1) = x(n) + dt v(n+1/2).
void Simulation::update_particles(double dt) {
  auto& pt = sph_->particles();
  const std::size_t n = pt.size();
  for (int k = 0; k < 3; ++k) {
    double* x = pt.x[k].data();
    const double* v = pt.v[k].data();
#pragma omp simd
    for (std::size_t i = 0; i < n; ++i) x[i] += dt * v[i];
  }
}

// The particles' part of restore(): every rank overwrites the evolving state of the
// particles it holds (those of the deck's first partition), then the particles are
// partitioned afresh at their restored positions. What the deck fixes (set, mass,
// reference position, constraints) stays as the constructor made it.
void Simulation::restore_particles(const Checkpoint& c, const std::string& from) {
  sph::Particles& pt = sph_->particles();
  // Every rank must throw, not only the one missing a particle.
  const std::int64_t none = std::numeric_limits<std::int64_t>::max();
  std::int64_t missing = none;
  for (std::size_t i = 0; i < pt.size(); ++i)
    if (!std::binary_search(c.particle_gid.begin(), c.particle_gid.end(), pt.gid[i]))
      missing = std::min(missing, pt.gid[i]);
  missing = comm_.min(missing);
  if (missing != none) throw InputError(from + " lacks particle " + std::to_string(missing + 1));
  for (std::size_t i = 0; i < pt.size(); ++i) {
    const auto it = std::lower_bound(c.particle_gid.begin(), c.particle_gid.end(), pt.gid[i]);
    const auto k = static_cast<std::size_t>(it - c.particle_gid.begin());
    const double* d = &c.particle_data[k * Checkpoint::particle_values];
    for (int j = 0; j < 3; ++j) {
      pt.x[j][i] = d[j];
      pt.v[j][i] = d[3 + j];
    }
    pt.rho[i] = d[6];
    pt.h[i] = d[7];
    for (int j = 0; j < 6; ++j) pt.stress[j][i] = d[8 + j];
    pt.energy[i] = d[14];
    pt.plastic_strain[i] = d[15];
    pt.temperature[i] = d[16];
    pt.wave_speed[i] = d[17];
    pt.last_face[i] = c.particle_face[k];
  }
  sph_->redistribute();
}

// Own particles of the sets in contact that an element of a part in contact holds
// (elements_holding); each counts once.
std::int64_t Simulation::particles_inside_contact_parts(const Mesh& mesh) const {
  const auto& pt = sph_->particles();
  std::vector<Vec3> points;
  for (std::size_t i = 0; i < pt.size(); ++i)
    if (sph_contact_set_[static_cast<std::size_t>(pt.set[i])])
      points.push_back({pt.x[0][i], pt.x[1][i], pt.x[2][i]});
  const auto holder = elements_holding(mesh, contact_blocks(mesh), points, {});
  return comm_.sum(static_cast<std::int64_t>(
      std::count_if(holder.begin(), holder.end(), [](std::int64_t e) { return e >= 0; })));
}

} // namespace anvil
