// The nodal forces of a pressure on a face of the mesh (deck `loads`, LS-DYNA
// *LOAD_SEGMENT): pure arithmetic on one face, no state.
#pragma once

namespace anvil {

// The forces a unit pressure exerts on the corners of a bilinear quadrilateral face whose
// corners x[0..3] run counter-clockwise seen from outside, so that the right-hand normal
// points out of the body: a positive pressure pushes into the body. They are the consistent
// forces of the bilinear interpolation,
//     f_a = - integral over [-1, 1]^2 of N_a (dx/dxi x dx/deta) dxi deta,
// which 2 x 2 Gauss points integrate exactly (N_a is bilinear, dx/dxi depends on eta only
// and dx/deta on xi only, so the integrand is at most quadratic in each variable). Their
// sum is minus the face's vector area, (x2 - x0) x (x3 - x1) / 2, on a warped face too; on
// a flat parallelogram each corner takes a quarter of it. Only differences of the corners
// enter, so the forces do not depend on where the face is.
inline void unit_pressure_forces(const double (&x)[4][3], double (&f)[4][3]) {
  // The corners' natural coordinates, counter-clockwise: (-1,-1), (1,-1), (1,1), (-1,1).
  static constexpr double xi_a[4] = {-1, 1, 1, -1}, eta_a[4] = {-1, -1, 1, 1};
  // The edge vectors the derivatives are made of: dx/dxi = ((x1 - x0)(1 - eta) + (x2 -
  // x3)(1 + eta)) / 4, dx/deta = ((x3 - x0)(1 - xi) + (x2 - x1)(1 + xi)) / 4.
  double e10[3], e23[3], e30[3], e21[3];
  for (int i = 0; i < 3; ++i) {
    e10[i] = x[1][i] - x[0][i];
    e23[i] = x[2][i] - x[3][i];
    e30[i] = x[3][i] - x[0][i];
    e21[i] = x[2][i] - x[1][i];
  }
  for (auto& fa : f) fa[0] = fa[1] = fa[2] = 0.0;
  const double g = 0.57735026918962576; // 1 / sqrt(3); the weights are 1
  for (const double eta : {-g, g})
    for (const double xi : {-g, g}) {
      double a[3], b[3];
      for (int i = 0; i < 3; ++i) {
        a[i] = 0.25 * (e10[i] * (1 - eta) + e23[i] * (1 + eta));
        b[i] = 0.25 * (e30[i] * (1 - xi) + e21[i] * (1 + xi));
      }
      const double n[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                           a[0] * b[1] - a[1] * b[0]};
      for (int c = 0; c < 4; ++c) {
        const double N = 0.25 * (1 + xi_a[c] * xi) * (1 + eta_a[c] * eta);
        for (int i = 0; i < 3; ++i) f[c][i] -= N * n[i];
      }
    }
}

} // namespace anvil
