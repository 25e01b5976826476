// Rigid bodies (a part with `rigid: true`, LS-DYNA's *MAT_RIGID): the nodes of a rigid part
// move as one body. Each cycle every rank gathers the body's points (mass, position,
// velocity v(n - 1/2), force) from their owners, places them in the body's node order and
// computes the body's motion (fe/rigid_body.hpp), so every rank moves every body the same
// way on any number of ranks. The nodes are constrained in every component, their
// velocities prescribed by the motion: first from the forces of t(n) (predict, for the
// contact search), then again with the contact forces (correct).
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>

#include <fmt/format.h>

#include "anvil/core/error.hpp"
#include "anvil/solver/model.hpp"
#include "anvil/solver/simulation.hpp"

namespace anvil {

int Simulation::rigid_body_of(const BoundaryCondition& bc) const {
  if (!bc.nodes.name.empty() || bc.nodes.box || !bc.nodes.part) return -1;
  const std::vector<int> lead = rigid_body_leads(config_.parts);
  for (std::size_t p = 0; p < config_.parts.size(); ++p)
    if (config_.parts[p].rigid && config_.parts[p].name == *bc.nodes.part) return lead[p];
  return -1;
}

// A selection of a whole rigid part merged with others (merge_with): every part of its
// body, which moves as one (an initial velocity given to the lead is the body's).
std::vector<std::int64_t> Simulation::body_nodes(const Mesh& mesh, const Selection& sel) const {
  if (!sel.name.empty() || sel.box || !sel.part) return selected_nodes(mesh, sel);
  const std::vector<int> lead = rigid_body_leads(config_.parts);
  int body = -1;
  for (std::size_t p = 0; p < config_.parts.size(); ++p)
    if (config_.parts[p].name == *sel.part) body = lead[p];
  if (body < 0) return selected_nodes(mesh, sel);
  std::vector<std::int64_t> ids;
  for (std::size_t p = 0; p < config_.parts.size(); ++p) {
    if (lead[p] != body) continue;
    Selection part = sel;
    part.part = config_.parts[p].name;
    const auto more = selected_nodes(mesh, part);
    ids.insert(ids.end(), more.begin(), more.end());
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

void Simulation::setup_rigid_bodies(const Mesh& mesh) {
  const std::size_t nn = fe_.node_gid.size();
  rigid_gids_.clear();
  // The bodies in the deck order of their leads, each the nodes of its parts (the lead
  // and those merged into it).
  const std::vector<int> lead = rigid_body_leads(config_.parts);
  std::vector<std::size_t> part_of_body, rigid_parts;
  for (std::size_t b = 0; b < config_.parts.size(); ++b) {
    if (lead[b] >= 0) rigid_parts.push_back(b);
    if (lead[b] != static_cast<int>(b)) continue;
    std::vector<std::int64_t> gids;
    for (std::size_t m = 0; m < config_.parts.size(); ++m)
      if (lead[m] == static_cast<int>(b))
        for (const auto& h : mesh.blocks[m].elements) gids.insert(gids.end(), h.begin(), h.end());
    std::sort(gids.begin(), gids.end());
    gids.erase(std::unique(gids.begin(), gids.end()), gids.end());
    // Two bodies that share a node would be one: anvil keeps bodies apart.
    for (std::size_t o = 0; o < rigid_gids_.size(); ++o) {
      std::vector<std::int64_t> common;
      std::set_intersection(gids.begin(), gids.end(), rigid_gids_[o].begin(), rigid_gids_[o].end(),
                            std::back_inserter(common));
      if (!common.empty())
        throw InputError(config_.parts[b].where,
                         fmt::format("the rigid bodies of parts {} and {} share {} node{}: each "
                                     "is a body of its own (merge one into the other with "
                                     "`merge_with`, LS-DYNA's *CONSTRAINED_RIGID_BODIES, or "
                                     "keep their nodes apart)",
                                     config_.parts[part_of_body[o]].name, config_.parts[b].name,
                                     common.size(), common.size() == 1 ? "" : "s"));
    }
    rigid_gids_.push_back(std::move(gids));
    part_of_body.push_back(b);
  }
  if (rigid_gids_.empty()) return;
  if (rigid_parts.size() == config_.parts.size() && config_.particles.empty())
    throw InputError(config_.parts[0].where,
                     "every part is rigid: anvil needs a deformable part or particles (their "
                     "stable time step sets the step)");
  // A condition on some of a rigid body's nodes would fight the body's motion; one on the
  // whole part holds the body.
  condition_body_.assign(config_.boundary_conditions.size(), -1);
  for (std::size_t c = 0; c < config_.boundary_conditions.size(); ++c) {
    const auto& bc = config_.boundary_conditions[c];
    if (const int p = rigid_body_of(bc); p >= 0) {
      condition_body_[c] = static_cast<int>(
          std::find(part_of_body.begin(), part_of_body.end(), static_cast<std::size_t>(p)) -
          part_of_body.begin());
      continue;
    }
    const auto ids = selected_nodes(mesh, bc.nodes);
    for (std::size_t o = 0; o < rigid_gids_.size(); ++o)
      for (const std::int64_t id : ids)
        if (std::binary_search(rigid_gids_[o].begin(), rigid_gids_[o].end(), id))
          throw InputError(bc.where,
                           fmt::format("this condition holds nodes of the rigid part {}: a "
                                       "rigid body is held or driven whole (`part: {}`, its "
                                       "centre and rotations), not node by node",
                                       config_.parts[part_of_body[o]].name,
                                       config_.parts[part_of_body[o]].name));
  }
  wall_planes_.clear();
  for (const auto& w : config_.rigid_walls) wall_planes_.push_back({w.point, w.normal, w.friction});
  rigid_offset_.assign(rigid_gids_.size() + 1, 0);
  for (std::size_t o = 0; o < rigid_gids_.size(); ++o)
    rigid_offset_[o + 1] = rigid_offset_[o] + rigid_gids_[o].size();
  rigid_part_ = std::move(part_of_body);
  rigid_points_.assign(rigid_offset_.back(), RigidPoint{});
  rigid_motion_.assign(rigid_gids_.size(), RigidMotion{});
  rigid_holder_.assign(rigid_gids_.size(), {-1, -1, -1, -1, -1, -1});
  rigid_node_.assign(nn, 0);
  rigid_nodes_.clear();
  for (std::size_t n = 0; n < nn; ++n)
    for (std::size_t o = 0; o < rigid_gids_.size(); ++o) {
      const auto& g = rigid_gids_[o];
      const auto it = std::lower_bound(g.begin(), g.end(), fe_.node_gid[n]);
      if (it == g.end() || *it != fe_.node_gid[n]) continue;
      rigid_nodes_.push_back({static_cast<int>(o), static_cast<int>(it - g.begin()),
                              static_cast<int>(n), fe_.node_owned[n] != 0});
      rigid_node_[n] = 1;
      constrained_[n] = 7; // every component follows the body
    }
  rigid_point_owned_.assign(rigid_points_.size(), 0);
  for (const auto& rn : rigid_nodes_)
    if (rn.owned)
      rigid_point_owned_[rigid_offset_[static_cast<std::size_t>(rn.body)] +
                         static_cast<std::size_t>(rn.slot)] = 1;
  rigid_send_.reserve(rigid_nodes_.size());
  rigid_recv_.reserve(rigid_points_.size());
  // Each body's centre of mass at t = 0 (history's rigid.NAME.ux...; the same bits on any
  // rank count, and at a restart, which builds the model from the deck again).
  rigid_centre0_.clear();
  for (const auto& gids : rigid_gids_) rigid_centre0_.push_back(mass_center(gids));
  warn_of_thin_rigid_parts(rigid_parts);
}

// A rigid element sets no time step, and contact takes a node only within depth_fraction
// of a face's element depth (V / A): a node faster than that depth a step passes through
// a thin rigid part unseen (QA round 29: a 20 um rigid plate struck at 100 m/s). Said at
// setup, for the deck's initial speeds and step (collective).
void Simulation::warn_of_thin_rigid_parts(const std::vector<std::size_t>& parts) {
  if (config_.contact.empty()) return;
  double depth = std::numeric_limits<double>::infinity();
  int thinnest = -1;
  for (std::size_t o = 0; o < parts.size(); ++o) {
    const HexBlock& b = blocks_[parts[o]];
    for (int e = 0; e < b.size(); ++e) {
      double area = 0; // the element's largest face
      for (const auto& f : hex_faces) {
        Vec3 x[4];
        for (int k = 0; k < 4; ++k) {
          const auto n = static_cast<std::size_t>(b.conn[f[k]][static_cast<std::size_t>(e)]);
          x[k] = {nodes_.x[0][n], nodes_.x[1][n], nodes_.x[2][n]};
        }
        area = std::max(area, 0.5 * norm(cross(x[2] - x[0], x[3] - x[1])));
      }
      const double d = b.volume[static_cast<std::size_t>(e)] / area;
      if (d < depth) {
        depth = d;
        thinnest = static_cast<int>(o);
      }
    }
  }
  double speed = 0;
  for (std::size_t n = 0; n < nodes_.size(); ++n)
    speed = std::max(speed,
                     std::sqrt(nodes_.v[0][n] * nodes_.v[0][n] + nodes_.v[1][n] * nodes_.v[1][n] +
                               nodes_.v[2][n] * nodes_.v[2][n]));
  if (sph_) {
    const auto& pt = sph_->particles();
    for (std::size_t i = 0; i < pt.size(); ++i)
      speed = std::max(speed, std::sqrt(pt.v[0][i] * pt.v[0][i] + pt.v[1][i] * pt.v[1][i] +
                                        pt.v[2][i] * pt.v[2][i]));
  }
  const double global_depth = comm_.min(depth);
  const double global_speed = comm_.max(speed);
  // (The particles' step where they set it: with no deformable element the elements' is
  // a placeholder of 1e300 s, QA round 37.)
  const double dt = config_.time_step_scale *
                    std::min(stable_time_step(),
                             sph_ ? sph_->initial_step() : std::numeric_limits<double>::infinity());
  const std::int64_t part =
      comm_.min(depth == global_depth && thinnest >= 0
                    ? static_cast<std::int64_t>(parts[static_cast<std::size_t>(thinnest)])
                    : std::numeric_limits<std::int64_t>::max());
  const double reach = config_.contact[0].depth_fraction * global_depth;
  if (global_speed * dt > reach && part < static_cast<std::int64_t>(config_.parts.size()))
    warnings_.push_back(fmt::format(
        "{}: rigid part {} is {:.3g} m deep at its thinnest element and its elements set no time "
        "step: at the deck's fastest initial speed, {:.3g} m/s, a node moves {:.3g} m a step "
        "({:.3g} s), more than contact's reach into it ({:.3g} m, depth_fraction {}); it can "
        "pass through unseen: make the part thicker or lower time_step.scale",
        config_.parts[static_cast<std::size_t>(part)].where.str(),
        config_.parts[static_cast<std::size_t>(part)].name, global_depth, global_speed,
        global_speed * dt, dt, reach, config_.contact[0].depth_fraction));
}

// Every body's points (mass, x(n), v(n - 1/2), force) from every rank's owned nodes into
// rigid_points_, in each body's node order (collective). Without contact (predict): the
// forces of t(n), v(n - 1/2) in nodes_.v. With contact (correct): the contact forces
// added, v(n - 1/2) in v_prev_.
void Simulation::gather_rigid_points(bool with_contact) {
  rigid_send_.clear();
  for (const auto& rn : rigid_nodes_) {
    if (!rn.owned) continue;
    const auto n = static_cast<std::size_t>(rn.local);
    RigidRecord r;
    r.at = static_cast<std::int64_t>(rigid_offset_[static_cast<std::size_t>(rn.body)]) + rn.slot;
    r.p.m = nodes_.mass[n];
    for (int i = 0; i < 3; ++i) {
      r.p.x[i] = nodes_.x[i][n];
      r.p.v[i] = with_contact ? v_prev_[i][n] : nodes_.v[i][n];
      r.p.f[i] = nodes_.f[i][n] + (with_contact ? contact_force_[i][n] : 0.0);
    }
    rigid_send_.push_back(r);
  }
  comm_.allgatherv(std::span<const RigidRecord>(rigid_send_), rigid_recv_, rigid_bytes_);
  for (const auto& r : rigid_recv_) rigid_points_[static_cast<std::size_t>(r.at)] = r.p;
}

// The bodies' motion over the step, from every rank's owned points in each body's node
// order (collective). Without contact (predict): the forces of t(n), v(n - 1/2) in
// nodes_.v. With contact (correct): the contact forces added, v(n - 1/2) in v_prev_.
void Simulation::move_rigid_bodies(bool with_contact) {
  gather_rigid_points(with_contact);
  // The walls act on the step's last motion: with contact, the one with the contact forces.
  const bool walls = !wall_planes_.empty() && (with_contact || !contact_);
  if (walls) rigid_wall_hits_.clear();
  const Vec3 g{gravity_[0], gravity_[1], gravity_[2]};
  const auto& bcs = config_.boundary_conditions;
  for (std::size_t o = 0; o < rigid_gids_.size(); ++o) {
    const std::span<const RigidPoint> pts(rigid_points_.data() + rigid_offset_[o],
                                          rigid_gids_[o].size());
    // The components the body's conditions hold over the step: each by the last active
    // one in the deck that holds it (as for nodes), at its value times its time history.
    RigidHold hold;
    rigid_holder_[o] = {-1, -1, -1, -1, -1, -1};
    for (std::size_t b = 0; b < bcs.size(); ++b) {
      if (condition_body_[b] != static_cast<int>(o) || !bc_active_[b]) continue;
      const auto& bc = bcs[b];
      for (std::size_t i = 0; i < 3; ++i) {
        const int k = static_cast<int>(i);
        if (bc.prescribed ? bc.components[i] : bc.fix[i]) {
          hold.velocity_held[i] = true;
          hold.velocity[k] = bc.prescribed ? bc.value[k] * motion_factor_[b] : 0.0;
          rigid_holder_[o][i] = static_cast<int>(b);
        }
        if (bc.prescribed ? bc.spin_components[i] : bc.fix_spin[i]) {
          hold.spin_held[i] = true;
          hold.spin[k] = bc.prescribed ? bc.spin[k] * motion_factor_[b] : 0.0;
          rigid_holder_[o][3 + i] = static_cast<int>(b);
        }
      }
    }
    rigid_motion_[o] = rigid_motion(pts, g, clock_.dt_prev, dt_avg_, clock_.dt, hold);
    // (Every rank computes the same motion: every rank stops.)
    if (!rigid_motion_[o].converged)
      throw PhysicsError(fmt::format("rigid part {}", config_.parts[rigid_part_[o]].name),
                         clock_.time,
                         "it spins too fast for the time step (by about a radian or more a "
                         "step, or a held spin by more than a radian): its rotation over a "
                         "step cannot be followed; lower time_step.scale or the spin");
    if (!walls) continue;
    // The walls' impulses change the motion; the nodes' velocities follow it, and the
    // change beyond the forces' is the constraints' (external) work, as a held component's.
    // Each point's normal impulse is a hit of its wall on the rank that owns its node.
    body_wall_impulses_.clear();
    if (apply_walls_to_body(pts, wall_planes_, hold, dt_avg_, rigid_motion_[o], body_wall_scratch_,
                            body_wall_impulses_) < 0)
      throw PhysicsError(fmt::format("rigid part {}", config_.parts[rigid_part_[o]].name),
                         clock_.time,
                         "the rigid walls' impulses on it did not settle (its held components "
                         "and the walls leave it no motion in front of them)");
    for (const auto& h : body_wall_impulses_)
      if (rigid_point_owned_[rigid_offset_[o] + h.point] != 0)
        rigid_wall_hits_.push_back({rigid_gids_[o][h.point], h.wall, h.impulse});
  }
}

} // namespace anvil
