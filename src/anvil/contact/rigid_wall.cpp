#include "anvil/contact/rigid_wall.hpp"

#include <cmath>

namespace anvil {

double apply_rigid_walls(const std::vector<RigidWallConfig>& walls, double dt, WallNodes nd,
                         std::vector<double>& impulse) {
  double work = 0;
  if (!(dt > 0)) return work;
  for (std::size_t w = 0; w < walls.size(); ++w) {
    const Vec3 p = walls[w].point, n = walls[w].normal;
    const double mu = walls[w].friction;
    for (std::size_t k = 0; k < nd.size; ++k) {
      const unsigned fixed = nd.constrained[k];
      if (fixed == 7u) continue;
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
      for (int i = 0; i < 3; ++i) // constrained components keep their prescribed value
        if (fixed & (1u << i)) vn[i] = v[i];
      for (int i = 0; i < 3; ++i) nd.v[i][k] = vn[i];
      if (nd.owned[k]) {
        impulse[w] += nd.mass[k] * dvn;
        // Impulse times the mean of the step's start and end velocities.
        const Vec3 v0{nd.v_start[0][k], nd.v_start[1][k], nd.v_start[2][k]};
        work += nd.mass[k] * dot(vn - v, 0.5 * (v0 + vn));
      }
    }
  }
  return work;
}

} // namespace anvil
