// Prescribed motions with time histories (deck `curve`, *BOUNDARY_PRESCRIBED_MOTION with
// *DEFINE_CURVE; docs/deck.md).
//
// 1. A velocity history drives a 1-D elastic wave (uniaxial strain). Reference:
//    d'Alembert's solution for a semi-infinite column (Graff, "Wave Motion in Elastic
//    Solids", 1975, section 1.1): the end's velocity v0(t) travels unchanged at
//    c = sqrt((lambda + 2 mu) / rho), v(z, t) = v0(t - z / c), until the reflection from
//    the free end comes back. v0 ramps linearly from 0 to 1 m/s over 40 element transits,
//    then holds. Tolerances (stated before the run): away from the ramp's two corners,
//    which the mesh's dispersion rounds off over a few elements, the mid-length velocity
//    within 0.5% of v0's amplitude; the driven end's displacement is the midpoint-rule
//    integral of the history, exact on each linear segment, so within the one step that
//    straddles the corner: |error| <= |slope jump| dt^2 / 8.
// 2. A displacement history (three segments, up, down, held) is followed by the driven
//    nodes and particles to round-off: the velocity of each step is the difference of the
//    history over the step, so no truncation error accumulates (a velocity integrated from
//    a velocity history would be off by O(dt^2) per corner, ~1e-10 m here). Tolerance: the
//    round-off of the position sums, one half-ulp of the largest coordinate (0.07 m) per
//    step and per operation (x += dt v, u = x - x0), i.e. cycles * ulp(0.07 m); the same from
//    an LS-DYNA keyword deck (VAD 2, SF and the curve's SFO).
// 3. The reactions (history columns bcN.fx ...): a column in uniaxial strain, fixed at its
//    base, its top pulled by a displacement ramp over 20 wave transits. References: (a)
//    Newton's second law, summed over the nodes: the internal forces cancel, so over each
//    step the reactions' sum times the velocity interval is the change of momentum, to
//    round-off (tolerance 1e-9 of the largest |sum R| dt); (b) statics (uniaxial strain):
//    the top's force M A u / L, M = E (1 - nu) / ((1 + nu) (1 - 2 nu)), plus the dynamic
//    part of a column driven at constant speed v, a step wave rho c v A that doubles on
//    reflection from the fixed base: tolerance 2 rho c v A (5% of the final static force).
// 4. A constraint that stops (or starts) nodes and particles at t = 0 gives them an impulse
//    there, which the first row's reactions hold (as a rigid wall's force does): times the
//    first step's velocity interval, the reactions are the change of momentum from the
//    deck's initial velocities to the first step's (Newton, the internal forces cancelling;
//    tolerance 1e-12 relative, round-off).
// 5. A body driven rigidly at a constant acceleration (every node on a velocity ramp):
//    the work-energy theorem, kinetic energy = the reactions' work at every row but the
//    last (whose step is shortened to land on the end time, exactly). Tolerance 1e-12 of
//    the kinetic energy (round-off of the sums; the work was ahead by F v dt / 2 before
//    QA round 24).
// 6. A condition holds only from its birth to its death (LS-DYNA's BIRTH and DEATH): a free
//    block and a particle cube at rest, driven at 2 m/s from 10 us to 30 us, keep still
//    before (Newton: no force, momentum 0 exactly), move at the driven speed between, and
//    coast at it after, free (no force: the momentum stays, to round-off of 1e-12, and the
//    reactions are 0). A component goes to the last item that holds it and is active: a
//    driver that dies hands its nodes and particles to a fix born then, or to a fix listed
//    before it (QA round 26: the later item owned the component even while inactive, so
//    the driver never acted); exactly 2 m/s, then exactly 0.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "anvil/io/keyword.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

// The steel columns of tests 1 and 3 (test::column_deck): L = 0.1 m along z, in uniaxial
// strain (sides held laterally), with the P-wave modulus M and wave speed c.
constexpr double L = test::column_length, rho = 7850, E = 200e9, nu = 0.3;
const double M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
const double c = std::sqrt(M / rho);
using test::column_deck;

