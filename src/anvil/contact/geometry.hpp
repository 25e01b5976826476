// Point-to-face geometry for the detailed contact check (Heinstein et al. 1993): the
// normal projection of a point onto a bilinear (possibly warped) quadrilateral.
#pragma once

#include <array>
#include <span>

#include "anvil/core/vec3.hpp"

namespace anvil {

struct QuadProjection {
  double xi = 0, eta = 0; // parent coordinates of the foot of the normal, face is [-1, 1]^2
  Vec3 point;             // x(xi, eta)
  Vec3 normal;            // unit outward normal at the foot (x_xi x x_eta)
  double gap = 0;         // (p - point) . normal: negative when p is behind the face
  bool converged = false; // the foot was found (it may lie outside the face)
};

// Bilinear shape functions of the face nodes 0..3 at (xi, eta); corner a at
// ((-1, -1), (1, -1), (1, 1), (-1, 1))[a].
std::array<double, 4> quad_shape(double xi, double eta);
// The shape functions at a foot of project_on_quad: quad_shape, or on a triangle (x2 = x3)
// its barycentric coordinates, exact also within 5% of its apex x2, where the foot's xi is
// (lb - la) / 0.05 rather than the collapsed quadrilateral's (lb - la) / (la + lb).
std::array<double, 4> foot_shape(double xi, double eta, bool triangle);

// Foot of the normal from p onto the bilinear surface through x[0..3] (counter-clockwise
// seen from outside), by Newton's method on (x(xi, eta) - p) . x_xi = (x - p) . x_eta = 0
// from the face centre, at most 12 iterations, parent coordinates kept within [-3, 3].
QuadProjection project_on_quad(const std::array<Vec3, 4>& x, const Vec3& p);

// The same for many points and faces, `simd::width` at a time: out[k] is, bit for bit,
// project_on_quad(queries[k].x, queries[k].p).
struct QuadQuery {
  std::array<Vec3, 4> x;
  Vec3 p;
};
void project_on_quads(std::span<const QuadQuery> queries, std::span<QuadProjection> out);

} // namespace anvil
