// External loads (deck `loads`, LS-DYNA *LOAD_SEGMENT(_SET) and *LOAD_NODE; docs/deck.md).
//
// 1. A pressure history on the top of a column in uniaxial strain (test::column_deck)
//    drives a 1-D elastic wave down it. Reference: d'Alembert's solution (Graff, "Wave
//    Motion in Elastic Solids", 1975, section 1.1): a traction -p(t) on the end z = L sends
//    the particle velocity v(z, t) = -p(t - (L - z) / c) / (rho c), c = sqrt(M / rho), until
//    the reflection from the fixed base comes back. p ramps from 0 to p0 over 40 element
//    transits, then holds. Tolerance (stated before the run, as for the prescribed velocity
//    of test_prescribed_motion.cpp): away from the ramp's two corners, which the mesh's
//    dispersion rounds off over a few elements, the mid-length velocity within 0.5% of the
//    amplitude p0 / (rho c).
// 2. Internal pressure in a thick-walled tube in plane strain (its ends held axially).
//    Reference: Lame's solution (Timoshenko and Goodier, "Theory of Elasticity", 3rd ed.,
//    1970, section 28): u(r) = (1 + nu) p a^2 / (E (b^2 - a^2)) ((1 - 2 nu) r + b^2 / r),
//    and the axial stress nu (sigma_r + sigma_theta) = 2 nu p a^2 / (b^2 - a^2), so the
//    ends carry 2 nu p pi a^2. The pressure ramps up over about ten periods of the tube's
//    breathing mode and then holds; the radial displacements of the inner and outer
//    surfaces and the base's axial reaction, averaged over the hold (the ringing the ramp
//    leaves averages out), are compared. Tolerance 1%: 8 elements through the wall and 72
//    around (the surface is a polygon whose area is 0.13% short of the circle's).
// 3. The pressure on the column's top and the nodal forces it amounts to, p A / 4 on each
//    of the top's four corners (the consistent forces of a uniform pressure on a flat
//    square, exactly), give the same motion: tolerance 1e-12 of the velocity amplitude
//    (the two sums differ in their last bits only).
// 4. A uniform pressure on the whole surface of a free body (a cylinder, whose butterfly
//    section and facets make warped and tilted faces) pushes it nowhere: the forces on a
//    closed surface sum to zero (each face's to minus its vector area, which depends on
//    its boundary only). Tolerance: the momentum stays below 1e-12 of the sum of |m v|.
//    And the state it settles to is uniform compression (the element reproduces a uniform
//    stress exactly, so this is exact in the continuum and on the mesh): the radial
//    displacement of the surface -p R / (3 K), averaged over the hold, within 1%.
// 5. The same column loaded from an LS-DYNA keyword deck (*SET_SEGMENT and
//    *LOAD_SEGMENT_SET; *LOAD_SEGMENT with the segment reversed and a negative scale;
//    *LOAD_NODE_POINT) moves as the YAML deck's: tolerance 1e-12 of the amplitude.
// 6. A load acts from its birth to its death: a force F on each node of a free element from
//    10 us to 30 us gives it the momentum N F (30 - 10) us (Newton), to within one step's
//    impulse N F dt (the steps that start inside the window carry the load), and none
//    before its birth. The same force on every node moves the block rigidly: its kinetic
//    energy is the load's work at every row but the last (work-energy theorem; tolerance
//    1e-12 of the kinetic energy, round-off; the load's sudden start and stop included).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "anvil/io/keyword.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

constexpr double L = test::column_length, rho = 7850, E = 200e9, nu = 0.3;
const double M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
const double c = std::sqrt(M / rho);
const double K = E / (3 * (1 - 2 * nu));

// Runs a deck to its end; the samples of every cycle.
std::vector<Sample> run(const Config& config) {
  const Comm world = Comm::world();
  Simulation sim(config, world);
  std::vector<Sample> out;
  while (!sim.finished()) {
    sim.step();
    out.push_back(sim.sample());
  }
  return out;
}

// The mean of column k of the probe values over the samples at or after `from`.
double mean_after(const std::vector<Sample>& samples, double from, std::size_t k) {
  double sum = 0;
  int count = 0;
  for (const auto& s : samples)
    if (s.time >= from) {
      sum += s.probes[k];
      ++count;
    }
  return sum / count;
}

