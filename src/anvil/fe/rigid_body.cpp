#include "anvil/fe/rigid_body.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace anvil {

namespace {

using Mat3 = double[3][3];

// x = I^-1 b; a body whose points lie on a line (or at one point) has no inertia about
// it: there (only) the tensor is lifted by 1e-12 of its trace, so that no spin about that
// line appears.
Vec3 solve(const Mat3& I0, const Vec3& b) {
  const double trace = I0[0][0] + I0[1][1] + I0[2][2];
  const double det0 = I0[0][0] * (I0[1][1] * I0[2][2] - I0[1][2] * I0[2][1]) -
                      I0[0][1] * (I0[1][0] * I0[2][2] - I0[1][2] * I0[2][0]) +
                      I0[0][2] * (I0[1][0] * I0[2][1] - I0[1][1] * I0[2][0]);
  const double lift = det0 > 1e-9 * trace * trace * trace ? 0.0 : 1e-12 * trace;
  Mat3 I;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) I[i][j] = I0[i][j] + (i == j ? lift : 0.0);
  const double c00 = I[1][1] * I[2][2] - I[1][2] * I[2][1];
  const double c01 = I[1][2] * I[2][0] - I[1][0] * I[2][2];
  const double c02 = I[1][0] * I[2][1] - I[1][1] * I[2][0];
  const double det = I[0][0] * c00 + I[0][1] * c01 + I[0][2] * c02;
  if (!(std::abs(det) > 0)) return {0, 0, 0};
  const double inv[3][3] = {
      {c00, I[0][2] * I[2][1] - I[0][1] * I[2][2], I[0][1] * I[1][2] - I[0][2] * I[1][1]},
      {c01, I[0][0] * I[2][2] - I[0][2] * I[2][0], I[0][2] * I[1][0] - I[0][0] * I[1][2]},
      {c02, I[0][1] * I[2][0] - I[0][0] * I[2][1], I[0][0] * I[1][1] - I[0][1] * I[1][0]}};
  Vec3 x;
  for (int i = 0; i < 3; ++i) x[i] = (inv[i][0] * b[0] + inv[i][1] * b[1] + inv[i][2] * b[2]) / det;
  return x;
}

// (R - I) r for the Cayley rotation R of a = omega dt / 2: R = I + s (A + A^2), s = 2 / (1 +
// a.a), A the cross-product matrix of a; R is exactly orthogonal, and (R - I) r =
// (dt / 2) omega x (r + R r).
Vec3 turn(const Vec3& a, const Vec3& r) {
  const Vec3 ar = cross(a, r);
  return (2 / (1 + dot(a, a))) * (ar + cross(a, ar));
}

} // namespace

Vec3 RigidMotion::point_velocity(const Vec3& x) const {
  const Vec3 r = x - centre;
  if (!(dt > 0)) return velocity + cross(omega, r);
  return velocity + turn(0.5 * dt * omega, r) * (1 / dt);
}

