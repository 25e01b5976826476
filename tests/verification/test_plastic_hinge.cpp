// The plastic limit of the assumed-strain hourglass control (docs/element.md, "Plastic
// limit"): one element through the thickness, bent or twisted far past yield, must carry
// the fully plastic moment of its section, not an elastic one.
//
// One hexahedron of J2 plasticity without hardening (E 200 GPa, nu 0.3, sigma_y 2 MPa: a
// yield strain of 1e-5, so that at ten times the yield curvature the rotations, and the
// membrane strains that they bring, stay negligible against it; the references are
// small-strain theory) is moved through a prescribed motion whose centre strain is zero,
// so that the one-point stress stays zero and the hourglass forces alone resist it:
//   pure bending  u_x = -kappa X Z, u_z = kappa X^2 / 2 (curvature kappa about y; the
//                 element l = 10 mm long, b = 10 mm wide, t = 2 mm thick);
//   pure twist    u = k (-Y Z, -X Z, X Y) (w = k x y: a plate's twist; 10 x 10 x 2 mm).
// The moment is the slope of the work done on the element (internal plus hourglass
// energy, which the kernel accumulates from the forces it applies): dW/dkappa = M l in
// bending, dW/dk = 2 M_xy A in twist (M_xy per unit width, A = l b). References,
// elementary plasticity of an elastic-perfectly-plastic rectangular section (e.g. Lubliner,
// "Plasticity Theory", 1990, section 4.5): elastic M = E I kappa, I = b t^3 / 12; past
// yield M = M_p (1 - (kappa_y / kappa)^2 / 3), M_p = sigma_y b t^2 / 4, kappa_y =
// 2 sigma_y / (E t); in twist the same with tau_y = sigma_y / sqrt 3 and shear modulus G:
// M_xy = G t^3 k / 6 elastic (gamma_xy = 2 k z), M_xy,p = tau_y t^2 / 4, k_y = tau_y / (G t).
// The element's limit is bilinear (elastic up to the fully plastic moment, reached at 1.5
// kappa_y, then flat), so the comparison is made where the exact curve is within 0.4% of
// M_p (10 times the yield curvature) and in the elastic range (half of it).
// Tolerance: 1% on each moment.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "anvil/fe/hex8.hpp"
#include "anvil/mesh/generators.hpp"
#include "kernel_rig.hpp"

