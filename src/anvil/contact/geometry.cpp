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
  QuadProjection r;
  double xi = 0, eta = 0;
  const double scale = dot(a, a) + dot(b, b);
  for (int it = 0; it < 12; ++it) {
    const Vec3 xs = c + xi * a + eta * b + (xi * eta) * d;
    const Vec3 txi = a + eta * d, teta = b + xi * d;
    const Vec3 res = xs - p;
    const double g1 = dot(res, txi), g2 = dot(res, teta);
    // Newton on the gradient of |x - p|^2 / 2; the Hessian's curvature term uses d.
    double h11 = dot(txi, txi), h22 = dot(teta, teta), h12 = dot(txi, teta) + dot(res, d);
    double det = h11 * h22 - h12 * h12;
    if (!(det > 1e-12 * scale * scale)) { // far from the surface: Gauss-Newton
      h12 = dot(txi, teta);
      det = h11 * h22 - h12 * h12;
      if (!(det > 0)) break;
    }
    const double dxi = -(h22 * g1 - h12 * g2) / det;
    const double deta = -(h11 * g2 - h12 * g1) / det;
    xi = std::clamp(xi + dxi, -3.0, 3.0);
    eta = std::clamp(eta + deta, -3.0, 3.0);
    if (std::abs(dxi) + std::abs(deta) < 1e-12) {
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
