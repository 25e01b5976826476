// The motion of a rigid body over one central-difference step, from its points' masses,
// positions at t(n), velocities v(n - 1/2) and forces at t(n): a kernel free of MPI, the
// same numbers in the same order giving the same bits (the caller gathers every point of
// the body in one fixed order, so every rank computes the same motion).
//
// The body's state is its points': nothing is kept between steps. Its momentum is the sum
// of m v(n - 1/2); its angular momentum about the centre of mass, the sum of m r x v with
// r taken at t(n - 1/2) (the mean of the positions at t(n - 1) = x - dt_prev v and t(n)).
// The step's rotation is the Cayley transform of omega dt, an exact rotation whose
// increment is omega x (r(n) + r(n + 1)) / 2, so that the angular momentum read back from
// the points the next step is I(n + 1/2) omega: exactly what was set, for the inertia at
// the mid-step that the step's omega solves for (fixed-point iterations until omega
// settles, each shrinking the error by about omega dt / 2). The points
// keep their distances to round-off, and a free body keeps its momentum and angular
// momentum.
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "anvil/core/vec3.hpp"

namespace anvil {

struct RigidPoint {
  double m;
  Vec3 x; // at t(n)
  Vec3 v; // v(n - 1/2); at the first step (dt_prev 0), the initial velocity
  Vec3 f; // at t(n)
};

// Components of a body's motion that conditions hold (LS-DYNA's *MAT_RIGID CON1, CON2 and
// *BOUNDARY_PRESCRIBED_MOTION_RIGID): the centre's velocity and the angular velocity over
// the step, in global axes.
struct RigidHold {
  std::array<bool, 3> velocity_held{false, false, false}, spin_held{false, false, false};
  Vec3 velocity{0, 0, 0}, spin{0, 0, 0}; // the held components' values (m/s, rad/s)
};

struct RigidMotion {
  Vec3 centre;   // of mass, at t(n)
  Vec3 velocity; // of the centre over the step
  Vec3 omega;    // angular velocity over the step
  double dt = 0;
  double mass = 0;
  // Whether omega settled (it cannot when the body would turn by about a radian or more
  // in the step: the caller stops the run rather than lose the spin); false too for a
  // held spin of more than a radian a step. A held spin's omega is the step's Cayley
  // parameter over dt / 2, which turns the body by exactly |omega_held| dt.
  bool converged = true;
  // The force and the torque about the centre the held components take (what the body's
  // momentum and angular momentum change by beyond the forces', per dt_avg): 0 where free.
  Vec3 held_force{0, 0, 0}, held_torque{0, 0, 0};
  // v(n + 1/2) of the point at x(n): it lands on centre + dt velocity + R (x - centre),
  // R the step's rotation. (R - I) r is formed as s (a x r + a x (a x r)), a = omega dt / 2,
  // s = 2 / (1 + a.a), not as R r - r: a small rotation would lose its digits to r.
  Vec3 point_velocity(const Vec3& x) const;
};

// The motion from t(n) to t(n) + dt of the body whose points are `p`, under their forces
// and the body acceleration g (dt_avg: the interval the velocity advances over), with the
// components `hold` holds set to its values: the free components of the angular velocity
// then solve the free rows of L = I omega.
RigidMotion rigid_motion(std::span<const RigidPoint> p, const Vec3& g, double dt_prev,
                         double dt_avg, double dt, const RigidHold& hold = {});

// A planar wall as a rigid body meets it: a point on the wall, its unit normal (towards the
// side bodies stay on) and the Coulomb friction coefficient.
struct WallPlane {
  Vec3 point, normal;
  double friction = 0;
};

// The normal impulse (N s) one wall gave one point of a body over the step.
struct WallImpulse {
  std::size_t point;
  int wall;
  double impulse;
};

// The constraints of apply_walls_to_body(), kept between calls (no allocation once grown).
struct BodyWallScratch {
  struct Row {
    std::size_t point;
    int wall;
    Vec3 r, rn;    // the point's offset from the centre, and r x n
    double target; // the normal velocity that lands the point on the wall
    double k;      // the inverse of the body's effective mass along n at the point
    double lambda; // the normal impulse so far
    Vec3 jt;       // the friction impulse so far
  };
  std::vector<Row> rows;
};

// Planar walls on a rigid body, kinematically as on nodes (contact/rigid_wall.hpp): where
// some point of the body would land behind a wall, x + dt v(x) with v(x) the motion's
// point_velocity, the body's velocity and angular velocity change by the impulses at those
// points that put each of them on its wall at t(n) + dt (or leave it in front), pushing and
// never pulling; friction then opposes each such point's sliding by at most mu times its
// normal impulse. The impulses solve the constraints together, point after point in the
// order given, repeated until every landing is on or in front of its wall to 1e-12 of the
// speeds (at least 1e-6 of the body's size per step: at rest they are round-off;
// projected Gauss-Seidel, at most 500 sweeps). Held components do not change (they
// take the impulse, as a fixed node does: motion.held_force and held_torque, per dt_avg, add
// what they take of it), and a wall nearly square to every free
// translation (the free part n_f of its normal, |n_f|^2 <= 1e-6) leaves the body alone, as
// it leaves a node: the held motion wins. The inertia is that of the points at t(n) about
// the motion's centre. Appends each normal impulse to `out`; returns the sweeps made (0: no
// point behind a wall, the motion unchanged), negated when some point still lands behind
// its wall by more than 1e-3 of the body's size after them.
int apply_walls_to_body(std::span<const RigidPoint> p, std::span<const WallPlane> walls,
                        const RigidHold& hold, double dt_avg, RigidMotion& motion,
                        BodyWallScratch& scratch, std::vector<WallImpulse>& out);

} // namespace anvil