TEST(PrescribedMotion, VelocityHistoryTravelsAsDAlembertSays) {
  const double T = 0.2 * L / c; // 40 of the 200 elements
  const double t_end = 1.2 * L / c;
  const std::string deck =
      column_deck(0.0005, 200, t_end,
                  fmt::format("  - {{set: column.zmin, velocity: [0, 0, 1.0], components: [z], "
                              "curve: [[0, 0], [{}, 1]]}}\n"
                              "probes:\n  - {{name: mid, at: [0, 0, 0.05]}}\n"
                              "  - {{name: end, at: [0, 0, 0]}}\n",
                              T));
  const Comm world = Comm::world();
  Simulation sim(test::deck(deck), world);
  auto v0 = [&](double t) { return t <= 0 ? 0.0 : (t < T ? t / T : 1.0); };
  auto d0 = [&](double t) { return t <= 0 ? 0.0 : (t < T ? t * t / (2 * T) : t - T / 2); };
  double worst = 0, dt_max = 0;
  int checked = 0;
  Sample s;
  while (!sim.finished()) {
    sim.step();
    s = sim.sample();
    dt_max = std::max(dt_max, s.dt);
    // Away from the corners at t' = 0 and t' = T (t' = t - z / c): 0.2 T on either side.
    const double tr = s.time - 0.05 / c;
    if (std::abs(tr) < 0.2 * T || std::abs(tr - T) < 0.2 * T) continue;
    worst = std::max(worst, std::abs(s.probes[5] - v0(tr)));
    ++checked;
  }
  ASSERT_GT(checked, 100);
  EXPECT_LT(worst, 0.005) << "mid-length velocity off d'Alembert's by " << worst << " m/s";
  const double uz = s.probes[6 + 2], expected = d0(s.time);
  const double bound = (1 / T) * dt_max * dt_max / 8;
  EXPECT_LE(std::abs(uz - expected), bound)
      << "end displacement " << uz << " m, integral of the history " << expected << " m";
  if (world.rank() == 0)
    std::printf("velocity history: worst mid-length velocity error %.2e m/s (%d samples), end "
                "displacement error %.2e m (bound %.2e m)\n",
                worst, checked, std::abs(uz - expected), bound);
}

// The history of test 2: up to 1 at 20 us, down to 0.25 at 50 us, then held.
double history(double t) {
  if (t <= 0) return 0;
  if (t < 2e-5) return t / 2e-5;
  if (t < 5e-5) return 1 - 0.75 * (t - 2e-5) / 3e-5;
  return 0.25;
}

// Runs `config` to its end; per probe, the largest difference between its z displacement
// and amplitude * history(t) over every sample.
// Also the round-off bound of the header, cycles * ulp(0.07 m), as the last entry.
std::vector<double> worst_displacement_errors(const Config& config, double amplitude) {
  const Comm world = Comm::world();
  Simulation sim(config, world);
  std::vector<double> worst(config.probes.size() + 1, 0.0);
  std::int64_t cycles = 0;
  while (!sim.finished()) {
    sim.step();
    const Sample s = sim.sample();
    cycles = s.cycle + 1;
    for (std::size_t p = 0; p + 1 < worst.size(); ++p)
      worst[p] = std::max(worst[p], std::abs(s.probes[6 * p + 2] - amplitude * history(s.time)));
  }
  worst.back() = static_cast<double>(cycles) * (std::nextafter(0.07, 1.0) - 0.07);
  return worst;
}