TEST(Loads, PressureHistoryTravelsAsDAlembertSays) {
  const double p0 = 1.0e8, T = 0.2 * L / c; // 40 of the 200 elements
  const std::string deck = test::column_deck(
      0.0005, 200, 1.2 * L / c,
      fmt::format("  - {{set: column.zmin, fix: [z]}}\n"
                  "loads:\n  - {{surface: column.zmax, pressure: {}, curve: [[0, 0], [{}, 1]]}}\n"
                  "probes:\n  - {{name: mid, at: [0, 0, 0.05]}}\n",
                  p0, T));
  const double amplitude = p0 / (rho * c);
  auto v = [&](double t) { return -amplitude * (t <= 0 ? 0.0 : (t < T ? t / T : 1.0)); };
  double worst = 0;
  int checked = 0;
  for (const Sample& s : run(test::deck(deck))) {
    // Away from the corners at t' = 0 and t' = T (t' = t - (L - z) / c): 0.2 T either side.
    const double tr = s.time - 0.05 / c;
    if (std::abs(tr) < 0.2 * T || std::abs(tr - T) < 0.2 * T) continue;
    worst = std::max(worst, std::abs(s.probes[5] - v(tr)));
    ++checked;
  }
  ASSERT_GT(checked, 100);
  EXPECT_LT(worst, 0.005 * amplitude) << "mid-length velocity off d'Alembert's by " << worst;
  if (Comm::world().rank() == 0)
    std::printf("pressure history: worst mid-length velocity error %.3f%% of %.4f m/s (%d "
                "samples)\n",
                100 * worst / amplitude, amplitude, checked);
}

TEST(Loads, InternalPressureMatchesLame) {
  const double p = 1.0e7, a = 0.025, b = 0.035;
  const double ramp = 4.0e-4, end = 6.0e-4;
  const std::string deck = fmt::format(R"(
termination: {{time: {}}}
materials:
  steel: {{model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}}
parts:
  tube:
    mesh: {{generate: can, radius: 0.03, height: 0.004, thickness: 0.01, divisions: [72, 1, 8]}}
    material: steel
boundary_conditions:
  - {{set: tube.bottom, fix: [z]}}
  - {{set: tube.top, fix: [z]}}
loads:
  - {{surface: tube.inner, pressure: {}, curve: [[0, 0], [{}, 1]]}}
probes:
  - {{name: in, at: [{}, 0, 0]}}
  - {{name: out, at: [{}, 0, 0]}}
)",
                                       end, p, ramp, a, b);
  const auto samples = run(test::deck(deck));
  auto lame = [&](double r) {
    return (1 + nu) * p * a * a / (E * (b * b - a * a)) * ((1 - 2 * nu) * r + b * b / r);
  };
  const double u_in = mean_after(samples, ramp, 0), u_out = mean_after(samples, ramp, 6);
  double fz = 0;
  int count = 0;
  for (const auto& s : samples)
    if (s.time >= ramp) {
      fz += s.reaction[2]; // bc0.fz, the base
      ++count;
    }
  fz /= count;
  const double axial = 2 * nu * p * std::numbers::pi * a * a;
  const double e_in = u_in / lame(a) - 1, e_out = u_out / lame(b) - 1;
  const double e_axial = std::abs(fz) / axial - 1;
  EXPECT_LT(std::abs(e_in), 0.01) << "inner radial displacement " << u_in << " m";
  EXPECT_LT(std::abs(e_out), 0.01) << "outer radial displacement " << u_out << " m";
  EXPECT_LT(std::abs(e_axial), 0.01) << "axial reaction " << fz << " N";
  if (Comm::world().rank() == 0)
    std::printf("Lame tube: u(a) %+.3f%%, u(b) %+.3f%%, axial reaction %+.3f%%\n", 100 * e_in,
                100 * e_out, 100 * e_axial);
}

