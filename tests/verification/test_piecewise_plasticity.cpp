// Tabulated hardening and the Cowper-Symonds rate law (`piecewise_linear_plasticity`,
// LS-DYNA's *MAT_PIECEWISE_LINEAR_PLASTICITY; docs/deck.md) in whole runs: a cube of
// 2 x 2 x 2 elements pulled in uniaxial stress (symmetry planes x = 0, y = 0, z = 0 held
// normally, the sides free, the top driven at a velocity that ramps up over 0.2 ms, well
// over the transit of the slowest plastic wave, then holds), to a true strain of about 0.2.
// The deformation is homogeneous, so the one-point element is exact for it, and the run
// is quasi-static to within the inertia of a 10 mm cube.
//
// Reference: the uniaxial-stress state of J2 plasticity with isotropic hardening (Hill,
// "The Mathematical Theory of Plasticity", 1950, ch. II; the hypoelastic rate form with
// no rotation integrates D exactly to the logarithmic strain): the true stress sigma = F /
// A (the base's reaction over the current cross-section, from the corner probe) equals
// the flow stress R(rate) sigma_y(ep), with ep = ln(lambda_z) - sigma / E, sigma_y the
// deck's curve and R = 1 + (rate / C)^(1/p) the Cowper-Symonds factor of the equivalent
// strain rate sqrt(2/3 D':D'), D from the probe's velocities and the current edge lengths.
// Tolerance 0.5% of sigma, past a plastic strain of 0.002 (before it, the corner of the
// curve at first yield is rounded by the ramp). What the tolerance covers is inertia: the
// cube rings after first yield (the elastic wave that the sudden drop in stiffness sends
// back and forth, measured at up to 0.37% in the rate-independent run), and that ringing
// dies out by ep = 0.01, past which the two agree to 2e-4 (the inertia of the cube and
// the half-step between the sampled velocities and positions). Holding the curve's last
// value instead of extending it misses by 5%.
//
// The element probe (`element_at`, history columns gauge.sxx ... gauge.plastic_strain) of
// the element at the top corner reads the cube's uniform state: szz = F / A and the other
// stresses 0 within the same 0.5% of sigma (the same ringing), its plastic strain
// ln(lambda_z) - sigma / E within 1e-4 (the ringing's share of sigma / E is 1e-5).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <string>

#include <fmt/format.h>

#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

constexpr double L = 0.01, E = 117e9, v_top = 2.0, t_ramp = 2e-4, t_end = 1.2e-3;
// The hardening curve of the deck: three segments, extended past 0.1 with the last slope.
constexpr double curve_x[] = {0.0, 0.02, 0.05, 0.1}, curve_y[] = {300e6, 340e6, 360e6, 370e6};

double sigma_y(double ep) {
  int k = 0;
  while (k < 2 && ep > curve_x[k + 1]) ++k;
  return curve_y[k] +
         (curve_y[k + 1] - curve_y[k]) / (curve_x[k + 1] - curve_x[k]) * (ep - curve_x[k]);
}

std::string cube_deck(const std::string& rate_law) {
  return fmt::format(R"(
termination: {{time: {}}}
materials:
  copper: {{model: piecewise_linear_plasticity, density: 8930, youngs_modulus: {},
           poissons_ratio: 0.35, hardening_curve: [[0, 3.0e8], [0.02, 3.4e8], [0.05, 3.6e8],
           [0.1, 3.7e8]]{}}}
parts:
  cube:
    mesh: {{generate: box, min: [0, 0, 0], max: [{}, {}, {}], divisions: [2, 2, 2]}}
    material: copper
boundary_conditions:
  - {{set: cube.xmin, fix: [x]}}
  - {{set: cube.ymin, fix: [y]}}
  - {{set: cube.zmin, fix: [z]}}
  - {{set: cube.zmax, velocity: [0, 0, {}], components: [z], curve: [[0, 0], [{}, 1]]}}
probes:
  - {{name: corner, at: [{}, {}, {}]}}
  - {{name: gauge, element_at: [{}, {}, {}]}}
)",
                     t_end, E, rate_law, L, L, L, v_top, t_ramp, L, L, L, 0.75 * L, 0.75 * L,
                     0.75 * L);
}

