// The deck's external loads (`loads`; LS-DYNA *LOAD_NODE, *LOAD_SEGMENT): forces on nodes
// and pressures on faces, each times its time history, applied at t(n) with the internal
// forces of the step.
//
// A pressure's forces are those of faces, and a face belongs to one element: they are
// assembled as the element forces are (fe_decomposition.hpp), into corner slots that the
// corner exchange carries to every rank holding the node, and summed per node in ascending
// (element gid, corner). Each slot holds its element's faces in ascending face and load.
// So every copy of a node adds the same numbers in the same order, on any number of
// ranks. A force on a node is the node's own: every holder adds the loads in deck order.
#include <algorithm>
#include <cmath>
#include <span>

#include <fmt/format.h>

#include "anvil/core/error.hpp"
#include "anvil/fe/pressure.hpp"
#include "anvil/solver/model.hpp"
#include "anvil/solver/simulation.hpp"

namespace anvil {

void Simulation::setup_loads(const Mesh& mesh) {
  const auto& loads = config_.loads;
  load_factor_.assign(loads.size(), 1.0);
  if (loads.empty()) return;
  const std::size_t nn = fe_.node_gid.size();
  auto local = [&](std::int64_t gid) {
    const auto it = std::lower_bound(fe_.node_gid.begin(), fe_.node_gid.end(), gid);
    return it != fe_.node_gid.end() && *it == gid ? static_cast<int>(it - fe_.node_gid.begin())
                                                  : -1;
  };
  // Per local node: 1 if a force acts on it, 2 if a pressed face touches it (either or both).
  std::vector<std::uint8_t> mark(nn, 0);
  for (std::size_t l = 0; l < loads.size(); ++l) {
    const Load& load = loads[l];
    if (load.kind == Load::Kind::force) {
      if (sph_) {
        const auto mask = select_particles(load.target);
        const std::int64_t held =
            comm_.sum(static_cast<std::int64_t>(std::count(mask.begin(), mask.end(), 1)));
        if (held > 0)
          throw InputError(load.target.where,
                           fmt::format("the selection holds {} particle{}: forces act on the "
                                       "nodes of the mesh only (particles take body loads: "
                                       "`gravity`, *LOAD_BODY_X/Y/Z in a keyword deck)",
                                       held, held == 1 ? "" : "s"));
      }
      const auto ids = resolve_selection(mesh, config_, load.target);
      warn_if_outside_model(ids, load.target.where);
      for (const std::int64_t gid : ids)
        if (const int n = local(gid); n >= 0) {
          nodal_forces_.push_back({n, static_cast<int>(l)});
          mark[static_cast<std::size_t>(n)] |= 1;
        }
      continue;
    }
    for (const SideEntry& side : resolve_surface(mesh, config_, load.target)) {
      const auto b = static_cast<std::size_t>(
          std::upper_bound(block_offsets_.begin(), block_offsets_.end(), side.element) -
          block_offsets_.begin() - 1);
      const Hex& h =
          mesh.blocks[b].elements[static_cast<std::size_t>(side.element - block_offsets_[b])];
      // Every holder of the face's nodes sums its slots, wherever the element is.
      for (const int a : hex_faces[static_cast<std::size_t>(side.face)])
        if (const int n = local(h[static_cast<std::size_t>(a)]); n >= 0)
          mark[static_cast<std::size_t>(n)] |= 2;
      const auto& gids = blocks_[b].gid;
      const auto it = std::lower_bound(gids.begin(), gids.end(), side.element);
      if (it != gids.end() && *it == side.element)
        pressed_.push_back({side.element, static_cast<int>(b), static_cast<int>(it - gids.begin()),
                            side.face, static_cast<int>(l)});
    }
  }
  std::sort(nodal_forces_.begin(), nodal_forces_.end(),
            [](const NodalForce& a, const NodalForce& b) {
              return a.node != b.node ? a.node < b.node : a.load < b.load;
            });
  std::sort(pressed_.begin(), pressed_.end(), [](const PressedFace& a, const PressedFace& b) {
    return std::tie(a.gid, a.face, a.load) < std::tie(b.gid, b.face, b.load);
  });
  for (std::size_t n = 0; n < nn; ++n) {
    if (mark[n]) loaded_nodes_.push_back(static_cast<int>(n));
    if (mark[n] & 2) pressure_nodes_.push_back(static_cast<int>(n));
  }
  const bool pressures = std::any_of(loads.begin(), loads.end(),
                                     [](const Load& l) { return l.kind == Load::Kind::pressure; });
  if (pressures)
    for (auto& c : load_corner_) c.assign(fe_.total_slots(), 0.0);
  for (auto& f : f_load_) f.assign(nn, 0.0);
}

std::vector<std::int64_t> Simulation::load_targets() const {
  std::vector<std::int64_t> count(config_.loads.size(), 0);
  for (const PressedFace& p : pressed_) ++count[static_cast<std::size_t>(p.load)];
  for (const NodalForce& nf : nodal_forces_)
    if (fe_.node_owned[static_cast<std::size_t>(nf.node)])
      ++count[static_cast<std::size_t>(nf.load)];
  comm_.sum(std::span<std::int64_t>(count));
  return count;
}

std::vector<double> Simulation::pressed_area() const {
  std::vector<double> area(config_.loads.size(), 0.0);
  for (const PressedFace& p : pressed_) {
    const auto& conn = fe_.blocks[static_cast<std::size_t>(p.block)].conn;
    double x[4][3], u[4][3];
    for (int a = 0; a < 4; ++a) {
      const auto n = static_cast<std::size_t>(conn[static_cast<std::size_t>(p.element)]
                                                  [hex_faces[static_cast<std::size_t>(p.face)][a]]);
      for (int i = 0; i < 3; ++i) x[a][i] = nodes_.x[i][n];
    }
    unit_pressure_forces(x, u); // their sum: minus the face's vector area
    area[static_cast<std::size_t>(p.load)] +=
        std::hypot(u[0][0] + u[1][0] + u[2][0] + u[3][0], u[0][1] + u[1][1] + u[2][1] + u[3][1],
                   u[0][2] + u[1][2] + u[2][2] + u[3][2]);
  }
  comm_.sum(std::span<double>(area));
  return area;
}

// The pressed faces' corner forces at x(n) and t(n), into their slots: each slot the sum of
// its element's faces in ascending face and load.
void Simulation::press_faces() {
  for (std::size_t l = 0; l < config_.loads.size(); ++l)
    load_factor_[l] = config_.loads[l].factor(clock_.time);
  if (pressed_.empty()) return;
  for (const PressedFace& p : pressed_) {
    const auto& lb = fe_.blocks[static_cast<std::size_t>(p.block)];
    for (const int a : hex_faces[static_cast<std::size_t>(p.face)])
      for (auto& c : load_corner_) c[lb.slot(static_cast<std::size_t>(p.element), a)] = 0.0;
  }
  for (const PressedFace& p : pressed_) {
    const auto b = static_cast<std::size_t>(p.block);
    const auto e = static_cast<std::size_t>(p.element);
    const auto& corners = hex_faces[static_cast<std::size_t>(p.face)];
    // An eroded element's faces carry no load (LS-DYNA deletes the segments of failed
    // elements).
    if (blocks_[b].alive[e] == 0.0) continue;
    double x[4][3], u[4][3];
    for (int a = 0; a < 4; ++a) {
      const auto n = static_cast<std::size_t>(fe_.blocks[b].conn[e][corners[a]]);
      for (int i = 0; i < 3; ++i) x[a][i] = nodes_.x[i][n];
    }
    unit_pressure_forces(x, u);
    const Load& load = config_.loads[static_cast<std::size_t>(p.load)];
    const double pressure = load.pressure * load_factor_[static_cast<std::size_t>(p.load)];
    for (int a = 0; a < 4; ++a) {
      const std::size_t slot = fe_.blocks[b].slot(e, corners[a]);
      for (int i = 0; i < 3; ++i) load_corner_[i][slot] += pressure * u[a][i];
    }
  }
}

// After the corner exchange: every loaded node's load force of the step (the pressures'
// slots summed, then the forces on it in deck order), added to its force.
void Simulation::add_loads() {
  if (loaded_nodes_.empty()) return;
  for (const int n : loaded_nodes_)
    for (auto& f : f_load_) f[static_cast<std::size_t>(n)] = 0.0;
  if (!pressure_nodes_.empty())
    gather_corners(fe_, {load_corner_[0].data(), load_corner_[1].data(), load_corner_[2].data()},
                   {f_load_[0].data(), f_load_[1].data(), f_load_[2].data()}, pressure_nodes_);
  for (const NodalForce& nf : nodal_forces_) {
    const Load& load = config_.loads[static_cast<std::size_t>(nf.load)];
    const double s = load_factor_[static_cast<std::size_t>(nf.load)];
    for (int i = 0; i < 3; ++i) f_load_[i][static_cast<std::size_t>(nf.node)] += load.force[i] * s;
  }
  for (const int n : loaded_nodes_)
    for (int i = 0; i < 3; ++i)
      nodes_.f[i][static_cast<std::size_t>(n)] += f_load_[i][static_cast<std::size_t>(n)];
}

// The loads' work of the current step, after predict() has set v(n + 1/2) (before contact
// and walls correct it): on each owned loaded node the impulse dt_v f (dt_v the velocity
// interval at t(n)), added to `work` as the constraints' are (predict()): with the kinetic
// energy of v(n), the work agrees to round-off on a free node whatever the load does (QA round 25:
// booked as the force of t(n - 1/2) times the step before's displacement, the work of a pressure on
// an element that eroded was lost, 10% of an eroding column's balance).
void Simulation::add_load_work(double dt_v, ImpulseWork& work) const {
  for (const int n : loaded_nodes_) {
    const auto k = static_cast<std::size_t>(n);
    if (!fe_.node_owned[k]) continue;
    for (int i = 0; i < 3; ++i) work.add(dt_v * f_load_[i][k], v_prev_[i][k], nodes_.v[i][k]);
  }
}

} // namespace anvil
