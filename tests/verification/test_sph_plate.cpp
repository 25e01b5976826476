// The oscillating plate of Gray, Monaghan and Swift (2001, "SPH elastic dynamics", CMAME
// 190, section 6.1): a plate of length L = 0.2 m and thickness H = 0.02 m clamped at one
// end (plane strain, `sph: {dimensions: 2}`), E = 2e6 Pa, nu = 0.3975, rho = 1000
// kg/m^3, given the first cantilever mode as initial velocity, tip speed 0.05 m/s
// (amplitude ~2 mm, linear). Analytic period from thin-plate theory (their eq. 43):
// omega^2 = E H^2 k^4 / (12 rho (1 - nu^2)), kL = 1.8751: T = 0.2541 s. Measured: the
// first zero crossing of the mean tip velocity is a quarter period (pure mode-1 start).
// Spacing H/16 = 1.25 mm (16 particles through the thickness), h = 1.3 spacing, the
// clamp 4 spacings of fixed particles behind x = 0, viscosity alpha 0.1, beta 0,
// artificial stress epsilon 0.3, normalised (corrected) velocity gradient. Tolerance
// (stated before the run): the period within 5% of the analytic value (the plate is
// thick enough, L/H = 10, for shear deformation to lower the frequency by ~1%).
// Resolution (docs/sph.md): the same settings give +38.5%, +13.5%, +4.2% at 4, 8, 16
// particles through the thickness, and the Richardson extrapolation of the last two
// (order 1.7) is 0.2541 s, the analytic value. The test runs 16 for the 5% check and 8
// to check that the error falls at least as fast as first order.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include <fmt/format.h>

#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

// Runs the plate to its first quarter period (collective); returns SPH and theory periods.
// `through` particles across the thickness H; the clamp is 4 spacings of fixed particles.
std::pair<double, double> plate_periods(int through) {
  const double dx = 0.02 / through;
  const std::string deck = fmt::format(R"(
termination: {{time: 0.1}}
sph: {{dimensions: 2}}
materials:
  plate: {{model: elastic, density: 1000, youngs_modulus: 2.0e6, poissons_ratio: 0.3975}}
particles:
  plate: {{generate: {{shape: box, min: [{:.17g}, -0.01, -0.001], max: [0.2, 0.01, 0.001], spacing: {:.17g}}},
          material: plate, smoothing_ratio: 1.3, viscosity: {{linear: 0.1, quadratic: 0.0}},
          corrected_gradient: true,
          artificial_stress: {{epsilon: 0.3}}}}
boundary_conditions:
  - {{set: {{part: plate, box: {{min: [-1, -1, -1], max: [0, 1, 1]}}}}, fix: all}}
)",
                                       -4 * dx, dx);
  const Config config = test::deck(deck);
  const Comm world = Comm::world();
  Simulation sim(config, world);
  const double L = 0.2, H = 0.02, E = 2e6, nu = 0.3975, rho = 1000, kL = 1.8751;
  const double k = kL / L;
  auto mode = [&](double x) {
    const double a = (std::cos(kL) + std::cosh(kL)) / (std::sin(kL) + std::sinh(kL));
    return (std::cos(k * x) - std::cosh(k * x)) - a * (std::sin(k * x) - std::sinh(k * x));
  };
  const double vtip = 0.05;
  auto& pt = sim.sph()->particles();
  for (std::size_t i = 0; i < pt.size(); ++i)
    if (pt.x0[0][i] > 0) pt.v[1][i] = vtip * mode(pt.x0[0][i]) / mode(L);

  // Mean y-velocity of the last column of particles (x0 > L - spacing).
  auto tip_velocity = [&]() {
    double s[2] = {0, 0};
    const auto& p = sim.sph()->particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.x0[0][i] > L - dx) {
        s[0] += p.v[1][i];
        s[1] += 1;
      }
    world.sum(std::span<double>(s, 2));
    return s[0] / s[1];
  };
  double t_prev = 0, v_prev = tip_velocity(), t_quarter = -1;
  while (!sim.finished() && t_quarter < 0) {
    sim.step();
    const double v = tip_velocity(); // v(n + 1/2) at t(n) + dt/2
    const double t = sim.clock().time - 0.5 * sim.clock().dt;
    if (v_prev > 0 && v <= 0) t_quarter = t_prev + (t - t_prev) * v_prev / (v_prev - v);
    t_prev = t;
    v_prev = v;
  }
  const double omega = std::sqrt(E * H * H * k * k * k * k / (12 * rho * (1 - nu * nu)));
  const double T = 2 * M_PI / omega, T_sph = 4 * t_quarter;
  if (world.rank() == 0)
    std::printf("plate: period %.4f s (plate theory %.4f s, %+.2f%%), cycles %lld\n", T_sph, T,
                100 * (T_sph / T - 1), static_cast<long long>(sim.clock().cycle));
  return {t_quarter > 0 ? T_sph : -1.0, T};
}

// The verification: 16 particles through the thickness, period within 5% of plate theory.
// Convergence: at 8 particles the error is larger by at least the factor 2 that a
// first-order method gives on halving the spacing (measured: 3.2, order 1.7).
TEST(SphPlate, PeriodWithin5PercentAndConverging) {
  const auto [T16, T] = plate_periods(16);
  EXPECT_NEAR(T, 0.2541, 5e-4);
  ASSERT_GT(T16, 0) << "the tip velocity did not change sign";
  EXPECT_LT(std::abs(T16 / T - 1), 0.05);
  const auto [T8, T_] = plate_periods(8);
  ASSERT_GT(T8, 0) << "the tip velocity did not change sign (8 particles)";
  EXPECT_GT(std::abs(T8 / T - 1), 2 * std::abs(T16 / T - 1));
}

} // namespace
