// The copper Taylor bar of examples/taylor_bar.yaml (Wilkins and Guinan 1973 setup; FE
// result of test_taylor_bar.cpp: final length 21.4-21.7 mm, footprint radius 7.12 mm,
// Simo 1992), here in SPH: the same bar (R = 3.2 mm, L = 32.4 mm, 227 m/s, J2
// plasticity, E = 117 GPa, nu = 0.35, yield 400 MPa, hardening 100 MPa, 80 us) as a
// particle cylinder against a rigid frictionless wall (the FE run fixes the impact face
// axially; the wall lets it slide alike). Coarse: spacing 0.8 mm (4 particles across
// the radius, 2,080 particles), h = 1.3 spacing, normalised gradient
// (`corrected_gradient: true`), viscosity alpha 0.2, beta 0.4, default artificial stress
// (0.3). Particle surfaces are taken half a spacing beyond the outermost centres.
// Tolerances (stated before the run): final length within 3% of 21.5 mm; footprint
// radius within 10% of 7.12 mm (4 particles across the radius).
// Why these settings (docs/sph.md, "Taylor bar"): with the plain gradient the outer
// particles' kernels are cut by the free surface, their strain rate is under-estimated
// and they yield late: footprint -25% at 0.8 mm and still -25% at 0.6 mm spacing (not a
// resolution error). Monaghan's viscosity at its gas-shock defaults (1, 2) resists the
// isochoric plastic flow (pairs along the axis approach although the volume does not
// change; the FE bar has only a bulk viscosity on the volume rate): with the normalised
// gradient, length +9.1% / +5.2% / +1.3% at alpha 1 / 0.5 / 0.2. At 0.6 mm spacing these
// settings give +0.95% and +7.2% (0.8 mm: +1.3%, +9.3%).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

struct TaylorResult {
  double length = 0, radius = 0, kinetic = 0;
};

// Runs the bar (collective): final length and footprint radius (mm), kinetic energy (J).
TaylorResult run_bar() {
  const char* deck = R"(
termination: {time: 8.0e-5}
materials:
  copper: {model: j2_plasticity, density: 8930, youngs_modulus: 117.0e9,
           poissons_ratio: 0.35, yield_stress: 0.4e9, hardening_modulus: 0.1e9}
particles:
  bar: {generate: {shape: cylinder, origin: [0, 0, 0], radius: 3.2e-3, length: 32.4e-3, axis: z,
                   spacing: 0.8e-3},
        material: copper, smoothing_ratio: 1.3, corrected_gradient: true,
        viscosity: {linear: 0.2, quadratic: 0.4}}
initial_conditions:
  - {part: bar, velocity: [0, 0, -227.0]}
rigid_walls:
  - {point: [0, 0, 0], normal: [0, 0, 1]}
)";
  const Config config = test::deck(deck);
  const Comm world = Comm::world();
  Simulation sim(config, world);
  while (!sim.finished()) sim.step();
  const auto& pt = sim.sph()->particles();
  const double s = 32.4e-3 / 40; // axial spacing of the lattice (40 layers)
  double radius = 0, top = -1e300, ke = 0;
  for (std::size_t i = 0; i < pt.size(); ++i) {
    if (pt.x0[2][i] < s) radius = std::max(radius, std::hypot(pt.x[0][i], pt.x[1][i]));
    top = std::max(top, pt.x[2][i]);
    ke += 0.5 * pt.mass[i] *
          (pt.v[0][i] * pt.v[0][i] + pt.v[1][i] * pt.v[1][i] + pt.v[2][i] * pt.v[2][i]);
  }
  radius = (world.max(radius) + 0.5 * 0.8e-3) * 1e3;
  const double length = (world.max(top) + 0.5 * s) * 1e3;
  ke = world.sum(ke);
  if (world.rank() == 0)
    std::printf("sph taylor bar: final length %.3f mm (FE 21.5: %+.2f%%), footprint radius %.3f mm "
                "(7.12: %+.2f%%), kinetic energy left %.3g J, cycles %lld\n",
                length, 100 * (length / 21.5 - 1), radius, 100 * (radius / 7.12 - 1), ke,
                static_cast<long long>(sim.clock().cycle));
  return {length, radius, ke};
}

TEST(SphTaylorBar, FinalLengthAndFootprintMatchFeResult) {
  const TaylorResult r = run_bar();
  EXPECT_LT(r.kinetic, 0.01 * 0.5 * 8930 * M_PI * 3.2e-3 * 3.2e-3 * 32.4e-3 * 227 * 227);
  EXPECT_LT(std::abs(r.length / 21.5 - 1), 0.03);
  EXPECT_LT(std::abs(r.radius / 7.12 - 1), 0.10);
}

} // namespace