TEST(PrescribedMotion, DisplacementHistoryIsFollowedToRoundOff) {
  const double a = 1e-4; // m
  const std::string deck = R"(
termination: {time: 8.0e-5}
materials:
  steel: {model: elastic, density: 7800, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  bar:
    mesh: {generate: box, min: [0, 0, 0], max: [0.01, 0.01, 0.05], divisions: [2, 2, 10]}
    material: steel
particles:
  slab:
    generate: {shape: box, min: [0, 0, 0.06], max: [0.01, 0.01, 0.07], spacing: 1.0e-3}
    material: steel
node_sets:
  piston: {part: slab, box: {min: [-1, -1, 0.0685], max: [1, 1, 1]}}
boundary_conditions:
  - {set: bar.zmin, fix: all}
  - {set: bar.zmax, displacement: [0, 0, 1.0e-4], components: [z],
     curve: [[0, 0], [2.0e-5, 1], [5.0e-5, 0.25]]}
  - {set: piston, displacement: [0, 0, 1.0e-4], components: [z],
     curve: [[0, 0], [2.0e-5, 1], [5.0e-5, 0.25]]}
probes:
  - {name: top, at: [0.01, 0.01, 0.05]}
  - {name: piston, at: [0.0095, 0.0095, 0.0695]}
)";
  const auto worst = worst_displacement_errors(test::deck(deck), a);
  const double worst_node = worst[0], worst_particle = worst[1], bound = worst[2];
  EXPECT_LT(worst_node, bound);
  EXPECT_LT(worst_particle, bound);

  // The same bar from a keyword deck: SF 2e-4 times a curve of values 0.5 (SFO 0.5) at the
  // history's points.
  const std::string k = R"(*KEYWORD
*CONTROL_TERMINATION
    8.0E-5
*PART
bar
         1         1         1
*SECTION_SOLID
         1         1
*MAT_ELASTIC
         1    7800.0   2.0E+11       0.3
*NODE
       1             0.0             0.0             0.0
       2            0.01             0.0             0.0
       3            0.01            0.01             0.0
       4             0.0            0.01             0.0
       5             0.0             0.0            0.05
       6            0.01             0.0            0.05
       7            0.01            0.01            0.05
       8             0.0            0.01            0.05
*ELEMENT_SOLID
       1       1       1       2       3       4       5       6       7       8
*SET_NODE_LIST
         1
         1         2         3         4
*SET_NODE_LIST
         2
         5         6         7         8
*BOUNDARY_SPC_SET
         1         0         1         1         1
*BOUNDARY_PRESCRIBED_MOTION_SET
         2         3         2         7    2.0E-4
*DEFINE_CURVE
         7         0       0.0       0.5
                 0.0                 0.0
              2.0E-5                 1.0
              5.0E-5                0.25
              8.0E-5                0.25
*DATABASE_HISTORY_NODE
         7
*END
)";
  const auto keyword = worst_displacement_errors(parse_keyword_deck(k, "bar.k", "."), a);
  const double worst_keyword = keyword[0];
  EXPECT_LT(worst_keyword, keyword[1]);
  if (Comm::world().rank() == 0)
    std::printf("displacement history: worst error %.2e m (nodes), %.2e m (particles), "
                "%.2e m (keyword deck); round-off bound %.2e m, amplitude %.0e m\n",
                worst_node, worst_particle, worst_keyword, bound, a);
}

TEST(PrescribedMotion, ReactionsBalanceMomentumAndTheStaticForce) {
  const double A = 1e-4, u_max = 1e-5;
  const double T = 20 * L / c, v = u_max / T;
  const std::string deck =
      column_deck(0.01, 20, 1.5 * T,
                  fmt::format("  - {{set: column.zmin, fix: [z]}}\n"
                              "  - {{set: column.zmax, displacement: [0, 0, {}], components: [z], "
                              "curve: [[0, 0], [{}, 1]]}}\n",
                              u_max, T));
  const Comm world = Comm::world();
  Simulation sim(test::deck(deck), world);
  double worst_balance = 0, largest_impulse = 0, worst_static = 0;
  while (!sim.finished()) {
    // The first row (t = 0) holds the impulse that set the top's velocity at t = 0, from the
    // deck's (rest): its step starts from that momentum.
    const auto p0 =
        sim.clock().cycle == 0 ? std::array<double, 4>{0, 0, 0, 0} : test::node_momentum(sim);
    const double dt_before = sim.clock().dt;
    sim.step();
    const double dt_avg = 0.5 * (dt_before + sim.clock().dt);
    const auto p1 = test::node_momentum(sim);
    const Sample s = sim.sample();
    for (int i = 0; i < 3; ++i) {
      double sum = 0;
      for (std::size_t b = 0; b < 6; ++b) sum += s.reaction[3 * b + i];
      worst_balance = std::max(worst_balance, std::abs(sum * dt_avg - (p1[i] - p0[i])));
      largest_impulse = std::max(largest_impulse, std::abs(sum * dt_avg));
    }
    // (Not at t = 0: the top starts at full speed, an impulse in the first row.)
    const double u = u_max * std::min(s.time / T, 1.0);
    if (s.cycle > 0)
      worst_static = std::max(worst_static, std::abs(s.reaction[3 * 5 + 2] - M * A * u / L));
  }
  EXPECT_LT(worst_balance, 1e-9 * largest_impulse);
  const double bound = 2 * rho * c * v * A;
  EXPECT_LT(worst_static, bound);
  if (world.rank() == 0)
    std::printf("reactions: momentum balance %.2e N s (largest impulse %.2e N s); top force off "
                "the static M A u / L by at most %.1f N (bound 2 rho c v A = %.1f N, static "
                "force at the end %.1f N)\n",
                worst_balance, largest_impulse, worst_static, bound, M * A * u_max / L);
}