TEST(Loads, PressureEqualsItsNodalForces) {
  const double p0 = 1.0e8, w = 0.002, end = 0.8 * L / c;
  const std::string more = "  - {set: column.zmin, fix: [z]}\n"
                           "probes:\n  - {name: mid, at: [0, 0, 0.05]}\n"
                           "  - {name: top, at: [0, 0, 0.1]}\n";
  const auto pressed = run(test::deck(
      test::column_deck(w, 50, end,
                        more + fmt::format("loads:\n  - {{surface: column.zmax, pressure: {}, "
                                           "curve: [[0, 0], [2.0e-6, 1]]}}\n",
                                           p0))));
  const auto pushed = run(test::deck(
      test::column_deck(w, 50, end,
                        more + fmt::format("loads:\n  - {{set: column.zmax, force: [0, 0, {}], "
                                           "curve: [[0, 0], [2.0e-6, 1]]}}\n",
                                           -p0 * w * w / 4))));
  ASSERT_EQ(pressed.size(), pushed.size());
  double worst = 0;
  for (std::size_t k = 0; k < pressed.size(); ++k)
    for (std::size_t j = 0; j < pressed[k].probes.size(); ++j)
      if (j % 6 >= 3) worst = std::max(worst, std::abs(pressed[k].probes[j] - pushed[k].probes[j]));
  const double amplitude = p0 / (rho * c);
  EXPECT_LT(worst, 1e-12 * amplitude);
  EXPECT_LT(pressed.back().probes[5], -0.5 * amplitude); // the wave has passed mid-length
}

TEST(Loads, PressureOnAClosedSurfaceMovesNothing) {
  const double p = 1.0e8, R = 0.01, ramp = 6.0e-5, end = 9.0e-5;
  const std::string deck = fmt::format(R"(
termination: {{time: {}}}
materials:
  steel: {{model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}}
parts:
  blob:
    mesh: {{generate: cylinder, radius: {}, length: 0.02, divisions: [4, 8]}}
    material: steel
loads:
  - {{surface: {{part: blob}}, pressure: {}, curve: [[0, 0], [{}, 1]]}}
probes:
  - {{name: rim, at: [{}, 0, 0.01]}}
)",
                                       end, R, p, ramp, R);
  const Comm world = Comm::world();
  Simulation sim(test::deck(deck), world);
  std::vector<Sample> samples;
  double worst = 0, scale = 0;
  while (!sim.finished()) {
    sim.step();
    samples.push_back(sim.sample());
    const auto m = test::node_momentum(sim);
    worst = std::max({worst, std::abs(m[0]), std::abs(m[1]), std::abs(m[2])});
    scale = std::max(scale, m[3]);
  }
  EXPECT_LT(worst, 1e-12 * scale) << "momentum " << worst << " N s against sum |m v| " << scale;
  // The rim probe is at (R, 0, L/2), the centre of the compression: its radial motion.
  const double u = mean_after(samples, ramp, 0), expected = -p * R / (3 * K);
  EXPECT_LT(std::abs(u / expected - 1), 0.01) << "radial displacement " << u << " m";
  if (Comm::world().rank() == 0)
    std::printf("closed surface: momentum %.1e of sum |m v| %.2e N s; radial displacement "
                "%+.3f%% off -p R / 3K\n",
                worst / scale, scale, 100 * (u / expected - 1));
}

// The column of test 3 as an LS-DYNA deck (free format: the numbers keep every digit):
// nodes 4l+1..4l+4 at height z_l (l = 0..cells), element l+1 between levels l and l+1, every
// node held in x and y and the base in z; the top face pressed as a segment set, and again
// as a single segment listed the other way round with a negative scale (each half the
// pressure), and a force on the top's first node.
std::string keyword_column(int cells, double w, double p0, double force) {
  const int t = 4 * cells; // the top's first node id - 1
  std::string k = fmt::format("*KEYWORD\n*CONTROL_TERMINATION\n{},\n", 0.8 * L / c);
  k += "*PART\ncolumn\n1, 1, 1\n*SECTION_SOLID\n1, 1\n*MAT_ELASTIC\n1, 7850.0, 2.0E+11, 0.3\n"
       "*NODE\n";
  const double xy[4][2] = {{0, 0}, {w, 0}, {w, w}, {0, w}};
  for (int l = 0; l <= cells; ++l)
    for (int a = 0; a < 4; ++a)
      k += fmt::format("{}, {}, {}, {}\n", 4 * l + a + 1, xy[a][0], xy[a][1], L * l / cells);
  k += "*ELEMENT_SOLID\n";
  for (int l = 0; l < cells; ++l) {
    k += fmt::format("{}, 1", l + 1);
    for (int a = 0; a < 8; ++a) k += fmt::format(", {}", 4 * (l + a / 4) + a % 4 + 1);
    k += "\n";
  }
  k += fmt::format("*SET_NODE_LIST\n1\n1, 2, 3, 4\n*SET_NODE_LIST_GENERATE\n2\n1, {}\n"
                   "*BOUNDARY_SPC_SET\n1, 0, 0, 0, 1\n2, 0, 1, 1, 0\n",
                   t + 4);
  k += "*DEFINE_CURVE\n7\n0.0, 0.0\n2.0E-6, 1.0\n";
  k += fmt::format("*SET_SEGMENT\n10\n{}, {}, {}, {}\n", t + 1, t + 2, t + 3, t + 4);
  k += fmt::format("*LOAD_SEGMENT_SET\n10, 7, {}\n", 0.5 * p0);
  k += fmt::format("*LOAD_SEGMENT\n7, {}, 0.0, {}, {}, {}, {}\n", -0.5 * p0, t + 4, t + 3, t + 2,
                   t + 1);
  k += fmt::format("*LOAD_NODE_POINT\n{}, 3, 7, {}\n*END\n", t + 1, force);
  return k;
}

