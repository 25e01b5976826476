#include "anvil/contact/penalty.hpp"

#include <cmath>

#include "anvil/contact/geometry.hpp"

namespace anvil {

void penalty_forces(const std::vector<ContactNodeItem>& nodes,
                    const std::vector<ContactFaceItem>& faces,
                    const std::vector<ContactPair>& pairs, const PenaltyOptions& opt,
                    const HolderGroups& holders, std::vector<ContactForceItem>& items,
                    std::vector<int>& dest) {
  auto send = [&](const ContactForceItem& item, int group) {
    const auto g = static_cast<std::size_t>(group);
    for (int j = holders.start[g]; j < holders.start[g + 1]; ++j) {
      items.push_back(item);
      dest.push_back(holders.ranks[static_cast<std::size_t>(j)]);
    }
  };
  for (const auto& p : pairs) {
    const auto& n = nodes[static_cast<std::size_t>(p.node)];
    const auto& f = faces[static_cast<std::size_t>(p.face)];
    const auto N = foot_shape(p.xi, p.eta, f.node[2] == f.node[3]);
    // The pair's inverse mass: the node against the face's nodes at the foot.
    double inv_m = 1 / n.mass;
    for (int a = 0; a < 4; ++a) inv_m += N[a] * N[a] / f.mass[a];
    double k = f.stiffness;
    if (opt.dt > 0) k = std::min(k, stable_stiffness_fraction / (inv_m * opt.dt * opt.dt));
    const double fn = k * std::max(0.0, -p.gap - p.allowance);
    Vec3 F = fn * p.normal;
    if (opt.friction > 0 && opt.dt > 0) {
      Vec3 vr{n.v[0], n.v[1], n.v[2]};
      for (int a = 0; a < 4; ++a) vr -= N[a] * Vec3{f.v[a][0], f.v[a][1], f.v[a][2]};
      const Vec3 vt = vr - dot(vr, p.normal) * p.normal;
      const double speed = norm(vt);
      if (speed > 0) {
        // The force that stops the sliding within the step, as the pairs of an interface
        // share it: a face's nodes are moved by every pair on the faces around them (their
        // weights N_a summing to about one per node, not N_a^2 as for this pair alone), and
        // an interface is found from both sides (the nodes of each body against the other's
        // faces), so each pair takes half. With this pair's own N_a^2 mass alone the pairs
        // together overshot, reversed the sliding and created energy at mu = 1 (QA round
        // 17: contact energy -0.31 J, the sliding block's kinetic energy up six-fold).
        double inv_m_shared = 1 / n.mass;
        for (int a = 0; a < 4; ++a) inv_m_shared += N[a] / f.mass[a];
        const double stick = speed / (2 * inv_m_shared * opt.dt);
        const double ft = std::min(opt.friction * fn, stick);
        F -= (ft / speed) * vt;
      }
    }
    send({n.gid, n.gid, f.gid, p.allowance, {F.x, F.y, F.z}}, n.holders);
    for (int a = 0; a < 4; ++a)
      send({f.node[a], n.gid, -1, 0.0, {-N[a] * F.x, -N[a] * F.y, -N[a] * F.z}}, f.holders[a]);
  }
}

} // namespace anvil
