// Constitutive models against closed-form answers on simple strain paths.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "anvil/material/johnson_cook.hpp"
#include "anvil/material/material.hpp"
#include "anvil/material/piecewise_linear_plasticity.hpp"

namespace {

using namespace anvil;

struct Point {
  double d[6] = {}, s[6] = {}, rho = 0, ep = 0, T = 0, c = 0;
  void step(const Material& m, double dt) {
    MaterialBatch b;
    b.n = 1;
    b.dt = dt;
    for (int k = 0; k < 6; ++k) {
      b.d[k] = &d[k];
      b.stress[k] = &s[k];
    }
    b.density = &rho;
    b.plastic_strain = &ep;
    b.temperature = &T;
    b.wave_speed = &c;
    m.update(b);
  }
};

// Hydrostatic compression of the elastic model: p = -K tr(eps); wave speed
// sqrt((K + 4G/3) / rho). Tolerance 1e-12 relative (round-off over 100 increments).
TEST(Materials, ElasticHydrostaticAndWaveSpeed) {
  const ParamValues p{{"density", 7850}, {"youngs_modulus", 200e9}, {"poissons_ratio", 0.3}};
  const auto m = find_material_model("elastic")->make(p, {});
  Point pt;
  pt.rho = 7850;
  for (int k = 0; k < 3; ++k) pt.d[k] = -1.0;
  for (int n = 0; n < 100; ++n) pt.step(*m, 1e-5);
  const double K = 200e9 / (3 * (1 - 0.6)), eps = -1e-3;
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(pt.s[k], 3 * K * eps, 1e-12 * std::abs(3 * K * eps));
  const double G = 200e9 / 2.6;
  EXPECT_NEAR(pt.c, std::sqrt((K + 4 * G / 3) / 7850), 1e-9);
}

// The fluid (LS-DYNA's *MAT_NULL): hydrostatic compression p = -K tr(eps) as the elastic
// model's; a shear rate gives the Newtonian stress 2 mu D' at once (no memory of the shear
// strain); wave speed sqrt(K / rho). With an equation of state (make_material), the EOS's
// pressure replaces K's. Tolerance 1e-12 relative (round-off).
TEST(Materials, FluidPressureAndViscousStress) {
  const ParamValues p{{"density", 1000}, {"bulk_modulus", 2.2e9}, {"viscosity", 1e-3}};
  const auto m = find_material_model("fluid")->make(p, {});
  Point pt;
  pt.rho = 1000;
  for (int k = 0; k < 3; ++k) pt.d[k] = -1.0;
  for (int n = 0; n < 100; ++n) pt.step(*m, 1e-5);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(pt.s[k], 2.2e9 * 3 * -1e-3, 1e-12 * 6.6e6);
  EXPECT_NEAR(pt.c, std::sqrt(2.2e9 / 1000), 1e-9);
  // Shear: D_xy = 50 /s for 10 steps; the stress is 2 mu D, not its integral.
  Point sh;
  sh.rho = 1000;
  sh.d[3] = 50;
  for (int n = 0; n < 10; ++n) sh.step(*m, 1e-5);
  EXPECT_NEAR(sh.s[3], 2 * 1e-3 * 50, 1e-15);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(sh.s[k], 0.0);
  // With Mie-Gruneisen: at rho = 1.01 rho0 and e = 0, p = rho0 c0^2 mu (1 + (1 - g/2) mu) /
  // (1 - (s - 1) mu)^2, mu = 0.01.
  const auto w =
      make_material("fluid", p, {}, "mie_gruneisen", {{"c0", 1480}, {"s", 1.92}, {"gamma0", 0.1}});
  Point q;
  q.rho = 1010;
  double e = 0;
  MaterialBatch b;
  b.n = 1;
  b.dt = 1e-6;
  for (int k = 0; k < 6; ++k) {
    b.d[k] = &q.d[k];
    b.stress[k] = &q.s[k];
  }
  b.density = &q.rho;
  b.wave_speed = &q.c;
  b.energy = &e;
  w->update(b);
  const double mu = 0.01, pexp = 1000 * 1480.0 * 1480.0 * mu * (1 + (1 - 0.05) * mu) /
                                 ((1 - 0.92 * mu) * (1 - 0.92 * mu));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(q.s[k], -pexp, 1e-12 * pexp);
}

// Simple shear of J2 with linear hardening: tau = G gamma until tau = Y0/sqrt(3), then
// tau = (Y0 + H gamma / sqrt(3)) / (sqrt(3) + H / (sqrt(3) G)) (von Mises, gamma_p =
// sqrt(3) ep). Radial return is exact for this proportional path; tolerance 1e-10.
TEST(Materials, J2SimpleShearFollowsTheAnalyticCurve) {
  const double E = 200e9, nu = 0.3, Y0 = 250e6, H = 1e9;
  const ParamValues p{{"density", 7850},
                      {"youngs_modulus", E},
                      {"poissons_ratio", nu},
                      {"yield_stress", Y0},
                      {"hardening_modulus", H}};
  const auto m = find_material_model("j2_plasticity")->make(p, {});
  const double G = E / (2 * (1 + nu));
  Point pt;
  pt.rho = 7850;
  pt.d[3] = 0.5; // gamma-dot = 1/s
  double gamma = 0;
  const double dt = 2e-5;
  for (int n = 0; n < 500; ++n) {
    pt.step(*m, dt);
    gamma += dt;
    const double elastic = G * gamma;
    const double tau =
        elastic < Y0 / std::sqrt(3.0)
            ? elastic
            : (Y0 + H * gamma / std::sqrt(3.0)) / (std::sqrt(3.0) + H / (std::sqrt(3.0) * G));
    ASSERT_NEAR(pt.s[3], tau, 1e-10 * tau) << "gamma " << gamma;
  }
  EXPECT_GT(pt.ep, 0.004);
  EXPECT_NEAR(pt.s[0], 0.0, 1e-3);
}

// Johnson-Cook: the returned state lies on the yield surface (consistency, 1e-10 relative),
// and the temperature rises by chi sigma_y dep / (rho cp), to the round-off of the
// temperature itself (1e-12 T: the rise, about 0.0075 K a step, is a difference of two
// temperatures near 294 K).
TEST(Materials, JohnsonCookConsistencyAndAdiabaticHeating) {
  const ParamValues p{{"density", 7830},
                      {"youngs_modulus", 200e9},
                      {"poissons_ratio", 0.29},
                      {"A", 792e6},
                      {"B", 510e6},
                      {"C", 0.014},
                      {"n", 0.26},
                      {"m", 1.03},
                      {"reference_strain_rate", 1.0},
                      {"room_temperature", 293},
                      {"melt_temperature", 1793},
                      {"specific_heat", 477},
                      {"taylor_quinney", 0.9},
                      {"max_hardening_stress", 0},
                      {"saturation_stress", 0}};
  const JohnsonCook jc(p);
  Point pt;
  pt.rho = 7830;
  pt.T = 293;
  pt.d[3] = 500.0; // shear at 1000 1/s
  const double dt = 1e-7;
  for (int n = 0; n < 200; ++n) {
    const double ep0 = pt.ep, T0 = pt.T;
    pt.step(jc, dt);
    const double q = std::sqrt(3.0) * std::abs(pt.s[3]);
    if (pt.ep > ep0) {
      const double rate = std::sqrt(2.0 / 3.0 * 2 * pt.d[3] * pt.d[3]);
      const double sy = jc.yield_stress(pt.ep, rate, T0);
      ASSERT_NEAR(q, sy, 1e-10 * sy);
      ASSERT_NEAR(pt.T - T0, 0.9 * sy * (pt.ep - ep0) / (7830 * 477), 1e-12 * pt.T);
    }
  }
  // Shear strain 0.02 in all, about 0.01 of it elastic: ep ~ 0.007, heating ~ 1.5 K.
  EXPECT_GT(pt.ep, 0.005);
  EXPECT_GT(pt.T, 294.0);
  // Thermal softening to zero strength at melt.
  EXPECT_EQ(jc.yield_stress(0.1, 1.0, 1793), 0.0);
  EXPECT_NEAR(jc.yield_stress(0.0, 1.0, 293), 792e6, 1e-6);
}

// Johnson-Cook without melt_temperature (LS-DYNA's simplified Johnson-Cook, MAT_098):
// no temperature, no thermal term, so at a fixed rate the flow stress is (A + B ep^n)
// (1 + C ln(rate / rate0)); max_hardening_stress caps A + B ep^n before the rate factor
// and saturation_stress caps the result (MAT_098's SIGMAX, SIGSAT). Simple shear at
// gamma-dot 1000 /s (equivalent rate 577 /s); q = sqrt(3) tau on the capped law at every
// plastic step, tolerance 1e-10 relative (the Newton solve's convergence, 1e-14 of q, and
// the shear stress's own round-off).
TEST(Materials, SimplifiedJohnsonCookAndItsCaps) {
  ParamValues p{{"density", 7830},
                {"youngs_modulus", 200e9},
                {"poissons_ratio", 0.29},
                {"A", 792e6},
                {"B", 510e6},
                {"C", 0.014},
                {"n", 0.26},
                {"m", 1},
                {"reference_strain_rate", 1.0},
                {"room_temperature", 293},
                {"melt_temperature", 0},
                {"specific_heat", 0},
                {"taylor_quinney", 0.9},
                {"max_hardening_stress", 0},
                {"saturation_stress", 0}};
  const double rate = 1000 / std::sqrt(3.0), R = 1 + 0.014 * std::log(rate);
  for (const auto& caps : {std::array<double, 2>{0, 0}, {1.0e9, 0}, {0, 1.05e9}}) {
    // (Named copies: clang before 16 cannot capture a structured binding in a lambda.)
    const double sigmax = caps[0], sigsat = caps[1];
    p["max_hardening_stress"] = sigmax;
    p["saturation_stress"] = sigsat;
    const JohnsonCook jc(p);
    EXPECT_FALSE(jc.has_temperature());
    auto expected = [&](double ep) {
      double h = 792e6 + 510e6 * std::pow(ep, 0.26);
      if (sigmax > 0) h = std::min(h, sigmax);
      double y = h * R;
      if (sigsat > 0) y = std::min(y, sigsat);
      return y;
    };
    Point pt;
    pt.rho = 7830;
    pt.d[3] = 500.0;
    int plastic = 0;
    for (int n = 0; n < 1000; ++n) { // to gamma = 0.1: ep ~ 0.05, past both caps
      const double ep0 = pt.ep;
      pt.step(jc, 1e-7);
      if (pt.ep == ep0) continue;
      ++plastic;
      const double q = std::sqrt(3.0) * std::abs(pt.s[3]);
      ASSERT_NEAR(q, expected(pt.ep), 1e-10 * q)
          << "step " << n << ", caps " << sigmax << " " << sigsat;
    }
    EXPECT_GT(plastic, 200);
    if (sigmax > 0) EXPECT_NEAR(std::sqrt(3.0) * pt.s[3], sigmax * R, 1e-10 * sigmax * R);
    if (sigsat > 0) EXPECT_NEAR(std::sqrt(3.0) * pt.s[3], sigsat, 1e-10 * sigsat);
  }
}

// piecewise_linear_plasticity (LS-DYNA MAT_024): the hardening curve of the tests below,
// three segments (slopes 2 GPa, 0.5 GPa, 0.1 GPa, the last one extended past 0.05).
const ParamTable plp_curve{{0.0, 0.002, 0.01, 0.05}, {250e6, 254e6, 258e6, 262e6}};
double plp_sigma(double ep) {
  const auto& c = plp_curve;
  std::size_t k = 0;
  while (k + 2 < c.x.size() && ep > c.x[k + 1]) ++k;
  return c.y[k] + (c.y[k + 1] - c.y[k]) / (c.x[k + 1] - c.x[k]) * (ep - c.x[k]);
}
ParamValues plp_params(double C = 0, double p = 0) {
  return {{"density", 7850},      {"youngs_modulus", 200e9}, {"poissons_ratio", 0.3},
          {"yield_stress", 0},    {"hardening_modulus", 0},  {"cowper_symonds_C", C},
          {"cowper_symonds_p", p}};
}

// Simple shear, gamma-dot = 1/s (tensor D_xy = 0.5): once plastic, von Mises q = sqrt(3)
// tau equals sigma(ep) on the curve, and tau = G (gamma - sqrt(3) ep) (gamma_p = sqrt(3)
// ep). So ep solves sqrt(3) G (gamma - sqrt(3) ep) = sigma(ep), linear on each segment;
// radial return is exact on this proportional path. Tolerance 1e-10 relative on tau, in
// 500 small steps and in one step from 0 to gamma = 0.1 that crosses every segment.
TEST(Materials, PiecewiseLinearSimpleShearFollowsTheCurve) {
  const TableValues t{{"hardening_curve", plp_curve}};
  ASSERT_TRUE(PiecewiseLinearPlasticity::check(plp_params(), t).why.empty());
  const auto m = find_material_model("piecewise_linear_plasticity")->make(plp_params(), t);
  const double G = 200e9 / 2.6, s3 = std::sqrt(3.0);
  auto exact = [&](double gamma) { // tau at gamma, and ep
    if (s3 * G * gamma <= plp_curve.y[0]) return std::array<double, 2>{G * gamma, 0.0};
    for (std::size_t k = 0; k + 1 < plp_curve.x.size(); ++k) {
      const double H =
          (plp_curve.y[k + 1] - plp_curve.y[k]) / (plp_curve.x[k + 1] - plp_curve.x[k]);
      // sqrt3 G gamma - 3 G ep = y_k + H (ep - x_k)
      const double ep = (s3 * G * gamma - plp_curve.y[k] + H * plp_curve.x[k]) / (3 * G + H);
      if (ep <= plp_curve.x[k + 1] || k + 2 == plp_curve.x.size())
        return std::array<double, 2>{G * (gamma - s3 * ep), ep};
    }
    return std::array<double, 2>{0, 0};
  };
  Point pt;
  pt.rho = 7850;
  pt.d[3] = 0.5;
  const double dt = 2e-4;
  double gamma = 0;
  for (int n = 0; n < 500; ++n) {
    pt.step(*m, dt);
    gamma += dt;
    const auto [tau, ep] = exact(gamma);
    ASSERT_NEAR(pt.s[3], tau, 1e-10 * tau) << "gamma " << gamma;
    ASSERT_NEAR(pt.ep, ep, 1e-10 * std::max(ep, 1e-3)) << "gamma " << gamma;
    if (ep > 0) ASSERT_NEAR(s3 * pt.s[3], plp_sigma(pt.ep), 1e-10 * plp_sigma(pt.ep));
  }
  EXPECT_GT(pt.ep, 0.05); // past the last point, on the extended slope
  Point big;
  big.rho = 7850;
  big.d[3] = 0.5;
  big.step(*m, 0.1);
  const auto [tau, ep] = exact(0.1);
  EXPECT_NEAR(big.s[3], tau, 1e-10 * tau);
  EXPECT_NEAR(big.ep, ep, 1e-10 * ep);
}

// The bilinear form (yield_stress, hardening_modulus) and a two-point curve on the same
// line are j2_plasticity: the same stresses on a mixed path (shear and stretch) to 1e-12
// relative (the same radial return, its terms in another order).
TEST(Materials, PiecewiseLinearBilinearIsJ2) {
  const double Y0 = 250e6, H = 1e9;
  ParamValues bilinear = plp_params();
  bilinear["yield_stress"] = Y0;
  bilinear["hardening_modulus"] = H;
  const TableValues line{{"hardening_curve", ParamTable{{0.0, 0.5}, {Y0, Y0 + 0.5 * H}}}};
  ParamValues j2p = bilinear;
  for (const char* k : {"cowper_symonds_C", "cowper_symonds_p"}) j2p.erase(k);
  const auto j2 = find_material_model("j2_plasticity")->make(j2p, {});
  const auto* model = find_material_model("piecewise_linear_plasticity");
  const auto a = model->make(bilinear, {}), b = model->make(plp_params(), line);
  Point p0, p1, p2;
  for (Point* p : {&p0, &p1, &p2}) {
    p->rho = 7850;
    p->d[0] = 1.0;
    p->d[1] = -0.3;
    p->d[3] = 0.4;
  }
  for (int n = 0; n < 300; ++n) {
    p0.step(*j2, 2e-5);
    p1.step(*a, 2e-5);
    p2.step(*b, 2e-5);
  }
  ASSERT_GT(p0.ep, 0.001);
  for (int k = 0; k < 6; ++k) {
    EXPECT_NEAR(p1.s[k], p0.s[k], 1e-12 * 300e6) << k;
    EXPECT_NEAR(p2.s[k], p0.s[k], 1e-12 * 300e6) << k;
  }
  EXPECT_NEAR(p1.ep, p0.ep, 1e-12 * p0.ep);
  EXPECT_NEAR(p2.ep, p0.ep, 1e-12 * p0.ep);
}

// Cowper-Symonds (Cowper and Symonds 1957; LS-DYNA MAT_024 VP = 0): at a constant
// equivalent strain rate r the flow stress is sigma(ep) (1 + (r / C)^(1/p)). Simple shear
// at gamma-dot gives r = gamma-dot / sqrt(3). Steel's C = 40 /s, p = 5 at gamma-dot = 100 /s:
// factor 1.97. Tolerance 1e-10 relative on q = sqrt(3) tau once plastic.
TEST(Materials, PiecewiseLinearCowperSymondsScalesTheYield) {
  const TableValues t{{"hardening_curve", plp_curve}};
  const auto m = find_material_model("piecewise_linear_plasticity")->make(plp_params(40, 5), t);
  const double rate = 100 / std::sqrt(3.0), factor = 1 + std::pow(rate / 40, 1.0 / 5);
  Point pt;
  pt.rho = 7850;
  pt.d[3] = 50; // gamma-dot 100 /s
  int plastic = 0;
  for (int n = 0; n < 400; ++n) {
    pt.step(*m, 2e-6);
    if (pt.ep == 0) continue;
    ++plastic;
    const double q = std::sqrt(3.0) * pt.s[3];
    ASSERT_NEAR(q, factor * plp_sigma(pt.ep), 1e-10 * q) << "step " << n;
  }
  EXPECT_GT(plastic, 100);
  EXPECT_GT(pt.ep, 0.01);
}

// The model's cross-parameter rules (both deck readers report them with file and line).
TEST(Materials, PiecewiseLinearChecksItsParameters) {
  const auto check = [](ParamValues p, TableValues t) {
    return PiecewiseLinearPlasticity::check(p, t);
  };
  const TableValues curve{{"hardening_curve", plp_curve}};
  EXPECT_EQ(check(plp_params(), {}).key, "yield_stress"); // neither form
  ParamValues both = plp_params();
  both["yield_stress"] = 1e8;
  EXPECT_EQ(check(both, curve).key, "yield_stress");
  ParamValues slope = plp_params();
  slope["hardening_modulus"] = 1e9;
  EXPECT_EQ(check(slope, curve).key, "hardening_modulus");
  EXPECT_EQ(check(plp_params(), {{"hardening_curve", ParamTable{{0.01, 0.1}, {1e8, 2e8}}}}).key,
            "hardening_curve"); // not from 0
  const auto soft = check(plp_params(), {{"hardening_curve", ParamTable{{0, 0.1}, {2e8, 1e8}}}});
  EXPECT_NE(soft.why.find("softening"), std::string::npos) << soft.why;
  EXPECT_EQ(check(plp_params(), {{"hardening_curve", ParamTable{{0}, {0}}}}).key,
            "hardening_curve");
  EXPECT_EQ(check(plp_params(40, 0), curve).key, "cowper_symonds_p");
  EXPECT_TRUE(check(plp_params(0, 5), curve).why.empty()); // C = 0: no rate effect
  const auto steep =
      check(plp_params(), {{"hardening_curve", ParamTable{{0, 1e-320, 1}, {4e8, 5e8, 6e8}}}});
  EXPECT_EQ(steep.point, 1) << steep.why;
  EXPECT_TRUE(check(plp_params(40, 5), curve).why.empty());
}

} // namespace