TEST(PrescribedMotion, RigidlyDrivenBodyGainsTheWorkOfItsReactions) {
  const double end = 2.0e-5;
  const std::string deck = fmt::format(R"(
termination: {{time: {}}}
materials:
  steel: {{model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}}
parts:
  box:
    mesh: {{generate: box, min: [0, 0, 0], max: [0.01, 0.01, 0.01], divisions: [3, 3, 3]}}
    material: steel
boundary_conditions:
  - {{set: {{part: box}}, velocity: [0.3, 0, 1.0], curve: [[0, 0], [4.0e-5, 2]]}}
)",
                                       end);
  const Comm world = Comm::world();
  Simulation sim(test::deck(deck), world);
  double worst = 0;
  int rows = 0;
  while (!sim.finished()) {
    sim.step();
    if (sim.finished()) break; // (the shortened last step's row)
    const Sample s = sim.sample();
    worst = std::max(worst, std::abs(s.kinetic - s.external_work) / std::max(s.kinetic, 1e-300));
    ++rows;
  }
  EXPECT_GT(rows, 50);
  EXPECT_LT(worst, 1e-12) << "kinetic energy off the reactions' work";
  EXPECT_EQ(sim.clock().time, end); // the last step lands on the end time exactly
}

TEST(PrescribedMotion, ConditionsHoldFromBirthToDeath) {
  const std::string deck = R"(
termination: {time: 5.0e-5}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  box:
    mesh: {generate: box, min: [0, 0, 0], max: [0.004, 0.004, 0.004], divisions: [2, 2, 2]}
    material: steel
particles:
  ball: {generate: {shape: box, min: [0.01, 0, 0], max: [0.014, 0.004, 0.004], spacing: 1.0e-3},
         material: steel}
boundary_conditions:
  - {set: {part: box}, velocity: [0, 0, 2.0], birth: 1.0e-5, death: 3.0e-5}
  - {set: {part: ball}, velocity: [2.0, 0, 0], components: [x], birth: 1.0e-5, death: 3.0e-5}
)";
  const Comm world = Comm::world();
  Simulation sim(test::deck(deck), world);
  const double M = sim.part_masses()[0], m = test::particle_momentum(sim)[3];
  int before = 0, during = 0, after = 0;
  while (!sim.finished()) {
    const double t = sim.clock().time; // the step's start: the window's test
    sim.step();
    const Sample s = sim.sample();
    const double pz = test::node_momentum(sim)[2];
    const double px = test::particle_momentum(sim)[0];
    if (t < 1.0e-5) {
      ++before;
      EXPECT_EQ(pz, 0.0);
      EXPECT_EQ(px, 0.0);
    } else if (t < 3.0e-5) {
      ++during;
      EXPECT_NEAR(pz, 2.0 * M, 1e-12 * M);
      EXPECT_NEAR(px, 2.0 * m, 1e-12 * m);
    } else {
      ++after;
      EXPECT_NEAR(pz, 2.0 * M, 1e-12 * M); // coasting, free
      EXPECT_NEAR(px, 2.0 * m, 1e-12 * m);
      for (const double r : s.reaction) EXPECT_EQ(r, 0.0);
    }
  }
  EXPECT_GT(before, 5);
  EXPECT_GT(during, 5);
  EXPECT_GT(after, 5);
}

