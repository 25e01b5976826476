// Constitutive models against closed-form answers on simple strain paths.
#include <gtest/gtest.h>

#include <cmath>

#include "anvil/material/johnson_cook.hpp"
#include "anvil/material/material.hpp"

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
  const auto m = find_material_model("elastic")->make(p);
  Point pt;
  pt.rho = 7850;
  for (int k = 0; k < 3; ++k) pt.d[k] = -1.0;
  for (int n = 0; n < 100; ++n) pt.step(*m, 1e-5);
  const double K = 200e9 / (3 * (1 - 0.6)), eps = -1e-3;
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(pt.s[k], 3 * K * eps, 1e-12 * std::abs(3 * K * eps));
  const double G = 200e9 / 2.6;
  EXPECT_NEAR(pt.c, std::sqrt((K + 4 * G / 3) / 7850), 1e-9);
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
  const auto m = find_material_model("j2_plasticity")->make(p);
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
                      {"taylor_quinney", 0.9}};
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

} // namespace