RigidMotion rigid_motion(std::span<const RigidPoint> p, const Vec3& g, double dt_prev,
                         double dt_avg, double dt, const RigidHold& hold) {
  RigidMotion out;
  out.dt = dt;
  double M = 0;
  Vec3 mx{0, 0, 0}, P{0, 0, 0}, F{0, 0, 0};
  for (const auto& q : p) {
    M += q.m;
    mx += q.m * q.x;
    P += q.m * q.v;
    F += q.f;
  }
  out.mass = M;
  const Vec3 c = mx * (1 / M);
  out.centre = c;
  // The centre at t(n - 1), for the offsets at t(n - 1/2).
  Vec3 c_prev = c;
  if (dt_prev > 0) {
    Vec3 mxp{0, 0, 0};
    for (const auto& q : p) mxp += q.m * (q.x - dt_prev * q.v);
    c_prev = mxp * (1 / M);
  }
  const Vec3 v_c = P * (1 / M);
  Vec3 L{0, 0, 0}, T{0, 0, 0};
  Mat3 J{}; // the second moment sum m r r^T of the offsets r at t(n)
  for (const auto& q : p) {
    const Vec3 r = q.x - c;
    const Vec3 r_half = dt_prev > 0 ? 0.5 * (r + (q.x - dt_prev * q.v - c_prev)) : r;
    L += q.m * cross(r_half, q.v - v_c);
    T += cross(r, q.f);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) J[i][j] += q.m * r[i] * r[j];
  }
  F += M * g;
  out.velocity = v_c + (dt_avg / M) * F;
  for (int i = 0; i < 3; ++i)
    if (hold.velocity_held[static_cast<std::size_t>(i)]) {
      out.held_force[i] = M * (hold.velocity[i] - out.velocity[i]) / dt_avg;
      out.velocity[i] = hold.velocity[i];
    }
  L += dt_avg * T;
  const bool spin_held = hold.spin_held[0] || hold.spin_held[1] || hold.spin_held[2];
  // With components of omega held: the held rows of I omega = L replaced by
  // tr(I) omega_i = tr(I) w_i (scaled so that solve() sees rows of one size).
  auto solve_held = [&](const Mat3& I0, const Vec3& b) {
    if (!spin_held) return solve(I0, b);
    const double tr = I0[0][0] + I0[1][1] + I0[2][2];
    Mat3 A;
    Vec3 r = b;
    for (int i = 0; i < 3; ++i) {
      const bool held = hold.spin_held[static_cast<std::size_t>(i)];
      for (int j = 0; j < 3; ++j) A[i][j] = held ? (i == j ? tr : 0.0) : I0[i][j];
      if (held) r[i] = tr * hold.spin[i];
    }
    Vec3 w = solve(A, r);
    for (int i = 0; i < 3; ++i)
      if (hold.spin_held[static_cast<std::size_t>(i)]) w[i] = hold.spin[i]; // exactly
    return w;
  };
  // omega = I(n + 1/2)^-1 L. The mid-step offsets are Q r, Q = I + (s / 2) (A + A^2) (the
  // half of the step's rotation, turn()), so I(n + 1/2) = tr(S) 1 - S with S = Q J Q^T: no
  // pass over the points per iteration. From I(n), fixed-point iterations until omega
  // settles (each shrinks its error by about omega dt / 2; they cannot settle when the
  // body turns by a radian or more in a step: `converged` then says so).
  // I = tr(S) 1 - S for the second moment S of the offsets.
  auto inertia_of = [](const Mat3& S, Mat3& I) {
    const double tr = S[0][0] + S[1][1] + S[2][2];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) I[i][j] = (i == j ? tr : 0.0) - S[i][j];
  };
  Mat3 I;
  inertia_of(J, I);
  Vec3 omega = solve_held(I, L);
  out.converged = false;
  double last_change = std::numeric_limits<double>::infinity();
  const bool all_held = hold.spin_held[0] && hold.spin_held[1] && hold.spin_held[2];
  for (int it = 0; it < 100 && !all_held; ++it) {
    const Vec3 a = 0.5 * dt * omega;
    const double s = 1 / (1 + dot(a, a)); // half of turn()'s 2 / (1 + a.a)
    const double A[3][3] = {{0, -a.z, a.y}, {a.z, 0, -a.x}, {-a.y, a.x, 0}};
    Mat3 Q, QJ{}, S{};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double a2 = 0;
        for (int k = 0; k < 3; ++k) a2 += A[i][k] * A[k][j];
        Q[i][j] = (i == j ? 1.0 : 0.0) + s * (A[i][j] + a2);
      }
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k) QJ[i][j] += Q[i][k] * J[k][j];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k) S[i][j] += QJ[i][k] * Q[j][k];
    inertia_of(S, I);
    const Vec3 next = solve_held(I, L);
    const double change = norm(next - omega);
    omega = next;
    // Settled to round-off, or no longer settling at round-off's level: a slender body's
    // inertia, ill-conditioned, held the change at 1.1e-14 of omega, flipping between two
    // values, and the run stopped as if it spun too fast (QA round 38: a bar turning 5e-4
    // rad a step).
    if (change <= 1e-14 * norm(omega) || (change >= last_change && change <= 1e-10 * norm(omega))) {
      out.converged = true;
      break;
    }
    last_change = change;
  }
  // The physical root has |omega| dt / 2 <= 1 (about a principal axis the fixed point is
  // a = a0 (1 + a^2), a = omega dt / 2, whose smaller root is at most 1); the iteration can
  // also settle on a spurious one at infinity, where the half-turned points collapse onto
  // the axis (QA round 29: 60,000 rad/s at dt 3.6e-5 s became 6e17 rad/s, the spin lost).
  if (all_held) out.converged = true;
  if (!(norm(omega) * dt <= 2)) out.converged = false;
  out.omega = omega;
  // A held spin turns the body by exactly |omega| dt a step: the Cayley rotation of a
  // turns by 2 atan |a|, so a = tan(|omega| dt / 2) omega / |omega| (the plain a = omega
  // dt / 2 turns short by (omega dt)^2 / 12: a driven wheel ran 0.5% slow at omega dt
  // 0.14, QA round 31). The nodes' velocities are the chords over the step. (A free or
  // partly held spin keeps the plain form: its omega is the root of L = I omega.)
  if (all_held && dt > 0) {
    const double w = norm(omega);
    out.converged = w * dt <= 1; // beyond a radian a step the caller stops the run
    if (w > 0 && out.converged) out.omega = omega * (2 * std::tan(0.5 * w * dt) / (w * dt));
  }
  // The torque the held components take: I(n + 1/2) omega - L, per dt_avg (I of the last
  // iteration: the one omega solved).
  if (spin_held)
    for (int i = 0; i < 3; ++i)
      if (hold.spin_held[static_cast<std::size_t>(i)])
        out.held_torque[i] =
            (I[i][0] * omega[0] + I[i][1] * omega[1] + I[i][2] * omega[2] - L[i]) / dt_avg;
  return out;
}