TEST(Loads, KeywordLoadsMatchTheYamlDeck) {
  const double p0 = 1.0e8, w = 0.002, f = -1000.0;
  const std::string yaml = test::column_deck(
      w, 50, 0.8 * L / c,
      fmt::format(
          "  - {{set: column.zmin, fix: [z]}}\n"
          "loads:\n  - {{surface: column.zmax, pressure: {}, curve: [[0, 0], [2.0e-6, 1]]}}\n"
          "  - {{set: corner, force: [0, 0, {}], curve: [[0, 0], [2.0e-6, 1]]}}\n"
          "node_sets:\n  corner: {{box: {{min: [0, 0, 0.1], max: [0, 0, 0.1]}}}}\n"
          "probes:\n  - {{name: mid, at: [0, 0, 0.05]}}\n  - {{name: top, at: [{}, {}, 0.1]}}\n",
          p0, f, w, w));
  Config k = parse_keyword_deck(keyword_column(50, w, p0, f), "column.k", ".");
  // The node's force, the set's pressure, the reversed segment's (-SF).
  ASSERT_EQ(k.loads.size(), 3u);
  EXPECT_EQ(k.loads[0].kind, Load::Kind::force);
  EXPECT_EQ(k.loads[1].pressure, 0.5 * p0);
  EXPECT_EQ(k.loads[2].pressure, 0.5 * p0);
  k.probes = test::deck(yaml).probes;
  const auto a = run(test::deck(yaml)), b = run(k);
  ASSERT_EQ(a.size(), b.size());
  double worst = 0;
  for (std::size_t s = 0; s < a.size(); ++s)
    for (std::size_t j = 0; j < a[s].probes.size(); ++j)
      if (j % 6 >= 3) worst = std::max(worst, std::abs(a[s].probes[j] - b[s].probes[j]));
  const double amplitude = p0 / (rho * c);
  EXPECT_LT(worst, 1e-12 * amplitude) << "keyword and YAML runs differ by " << worst << " m/s";
  EXPECT_LT(b.back().probes[5], -0.5 * amplitude);
}

TEST(Loads, ALoadActsFromBirthToDeath) {
  const double F = 3.0;
  const std::string deck = fmt::format(R"(
termination: {{time: 5.0e-5}}
materials:
  steel: {{model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}}
parts:
  box:
    mesh: {{generate: box, min: [0, 0, 0], max: [0.004, 0.004, 0.004], divisions: [1, 1, 1]}}
    material: steel
loads:
  - {{set: {{part: box}}, force: [0, 0, {}], birth: 1.0e-5, death: 3.0e-5}}
)",
                                       F);
  const Comm world = Comm::world();
  Simulation sim(test::deck(deck), world);
  const double N = 8; // the block's nodes, of equal masses: the block moves rigidly
  double dt_max = 0;
  double worst = 0;
  while (!sim.finished()) {
    const double t = sim.clock().time;
    sim.step();
    dt_max = std::max(dt_max, sim.clock().dt);
    if (t < 1.0e-5) EXPECT_EQ(test::node_momentum(sim)[2], 0.0);
    if (sim.finished()) break; // (the shortened last step's row)
    const Sample s = sim.sample();
    if (s.kinetic > 0) worst = std::max(worst, std::abs(s.external_work / s.kinetic - 1));
  }
  EXPECT_LT(worst, 1e-12) << "kinetic energy off the load's work";
  const double pz = test::node_momentum(sim)[2], expected = N * F * 2.0e-5;
  EXPECT_NEAR(pz, expected, N * F * dt_max) << "momentum " << pz << " N s";
}

} // namespace