struct Worst {
  double error = 0, ep_end = 0, rate = 0;
  int checked = 0;
  double gauge_stress = 0, gauge_lateral = 0, gauge_strain = 0; // largest differences
};

// Runs the cube; the largest |sigma - R sigma_y(ep)| / sigma past ep = 0.002.
Worst pull(const std::string& rate_law, double C, double p) {
  const Comm world = Comm::world();
  Simulation sim(test::deck(cube_deck(rate_law)), world);
  Worst w;
  while (!sim.finished()) {
    sim.step();
    const Sample s = sim.sample();
    const double lx = L + s.probes[0], ly = L + s.probes[1], lz = L + s.probes[2];
    const double sigma = -s.reaction[3 * 2 + 2] / (lx * ly); // the base's reaction (bc 2)
    const double ep = std::log(lz / L) - sigma / E;
    if (ep < 0.002) continue;
    const double d[3] = {s.probes[3] / lx, s.probes[4] / ly, s.probes[5] / lz};
    const double dm = (d[0] + d[1] + d[2]) / 3;
    const double rate = std::sqrt(
        2.0 / 3.0 *
        ((d[0] - dm) * (d[0] - dm) + (d[1] - dm) * (d[1] - dm) + (d[2] - dm) * (d[2] - dm)));
    const double factor = C > 0 ? 1 + std::pow(rate / C, 1 / p) : 1.0;
    w.error = std::max(w.error, std::abs(sigma - factor * sigma_y(ep)) / sigma);
    // The element probe (the element at the top corner): its own stress and plastic
    // strain, the same state as the cube's (uniform).
    const double* g = s.element_probes.data();
    w.gauge_stress = std::max(w.gauge_stress, std::abs(g[2] - sigma) / sigma);
    w.gauge_lateral =
        std::max({w.gauge_lateral, std::abs(g[0]) / sigma, std::abs(g[1]) / sigma,
                  std::abs(g[3]) / sigma, std::abs(g[4]) / sigma, std::abs(g[5]) / sigma});
    w.gauge_strain = std::max(w.gauge_strain, std::abs(g[6] - ep));
    w.ep_end = ep;
    w.rate = rate;
    ++w.checked;
  }
  return w;
}

TEST(PiecewisePlasticity, UniaxialStressFollowsTheCurve) {
  const Worst w = pull("", 0, 0);
  EXPECT_GT(w.checked, 500);
  EXPECT_GT(w.ep_end, 0.15); // past the curve's last point, on its extension
  EXPECT_LT(w.error, 0.005) << "true stress off the hardening curve by " << w.error;
  EXPECT_LT(w.gauge_stress, 0.005) << "element probe's szz off F / A by " << w.gauge_stress;
  EXPECT_LT(w.gauge_lateral, 0.005) << "element probe's other stresses " << w.gauge_lateral;
  EXPECT_LT(w.gauge_strain, 1e-4) << "element probe's plastic strain off by " << w.gauge_strain;
  if (Comm::world().rank() == 0)
    std::printf("tabulated hardening: worst |sigma - sigma_y(ep)| / sigma %.2e over %d samples "
                "to ep %.3f; element probe: szz %.2e, other stresses %.2e (of sigma), plastic "
                "strain %.2e\n",
                w.error, w.checked, w.ep_end, w.gauge_stress, w.gauge_lateral, w.gauge_strain);
}

TEST(PiecewisePlasticity, CowperSymondsRaisesTheFlowStress) {
  const Worst w = pull(", cowper_symonds_C: 40, cowper_symonds_p: 5", 40, 5);
  EXPECT_GT(w.checked, 500);
  EXPECT_GT(w.rate, 150); // ~ v / l: the factor R is about 2.3
  EXPECT_LT(w.error, 0.005) << "true stress off the Cowper-Symonds flow stress by " << w.error;
  if (Comm::world().rank() == 0)
    std::printf("Cowper-Symonds: worst |sigma - R sigma_y(ep)| / sigma %.2e over %d samples, "
                "final rate %.1f /s (R = %.3f)\n",
                w.error, w.checked, w.rate, 1 + std::pow(w.rate / 40, 0.2));
}

} // namespace