int apply_walls_to_body(std::span<const RigidPoint> p, std::span<const WallPlane> walls,
                        const RigidHold& hold, double dt_avg, RigidMotion& motion,
                        BodyWallScratch& scratch, std::vector<WallImpulse>& out) {
  const double dt = motion.dt;
  if (!(dt > 0) || walls.empty() || p.empty() || !(motion.mass > 0)) return 0;
  const Vec3 c = motion.centre;
  auto& rows = scratch.rows;
  rows.clear();
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t w = 0; w < walls.size(); ++w) {
      const Vec3& n = walls[w].normal;
      // A wall nearly square to every free translation leaves the body alone (its held
      // motion wins, as a node's does): turning alone cannot lift a face off a wall, and
      // the impulses would spin it up without end (QA round 37: 2e6 rad/s in a step).
      Vec3 free = n;
      for (int k = 0; k < 3; ++k)
        if (hold.velocity_held[static_cast<std::size_t>(k)]) free[k] = 0;
      if (!(dot(free, free) > 1e-6)) continue;
      const Vec3 land = p[i].x + dt * motion.point_velocity(p[i].x);
      if (dot(n, land - walls[w].point) < 0)
        rows.push_back({i, static_cast<int>(w), p[i].x - c, cross(p[i].x - c, n),
                        dot(n, walls[w].point - p[i].x) / dt, 0.0, 0.0, Vec3{0, 0, 0}});
    }
  if (rows.empty()) return 0;
  // The body's response to an impulse: its centre's velocity changes by J / M and its
  // angular velocity by I^-1 (r x J), I the inertia at t(n); a held component does not
  // change (its rows of I omega = L give way to omega_i = its value, as in rigid_motion).
  Mat3 J{};
  for (const auto& q : p) {
    const Vec3 r = q.x - c;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) J[i][j] += q.m * r[i] * r[j];
  }
  const double trJ = J[0][0] + J[1][1] + J[2][2];
  Mat3 I;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) I[i][j] = (i == j ? trJ : 0.0) - J[i][j];
  const bool all_held = hold.spin_held[0] && hold.spin_held[1] && hold.spin_held[2];
  const double trI = I[0][0] + I[1][1] + I[2][2];
  Mat3 I_full; // (before the held rows give way: the torque the holds take, below)
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) I_full[i][j] = I[i][j];
  const Vec3 omega_before = motion.omega;
  for (int i = 0; i < 3; ++i)
    if (hold.spin_held[static_cast<std::size_t>(i)])
      for (int j = 0; j < 3; ++j) I[i][j] = i == j ? trI : 0.0;
  Mat3 W{}; // columns: the change of omega per unit torque about each axis
  if (!all_held)
    for (int k = 0; k < 3; ++k) {
      // (A torque about a held axis is the hold's: no change, column 0; the held rows'
      // right-hand sides are 0, so the free rows solve I_ff dw_f = tau_f.)
      if (hold.spin_held[static_cast<std::size_t>(k)]) continue;
      Vec3 e{0, 0, 0};
      e[k] = 1;
      Vec3 col = solve(I, e);
      for (int i = 0; i < 3; ++i) {
        if (hold.spin_held[static_cast<std::size_t>(i)]) col[i] = 0;
        W[i][k] = col[i];
      }
    }
  const double inv_m = 1 / motion.mass;
  auto dv = [&](const Vec3& imp) {
    Vec3 d = inv_m * imp;
    for (int i = 0; i < 3; ++i)
      if (hold.velocity_held[static_cast<std::size_t>(i)]) d[i] = 0;
    return d;
  };
  auto dw = [&](const Vec3& tau) {
    Vec3 d;
    for (int i = 0; i < 3; ++i) d[i] = W[i][0] * tau[0] + W[i][1] * tau[1] + W[i][2] * tau[2];
    return d;
  };
  auto response = [&](const Vec3& r, const Vec3& dir) {
    const Vec3 rd = cross(r, dir);
    return dot(dir, dv(dir)) + dot(rd, dw(rd));
  };
  // The speeds' scale, and a floor under it for a body at rest on a wall, whose speeds are
  // round-off (QA round 38: a cube at rest after landing flat stopped the run): the speed
  // that moves the body by 1e-6 of its size in a step.
  double scale = 0, extent = 0;
  for (const auto& q : p) extent = std::max(extent, norm(q.x - c));
  for (auto& row : rows) {
    row.k = response(row.r, walls[static_cast<std::size_t>(row.wall)].normal);
    scale = std::max(scale, std::abs(row.target) + norm(motion.point_velocity(p[row.point].x)));
  }
  scale = std::max(scale, 1e-6 * extent / dt);
  // Settled to 1e-12 of the speeds (a landing behind the wall by 1e-12 of a step's
  // motion); points on a line or a face are redundant constraints, which the sweeps settle
  // slowly, and friction more slowly still: at most 500 sweeps, whatever is left then
  // corrected the next step.
  const double tol = 1e-12 * scale;
  // After 20 sweeps, a landing behind the wall by 1e-9 of the body's size is settled enough:
  // a body resting on a wall on many points, whose gravity each step's impulses take off
  // again, settled slowly towards round-off and took the 500 sweeps every cycle (QA round
  // 39: 0.83 ms a cycle for 15 points); one point settles to round-off in a few sweeps.
  const double enough = 1e-9 * extent / dt;
  int sweep = 0;
  for (double worst = 2 * tol + 1;
       sweep < 500 && worst > tol && !(sweep >= 20 && worst <= enough);) {
    ++sweep;
    for (auto& row : rows) {
      if (!(row.k > 0)) continue; // every component the impulse would move is held
      const WallPlane& wall = walls[static_cast<std::size_t>(row.wall)];
      const Vec3& n = wall.normal;
      const Vec3& x = p[row.point].x;
      const double lambda =
          std::max(0.0, row.lambda + (row.target - dot(n, motion.point_velocity(x))) / row.k);
      const double d = lambda - row.lambda;
      row.lambda = lambda;
      motion.velocity += dv(d * n);
      motion.omega += dw(d * row.rn);
      if (!(wall.friction > 0)) continue;
      // Friction: the impulse in the wall's plane that stops the point's sliding, within
      // mu times the normal impulse.
      const Vec3 u = motion.point_velocity(x);
      const Vec3 ut = u - dot(n, u) * n;
      const double slide = norm(ut);
      Vec3 jt = row.jt;
      if (slide > 0) {
        const Vec3 dir = ut * (1 / slide);
        const double kt = response(row.r, dir);
        if (kt > 0) jt = jt - (slide / kt) * dir;
      }
      const double limit = wall.friction * row.lambda, size = norm(jt);
      if (size > limit) jt = size > 0 ? jt * (limit / size) : Vec3{0, 0, 0};
      const Vec3 dj = jt - row.jt;
      row.jt = jt;
      motion.velocity += dv(dj);
      motion.omega += dw(cross(row.r, dj));
    }
    // How far from settled: a point still landing behind its wall, or one pushed by an
    // impulse off it (the impulse could be less).
    worst = 0;
    for (const auto& row : rows) {
      if (!(row.k > 0)) continue;
      const double miss = row.target - dot(walls[static_cast<std::size_t>(row.wall)].normal,
                                           motion.point_velocity(p[row.point].x));
      worst = std::max(worst, row.lambda > 0 ? std::abs(miss) : miss);
    }
  }
  for (const auto& row : rows)
    if (row.lambda > 0) out.push_back({row.point, row.wall, row.lambda});
  // What the holds take of the walls' impulses (their reactions, as of the forces'): a held
  // translation all of the impulses along it; a held spin what its row of I d omega = the
  // impulses' torque leaves over, d omega being the free components' change.
  Vec3 J_all{0, 0, 0}, T_all{0, 0, 0};
  for (const auto& row : rows) {
    const Vec3 J = row.lambda * walls[static_cast<std::size_t>(row.wall)].normal + row.jt;
    J_all += J;
    T_all += cross(row.r, J);
  }
  if (dt_avg > 0)
    for (int i = 0; i < 3; ++i) {
      if (hold.velocity_held[static_cast<std::size_t>(i)])
        motion.held_force[i] -= J_all[i] / dt_avg;
      if (hold.spin_held[static_cast<std::size_t>(i)]) {
        double Idw = 0;
        for (int j = 0; j < 3; ++j) Idw += I_full[i][j] * (motion.omega[j] - omega_before[j]);
        motion.held_torque[i] += (Idw - T_all[i]) / dt_avg;
      }
    }
  double left = 0;
  for (const auto& row : rows)
    if (row.k > 0)
      left = std::max(left, row.target - dot(walls[static_cast<std::size_t>(row.wall)].normal,
                                             motion.point_velocity(p[row.point].x)));
  // (QA round 37's spin-up is excluded above; what is left after the sweeps is a landing
  // behind the wall by a small part of a step's motion, corrected the next step, unless it
  // is gross: 1e-3 of the body's size.)
  return left * dt > 1e-3 * extent ? -sweep : sweep;
}

} // namespace anvil
