#include "anvil/contact/geometry.hpp"

#include <algorithm>
#include <cmath>

namespace anvil {

namespace {
constexpr double sx[4] = {-1, 1, 1, -1};
constexpr double sy[4] = {-1, -1, 1, 1};
} // namespace

std::array<double, 4> quad_shape(double xi, double eta) {
  std::array<double, 4> n;
  for (int a = 0; a < 4; ++a) n[a] = 0.25 * (1 + sx[a] * xi) * (1 + sy[a] * eta);
  return n;
}

QuadProjection project_on_quad(const std::array<Vec3, 4>& x, const Vec3& p) {
  // x(xi, eta) = c + a xi + b eta + d xi eta.
  const Vec3 c = 0.25 * (x[0] + x[1] + x[2] + x[3]);
  const Vec3 a = 0.25 * (-1.0 * x[0] + x[1] + x[2] - x[3]);
  const Vec3 b = 0.25 * (-1.0 * x[0] - x[1] + x[2] + x[3]);
  const Vec3 d = 0.25 * (x[0] - x[1] + x[2] - x[3]);
  // The iteration needs only dot products of r0 = c - p, a, b and d: formed once, the
  // residual's projections are then polynomials in (xi, eta) (a few scalar operations per
  // iteration instead of vectors rebuilt each time).
  const Vec3 r0 = c - p;
  const double aa = dot(a, a), bb = dot(b, b), dd = dot(d, d);
  const double ab = dot(a, b), ad = dot(a, d), bd = dot(b, d);
  const double ra = dot(r0, a), rb = dot(r0, b), rd = dot(r0, d);
  QuadProjection r;
  double xi = 0, eta = 0;
  const double scale = aa + bb;
  for (int it = 0; it < 12; ++it) {
    // res = x(xi, eta) - p, t_xi = a + eta d, t_eta = b + xi d.
    const double xe = xi * eta;
    const double res_a = ra + xi * aa + eta * ab + xe * ad;
    const double res_b = rb + xi * ab + eta * bb + xe * bd;
    const double res_d = rd + xi * ad + eta * bd + xe * dd;
    const double g1 = res_a + eta * res_d, g2 = res_b + xi * res_d;
    // Newton on the gradient of |x - p|^2 / 2; the Hessian's curvature term uses d.
    const double h11 = aa + eta * (2 * ad + eta * dd), h22 = bb + xi * (2 * bd + xi * dd);
    const double tt = ab + xi * ad + eta * bd + xe * dd; // t_xi . t_eta
    double h12 = tt + res_d;
    double det = h11 * h22 - h12 * h12;
    // Newton converges quadratically: after a step below 1e-6 the error is of order 1e-12
    // times the face's relative curvature, and the iteration stops. Gauss-Newton
    // converges only linearly, and stops after a step below 1e-12.
    double done = 1e-6;
    if (!(det > 1e-12 * scale * scale)) { // far from the surface: Gauss-Newton
      h12 = tt;
      det = h11 * h22 - h12 * h12;
      done = 1e-12;
      if (!(det > 0)) break;
    }
    const double dxi = -(h22 * g1 - h12 * g2) / det;
    const double deta = -(h11 * g2 - h12 * g1) / det;
    xi = std::clamp(xi + dxi, -3.0, 3.0);
    eta = std::clamp(eta + deta, -3.0, 3.0);
    if (std::abs(dxi) + std::abs(deta) < done) {
      r.converged = true;
      break;
    }
  }
  r.xi = xi;
  r.eta = eta;
  r.point = c + xi * a + eta * b + (xi * eta) * d;
  const Vec3 n = cross(a + eta * d, b + xi * d);
  const double len = norm(n);
  r.normal = len > 0 ? n * (1 / len) : Vec3{};
  r.gap = dot(p - r.point, r.normal);
  if (!r.converged) { // accept a foot where the gradient vanishes to round-off
    const Vec3 res = r.point - p;
    const double g1 = dot(res, a + eta * d), g2 = dot(res, b + xi * d);
    r.converged = std::abs(g1) + std::abs(g2) <= 1e-9 * (norm(res) + 1e-300) * std::sqrt(scale);
  }
  return r;
}

} // namespace anvil
