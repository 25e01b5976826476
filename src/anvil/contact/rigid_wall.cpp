#include "anvil/contact/rigid_wall.hpp"

#include <algorithm>
#include <cmath>

namespace anvil {

Vec3 free_part(const Vec3& n, unsigned fixed) {
  Vec3 nf = n;
  for (int i = 0; i < 3; ++i)
    if (fixed & (1u << i)) nf[i] = 0.0;
  return nf;
}

bool wall_can_move(const Vec3& n, unsigned fixed) {
  const Vec3 nf = free_part(n, fixed);
  return dot(nf, nf) > 1e-6;
}

WallResult apply_rigid_walls(const std::vector<RigidWallConfig>& walls, double dt, WallNodes nd,
                             std::vector<WallHit>& hits) {
  WallResult r;
  if (!(dt > 0)) return r;
  for (std::size_t w = 0; w < walls.size(); ++w) {
    const Vec3 p = walls[w].point, n = walls[w].normal;
    const double mu = walls[w].friction;
    for (std::size_t k = 0; k < nd.size; ++k) {
      const unsigned fixed = nd.constrained[k];
      if (!wall_can_move(n, fixed)) continue;
      const Vec3 v{nd.v[0][k], nd.v[1][k], nd.v[2][k]};
      const Vec3 xs = Vec3{nd.x[0][k], nd.x[1][k], nd.x[2][k]} + dt * v;
      const double gap = dot(xs - p, n);
      if (!(gap < 0)) continue;
      const double dvn = -gap / dt; // normal velocity change, > 0
      Vec3 vn = v + dvn * n;
      if (mu > 0) {
        const Vec3 vt = vn - dot(vn, n) * n;
        const double speed = norm(vt);
        if (speed > 0) vn -= std::min(1.0, mu * dvn / speed) * vt;
      }
      if (fixed != 0u) {
        // Constrained components keep their prescribed value; the free ones alone bring
        // the node onto the wall: the rest of the normal change along n's free part
        // n_f, which moves the node along n by |n_f|^2 per unit (a wedge: a node driven
        // into an oblique wall slides along it).
        const Vec3 nf = free_part(n, fixed);
        for (int i = 0; i < 3; ++i)
          if (fixed & (1u << i)) vn[i] = v[i];
        vn += ((dvn - dot(vn - v, n)) / dot(nf, nf)) * nf;
      }
      for (int i = 0; i < 3; ++i) nd.v[i][k] = vn[i];
      if (nd.owned[k]) {
        // The impulse applied: a constrained component the wall left alone gave none.
        const Vec3 dv = vn - v;
        hits.push_back(
            {nd.gid[k] + nd.gid_offset, static_cast<std::int32_t>(w), nd.mass[k] * dot(dv, n)});
        // Impulse times the mean of the step's start and end velocities.
        const Vec3 v0{nd.v_start[0][k], nd.v_start[1][k], nd.v_start[2][k]};
        r.work += nd.mass[k] * dot(dv, 0.5 * (v0 + vn));
        const Vec3 before = 0.5 * (v0 + v), after = 0.5 * (v0 + vn);
        r.kinetic += 0.5 * nd.mass[k] * (dot(after, after) - dot(before, before));
      }
    }
  }
  return r;
}

void wall_forces(std::vector<WallHit>& hits, double dt, std::vector<double>& force) {
  std::sort(hits.begin(), hits.end(), [](const WallHit& a, const WallHit& b) {
    return a.wall != b.wall ? a.wall < b.wall : a.key < b.key;
  });
  std::fill(force.begin(), force.end(), 0.0);
  for (const WallHit& h : hits) force[static_cast<std::size_t>(h.wall)] += h.impulse;
  for (double& f : force) f = dt > 0 ? f / dt : 0.0;
}

} // namespace anvil
