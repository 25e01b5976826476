#include "anvil/fe/rigid_body.hpp"

#include <cmath>

namespace anvil {

namespace {

using Mat3 = double[3][3];

// The inertia tensor about the centre of points at offsets r (point masses).
void inertia(std::span<const RigidPoint> p, const Vec3* r, Mat3& I) {
  for (auto& row : I)
    for (double& v : row) v = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double rr = dot(r[k], r[k]);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) I[i][j] += p[k].m * ((i == j ? rr : 0.0) - r[k][i] * r[k][j]);
  }
}

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

RigidMotion rigid_motion(std::span<const RigidPoint> p, std::span<Vec3> scratch, const Vec3& g,
                         double dt_prev, double dt_avg, double dt) {
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
  // Offsets at t(n), and at the mid-step for the iterations below.
  const std::span<Vec3> r = scratch.first(p.size()), mid = scratch.subspan(p.size(), p.size());
  for (std::size_t k = 0; k < p.size(); ++k) {
    r[k] = p[k].x - c;
    const Vec3 r_half = dt_prev > 0 ? 0.5 * (r[k] + (p[k].x - dt_prev * p[k].v - c_prev)) : r[k];
    L += p[k].m * cross(r_half, p[k].v - v_c);
    T += cross(r[k], p[k].f);
  }
  F += M * g;
  out.velocity = v_c + (dt_avg / M) * F;
  L += dt_avg * T;
  // omega = I(n + 1/2)^-1 L, the mid-step inertia depending on the rotation: from I(n).
  Mat3 I;
  inertia(p, r.data(), I);
  Vec3 omega = solve(I, L);
  for (int it = 0; it < 5; ++it) {
    const Vec3 a = 0.5 * dt * omega;
    for (std::size_t k = 0; k < p.size(); ++k) mid[k] = r[k] + 0.5 * turn(a, r[k]);
    inertia(p, mid.data(), I);
    omega = solve(I, L);
  }
  out.omega = omega;
  return out;
}

} // namespace anvil