namespace {

using namespace anvil;

constexpr double E = 200e9, nu = 0.3, sy = 2e6;
constexpr double l = 0.01, b = 0.01, t = 0.002; // the element: length, width, thickness

// Work done on one element (internal plus hourglass energy) along u = s shape(X), s from 0
// to each of the given values (increasing), in `steps` equal steps per unit of s_max.
std::vector<double> work_along(Vec3 size, Vec3 (*shape)(const Vec3&), std::vector<double> at,
                               int steps, int points = 0) {
  Mesh m = generate_box(
      {{-size.x / 2, -size.y / 2, -size.z / 2}, {size.x / 2, size.y / 2, size.z / 2}, {1, 1, 1}});
  const ParamValues steel{{"density", 7850},
                          {"youngs_modulus", E},
                          {"poissons_ratio", nu},
                          {"yield_stress", sy},
                          {"hardening_modulus", 0.0}};
  HourglassControl hg;
  hg.model = HourglassControl::Model::assumed_strain;
  hg.coefficient = 1.0;
  test::KernelRig rig(std::move(m), "j2_plasticity", steel, hg, BulkViscosity{0, 0},
                      ThickShell{points});
  const std::size_t nn = rig.fe.node_gid.size();
  const std::array<std::vector<double>, 3> X = rig.x;
  const double dt = 1e-6, s_max = at.back();
  const double ds = s_max / steps;
  std::vector<double> out;
  rig.forces(0.0);
  double s = 0;
  for (double target : at) {
    while (s < target - 0.5 * ds) {
      s += ds;
      for (std::size_t k = 0; k < nn; ++k) {
        const Vec3 u = shape({X[0][k], X[1][k], X[2][k]});
        const double un[3] = {u.x, u.y, u.z};
        for (int i = 0; i < 3; ++i) {
          const double x_new = X[i][k] + s * un[i];
          rig.v[i][k] = (x_new - rig.x[i][k]) / dt;
          rig.x[i][k] = x_new;
        }
      }
      rig.forces(dt);
    }
    out.push_back(rig.block.internal_energy[0] + rig.block.hourglass_energy[0]);
  }
  return out;
}

Vec3 bending(const Vec3& X) {
  return {-X.x * X.z, 0.0, 0.5 * X.x * X.x};
}
Vec3 twist(const Vec3& X) {
  return {-X.y * X.z, -X.x * X.z, X.x * X.y};
}

// The moments at half and ten times the yield value k_y of the load parameter (central
// differences of the work, step 0.02 k_y, divided by `per`: the work per unit moment and
// load), against the elastic moment at half of it (el_ref) and the exact
// elastic-perfectly-plastic moment at ten times it, M_p (1 - 1/300).
void check_moments(const char* name, Vec3 (*shape)(const Vec3&), double ky, double per,
                   double el_ref, double Mp, int points = 0) {
  const double h = 0.02 * ky;
  const auto W = work_along({l, b, t}, shape,
                            {0.5 * ky - h, 0.5 * ky + h, 10 * ky - h, 10 * ky + h}, 20000, points);
  const double M_el = (W[1] - W[0]) / (2 * h) / per, M_pl = (W[3] - W[2]) / (2 * h) / per;
  const double pl_ref = Mp * (1 - 1.0 / 300.0);
  std::printf("%s: M(0.5 k_y) = %.5g (elastic %.5g, %+.2f%%), M(10 k_y) = %.5g (exact %.5g, "
              "%+.2f%%; M_p %.5g)\n",
              name, M_el, el_ref, 100 * (M_el / el_ref - 1), M_pl, pl_ref,
              100 * (M_pl / pl_ref - 1), Mp);
  EXPECT_NEAR(M_el / el_ref, 1.0, 0.01);
  EXPECT_NEAR(M_pl / pl_ref, 1.0, 0.01);
}

TEST(PlasticHinge, OneElementBendsAtTheFullyPlasticMoment) {
  const double I = b * t * t * t / 12, ky = 2 * sy / (E * t);
  check_moments("bending (N m)", bending, ky, l, E * I * 0.5 * ky, sy * b * t * t / 4);
}

TEST(PlasticHinge, OneElementTwistsAtTheFullyPlasticMoment) {
  const double G = E / (2 * (1 + nu)), tau_y = sy / std::sqrt(3.0), ky = tau_y / (G * t);
  check_moments("twist (N m per m)", twist, ky, 2 * l * b, G * t * t * t * 0.5 * ky / 6,
                tau_y * t * t / 4);
}

// The thick shell (docs/element.md, "Thick shell") bends one element of the same section
// through its points: its bending stresses are integrated at n Gauss points through the
// thickness, each a J2 point in plane stress (sigma_zz = 0). The same prescribed motions;
// references from the same elementary plasticity, for the thick shell's section:
//   bending: the motion keeps eps_yy = 0, so the section is a plate in cylindrical bending:
//     elastic M = E I kappa / (1 - nu^2); fully plastic, each fibre yields in plane strain
//     (s_yy = 0, sigma_yy = sigma_xx / 2), sigma_xx = 2 sigma_y / sqrt 3;
//   twist: as above (pure shear needs no plane-strain factor).
// At ten times the yield curvature every point off the mid-surface is past yield (the
// nearest, zeta = 0.54 for n = 5, at 5.4 times its yield strain), so the rule's own
// moment is M_n = M_p sum_p w_p |zeta_p| (M_p the exact fully plastic moment, whose
// rectangle of stress the rule integrates as sum_p w_p |zeta_p| instead of 1): 1.1547
// (n = 2), 0.8607 (3), 1.0426 (4), 0.9449 (5). That is the comparison at 10 k_y (the
// element must reproduce its rule; the rule's error against M_p is the price of n points,
// reported); the elastic one is exact for any n. Tolerance 1% as above.
double rule_factor(int n) {
  double s = 0;
  for (int p = 0; p < n; ++p)
    s += hex8::thick_shell_weight[n - 2][p] * std::abs(hex8::thick_shell_point[n - 2][p]);
  return s;
}

TEST(PlasticHinge, ThickShellBendsAtItsRulesFullyPlasticMoment) {
  const double I = b * t * t * t / 12, ky = 2 * sy / (E * t);
  for (int n : {2, 3, 5}) {
    const double Mp = 2 / std::sqrt(3.0) * sy * b * t * t / 4;
    std::printf("thick shell, %d points, against M_n = %.4f M_p: ", n, rule_factor(n));
    check_moments("bending (N m)", bending, ky, l, E * I * 0.5 * ky / (1 - nu * nu),
                  Mp * rule_factor(n) / (1 - 1.0 / 300.0), n);
  }
}

TEST(PlasticHinge, ThickShellTwistsAtItsRulesFullyPlasticMoment) {
  const double G = E / (2 * (1 + nu)), tau_y = sy / std::sqrt(3.0), ky = tau_y / (G * t);
  for (int n : {2, 3}) {
    std::printf("thick shell, %d points, against M_n = %.4f M_p: ", n, rule_factor(n));
    check_moments("twist (N m per m)", twist, ky, 2 * l * b, G * t * t * t * 0.5 * ky / 6,
                  tau_y * t * t / 4 * rule_factor(n) / (1 - 1.0 / 300.0), n);
  }
}

} // namespace