TEST(PrescribedMotion, ADriverThatDiesHandsItsComponentsOn) {
  const std::string base = R"(
termination: {time: 4.0e-5}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  box:
    mesh: {generate: box, min: [0, 0, 0], max: [0.004, 0.004, 0.004], divisions: [1, 1, 1]}
    material: steel
particles:
  ball: {generate: {shape: box, min: [0.01, 0, 0], max: [0.012, 0.002, 0.002], spacing: 1.0e-3},
         material: steel}
boundary_conditions:
)";
  const std::string push = "  - {set: {part: box}, velocity: [0, 0, 2.0], death: 2.0e-5}\n"
                           "  - {set: {part: ball}, velocity: [0, 0, 2.0], death: 2.0e-5}\n";
  const std::string hold_later = "  - {set: {part: box}, fix: [z], birth: 2.0e-5}\n"
                                 "  - {set: {part: ball}, fix: [z], birth: 2.0e-5}\n";
  const std::string hold_always = "  - {set: {part: box}, fix: [z]}\n"
                                  "  - {set: {part: ball}, fix: [z]}\n";
  const Comm world = Comm::world();
  for (const std::string& deck : {base + push + hold_later, base + hold_always + push}) {
    Simulation sim(test::deck(deck), world);
    const double M = sim.part_masses()[0], m = test::particle_momentum(sim)[3];
    int pushed = 0, held = 0;
    while (!sim.finished()) {
      const double t = sim.clock().time;
      sim.step();
      const double pz = test::node_momentum(sim)[2];
      const double qz = test::particle_momentum(sim)[2];
      const double v = t < 2.0e-5 ? 2.0 : 0.0;
      (t < 2.0e-5 ? pushed : held)++;
      EXPECT_NEAR(pz, v * M, 1e-12 * M) << "t = " << t;
      EXPECT_NEAR(qz, v * m, 1e-12 * m) << "t = " << t;
    }
    EXPECT_GT(pushed, 5);
    EXPECT_GT(held, 5);
  }
}

TEST(PrescribedMotion, TheImpulseOfTimeZeroIsInTheFirstRow) {
  const std::string deck = R"(
termination: {cycles: 3}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  bar:
    mesh: {generate: box, min: [0, 0, 0], max: [0.004, 0.004, 0.02], divisions: [2, 2, 10]}
    material: steel
particles:
  ball: {generate: {shape: box, min: [0.01, 0, 0], max: [0.014, 0.004, 0.004], spacing: 1.0e-3},
         material: steel}
initial_conditions:
  - {part: bar, velocity: [0, 3.0, -10.0]}
  - {part: ball, velocity: [4.0, 0, 0]}
boundary_conditions:
  - {set: bar.zmin, fix: [z]}
  - {set: {part: ball}, velocity: [-1.0, 0, 0], components: [x]}
)";
  const Comm world = Comm::world();
  Simulation sim(test::deck(deck), world);
  sim.step();
  const Sample s = sim.sample();
  ASSERT_EQ(s.cycle, 0);
  const double dt_avg = 0.5 * sim.clock().dt; // the first step's interval: half its step
  // Newton over the first step, from the deck's velocities (the internal forces cancel):
  // the bar's z momentum was -10 M, the particles' x momentum 4 m.
  const double M = sim.part_masses()[0];
  const auto particles = test::particle_momentum(sim);
  const double m = particles[3], px = particles[0];
  const double pz = test::node_momentum(sim)[2];
  EXPECT_NEAR(s.reaction[2] * dt_avg, pz - (-10.0 * M), 1e-12 * 10.0 * M);
  EXPECT_NEAR(s.reaction[3] * dt_avg, px - 4.0 * m, 1e-12 * 5.0 * m);
  EXPECT_GT(s.reaction[2] * dt_avg, 10.0 * M / 20); // at least the stop of the base (M / 20)
  EXPECT_NEAR(px, -1.0 * m, 1e-12 * m);             // held at -1 m/s
  // Later rows hold only the steps' forces: no impulse of t = 0 again.
  sim.step();
  EXPECT_LT(std::abs(sim.sample().reaction[3]), 1e-6 * m * 5.0 / dt_avg);
}

} // namespace
