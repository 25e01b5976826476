// Rigid bodies (a part with `rigid: true`, LS-DYNA's *MAT_RIGID; docs/deck.md), in whole
// runs at NP 1 and 3.
//
// 1. An elastic bar in uniaxial strain (sides held laterally) strikes a free rigid block
//    1e4 times its mass, in general contact. Reference: 1-D wave theory (Graff, "Wave
//    Motion in Elastic Solids", 1975, section 1.1), as for the rigid wall (test_rigid_wall):
//    against a target that does not move, the bar leaves with v0 reversed after 2L/c; the
//    block then carries 2 m v0 (momentum), pushed by the force rho c v0 A. Tolerances, as the
//    wall test's: the bar's rebound within 2% of v0; the contact force (the block's mass
//    times its acceleration) on its plateau within 2% of rho c v0 A, and the contact's
//    duration (from the force's rise through half the plateau to its fall below it)
//    within 2% of 2L/c. (Measured first from the block's first motion to its last change
//    of velocity, the duration came out 7.6% long, and 3.1% from the first motion to the
//    fall: the penalty, a spring at the interface, takes a few steps to build the force
//    and lets the bar's end touch lightly after the wave has left; the wall of the wall
//    test stops the end at once.) The z momentum of bar and
//    block together constant to 1e-12 of
//    m v0 (contact forces equal and opposite, the body's internal impulses summing to zero,
//    the lateral holds acting across z); the block's corners keep their distances to 1e-12
//    relative.
// 2. The same run on one rank and on all: every probe value the same bits (DESIGN.md
//    section 3: each rank gathers the body's points in one order and moves it the same way).
// 4. A rigid plate driven into an elastic column (a keyword deck: the plate's element
//    shares the column's base nodes; *MAT_RIGID CMO = 1 holds its x, y and rotations,
//    *BOUNDARY_PRESCRIBED_MOTION_RIGID drives z at V). Reference: 1-D wave theory (Graff
//    1975, section 1.1), as test_wave_1d: the base moving at V sends the stress -rho c V up
//    the column, and the driver holds the plate against it with rho c V A. Before the wave
//    returns (2L/c), the driver's mean force (history bcN.fz) within 1% of rho c V A, the
//    mean axial stress behind the front within 1% of -rho c V, and the plate's velocity V
//    exactly, its x, y and spin 0 exactly.
// 3. An initial velocity about the body's centre of mass (`center: mass_center`, LS-DYNA's
//    *INITIAL_VELOCITY_RIGID_BODY): at t = 0 a free rigid box's centre moves at V and its
//    angular momentum is I omega about the centre; it keeps both for 200 steps (a free
//    body: Newton, Euler); all to 1e-12 of |V| and of |I omega|.
// 5. A free rigid cube, moving along x and spinning about y, dropped onto a frictionless
//    planar wall (`rigid_walls`): it lands on an edge, turns onto its face and leaves
//    rocking. Reference: the mechanics of impulses on a rigid body (Goldstein, "Classical
//    Mechanics", 3rd ed., 2002, section 1.2) and the wall's kinematic condition (the point
//    that would cross it lands on it, contact.md "Rigid walls"): no node ever behind the
//    wall (1e-12 m, round-off of 1 cm coordinates); the x momentum kept (1e-12 relative:
//    the wall pushes along z only); the wall's impulses, its force history times the step,
//    the body's change of z momentum (1e-9 relative); the energy balance closed (1e-12:
//    the walls' work is external work); the same bits on one rank and on all.
// 6. Merged rigid bodies (`merge_with`, LS-DYNA's *CONSTRAINED_RIGID_BODIES): two boxes
//    apart, the second merged into the first, the initial velocity and spin given to the
//    lead about the body's centre of mass. Reference: one rigid body (Newton, Euler): the
//    body's mass is both parts' (1e-12 relative), its centre keeps the velocity given and
//    the distance between a node of each part stays (1e-12 relative) over 300 steps, with
//    one body's columns in the sample; a condition on the merged part (`fix: [z]`) holds the
//    whole body (its z velocity 0 exactly).
// 7. A slender free body tumbling slowly for its step (QA round 38): a bar of 20 x 1 x 1
//    elements, 200 x 10 x 10 mm, at omega = (-1130, 183, 786) rad/s, 5e-4 rad a step.
//    Reference: Euler's torque-free motion (Goldstein 2002, section 5.6): it runs to 2 ms
//    (the spin's fixed-point iteration stalled at 1.1e-14 of omega at 0.29 ms, short of
//    its 1e-14, and the run stopped as if the bar spun too fast), its angular momentum
//    about its centre, from the nodes, kept to 1e-9 relative (round-off over 2,000 steps).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "anvil/io/keyword.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

// The momenta of a rigid body whose nodes are the owned ones left of x = 0.5 (the decks'
// other part lies beyond): mass, centre, the centre's velocity and the angular momentum
// about the centre (collective).
struct BodyMoments {
  double mass = 0;
  Vec3 centre, velocity, L;
};
BodyMoments body_moments(const Simulation& sim, const Comm& world) {
  const auto& nd = sim.nodes();
  BodyMoments b;
  double m = 0;
  Vec3 p{0, 0, 0}, mx{0, 0, 0};
  for (std::size_t n = 0; n < nd.size(); ++n) {
    if (!sim.fe().node_owned[n] || nd.x[0][n] > 0.5) continue;
    m += nd.mass[n];
    p += nd.mass[n] * Vec3{nd.v[0][n], nd.v[1][n], nd.v[2][n]};
    mx += nd.mass[n] * Vec3{nd.x[0][n], nd.x[1][n], nd.x[2][n]};
  }
  b.mass = world.sum(m);
  for (int i = 0; i < 3; ++i) {
    b.velocity[i] = world.sum(p[i]) / b.mass;
    b.centre[i] = world.sum(mx[i]) / b.mass;
  }
  Vec3 l{0, 0, 0};
  for (std::size_t n = 0; n < nd.size(); ++n) {
    if (!sim.fe().node_owned[n] || nd.x[0][n] > 0.5) continue;
    const Vec3 r = Vec3{nd.x[0][n], nd.x[1][n], nd.x[2][n]} - b.centre;
    l += nd.mass[n] * cross(r, Vec3{nd.v[0][n], nd.v[1][n], nd.v[2][n]} - b.velocity);
  }
  for (int i = 0; i < 3; ++i) b.L[i] = world.sum(l[i]);
  return b;
}

// How many values of two series differ in their bits.
std::size_t differing_bits(const std::vector<double>& a, const std::vector<double>& b) {
  std::size_t differing = 0;
  for (std::size_t k = 0; k < a.size() && k < b.size(); ++k)
    differing += std::memcmp(&a[k], &b[k], sizeof(double)) != 0;
  return differing;
}

constexpr double L = 0.05, a = 0.002, rho = 7850, E = 200e9, nu = 0.3, v0 = 5.0;
const double c_wave = std::sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / rho);
const double t_contact = 2 * L / c_wave;

std::string deck() {
  // The block: 4 mm x 4 mm x 2 mm under the bar's end, density 1e4 times the bar's mass
  // over its volume (bar 2 x 2 x 50 mm: the same volume ratio 200 / 32).
  const double block_density = 1e4 * rho * (a * a * L) / (0.004 * 0.004 * 0.002);
  return fmt::format(R"(
termination: {{time: {}}}
materials:
  steel: {{model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}}
  heavy: {{model: elastic, density: {}, youngs_modulus: 200.0e9, poissons_ratio: 0.3}}
parts:
  bar:
    mesh: {{generate: box, min: [0, 0, 0.000001], max: [0.002, 0.002, 0.050001], divisions: [1, 1, 100]}}
    material: steel
    bulk_viscosity: {{linear: 0, quadratic: 0}}
  block:
    mesh: {{generate: box, min: [-0.001, -0.001, -0.002], max: [0.003, 0.003, 0], divisions: [2, 2, 1]}}
    material: heavy
    rigid: true
initial_conditions:
  - {{part: bar, velocity: [0, 0, -5.0]}}
boundary_conditions:
  - {{set: bar.xmin, fix: [x]}}
  - {{set: bar.xmax, fix: [x]}}
  - {{set: bar.ymin, fix: [y]}}
  - {{set: bar.ymax, fix: [y]}}
contact:
  - {{type: general}}
probes:
  - {{name: b0, at: [-0.001, -0.001, -0.002]}}
  - {{name: b1, at: [0.003, 0.003, 0]}}
  - {{name: b2, at: [0.003, -0.001, -0.002]}}
  - {{name: top, at: [0, 0, 0.050001]}}
)",
                     1.6 * t_contact, block_density);
}

struct BarRun {
  std::vector<double> t, probes, force;
  double bar_v = 0, p_worst = 0, shape_worst = 0, start = -1;
};

BarRun run(const Comm& comm) {
  Simulation sim(test::deck(deck()), comm);
  BarRun r;
  const double m_bar = rho * a * a * L;
  const std::array<Vec3, 3> corner0{Vec3{-0.001, -0.001, -0.002}, Vec3{0.003, 0.003, 0},
                                    Vec3{0.003, -0.001, -0.002}};
  double block_v_last = 0;
  while (!sim.finished()) {
    sim.step();
    const Sample s = sim.sample();
    r.t.push_back(s.time);
    r.probes.insert(r.probes.end(), s.probes.begin(), s.probes.end());
    // z momentum of all nodes (the block's and the bar's), against the initial -m v0.
    const auto p = test::node_momentum(sim);
    r.p_worst = std::max(r.p_worst, std::abs(p[2] + m_bar * v0) / (m_bar * v0));
    std::array<Vec3, 3> x;
    for (int k = 0; k < 3; ++k)
      x[static_cast<std::size_t>(k)] =
          corner0[static_cast<std::size_t>(k)] +
          Vec3{s.probes[6 * k], s.probes[6 * k + 1], s.probes[6 * k + 2]};
    for (int i = 0; i < 3; ++i)
      for (int j = i + 1; j < 3; ++j) {
        const double d0 = norm(corner0[i] - corner0[j]), d = norm(x[i] - x[j]);
        r.shape_worst = std::max(r.shape_worst, std::abs(d - d0) / d0);
      }
    // The block's velocity is v(n + 1/2) averaged with v(n - 1/2): its change from the
    // last row over the interval is the contact force's mean (times the block's mass).
    const double block_v = s.probes[5];
    if (r.start < 0 && block_v != 0) r.start = s.time;
    r.force.push_back(r.t.size() > 1
                          ? -1e4 * m_bar * (block_v - block_v_last) / (s.time - r.t[r.t.size() - 2])
                          : 0.0);
    block_v_last = block_v;
  }
  // The bar's rebound: its centre-of-mass velocity, from the whole momentum minus the
  // block's (its probe's velocity times its mass).
  const auto p = test::node_momentum(sim);
  const double m_block = 1e4 * m_bar;
  r.bar_v = (p[2] - m_block * block_v_last) / m_bar;
  return r;
}

TEST(RigidBody, ElasticBarOnAHeavyFreeBlock) {
  const Comm world = Comm::world();
  const BarRun r = run(world);
  ASSERT_GT(r.start, 0);
  const double plateau_expected = rho * c_wave * v0 * a * a;
  double sum = 0;
  int n = 0;
  for (std::size_t k = 0; k < r.t.size(); ++k)
    if (r.t[k] > r.start + 0.1 * t_contact && r.t[k] < r.start + 0.9 * t_contact) {
      sum += r.force[k];
      ++n;
    }
  const double plateau = sum / n;
  double begin = -1, end = -1;
  for (std::size_t k = 1; k < r.t.size() && begin < 0; ++k)
    if (r.force[k - 1] < 0.5 * plateau && r.force[k] >= 0.5 * plateau)
      begin = r.t[k - 1] + (0.5 * plateau - r.force[k - 1]) / (r.force[k] - r.force[k - 1]) *
                               (r.t[k] - r.t[k - 1]);
  for (std::size_t k = 1; k < r.t.size(); ++k)
    if (r.t[k] > r.start + 0.5 * t_contact && r.force[k - 1] >= 0.5 * plateau &&
        r.force[k] < 0.5 * plateau) {
      end = r.t[k - 1] + (r.force[k - 1] - 0.5 * plateau) / (r.force[k - 1] - r.force[k]) *
                             (r.t[k] - r.t[k - 1]);
      break;
    }
  ASSERT_GT(begin, 0);
  const double duration = end - begin;
  if (world.rank() == 0)
    std::printf("bar on a rigid block: rebound %.4f m/s (v0 %.1f), plateau %.2f N (%.2f), "
                "contact %.4e s (2L/c %.4e, %+.2f%%), momentum %.1e, block shape %.1e\n",
                r.bar_v, v0, plateau, plateau_expected, duration, t_contact,
                100 * (duration - t_contact) / t_contact, r.p_worst, r.shape_worst);
  EXPECT_LT(std::abs(r.bar_v - v0) / v0, 0.02);
  EXPECT_LT(std::abs(plateau - plateau_expected) / plateau_expected, 0.02);
  ASSERT_GT(end, 0);
  EXPECT_LT(std::abs(duration - t_contact) / t_contact, 0.02);
  EXPECT_LT(r.p_worst, 1e-12);
  EXPECT_LT(r.shape_worst, 1e-12);
  // On one rank: the same bits (the world run may be on several).
  if (world.rank() != 0) return;
  const BarRun one = run(Comm::self());
  ASSERT_EQ(one.probes.size(), r.probes.size());
  EXPECT_EQ(differing_bits(one.probes, r.probes), 0u)
      << "probe values differing from the one-rank run";
}

// What rigid bodies do not support is an input error on every rank (no rank left waiting):
// a condition on a rigid part's nodes, two rigid parts sharing nodes, a model of rigid
// parts only.
TEST(RigidBody, UnsupportedUsesAreInputErrors) {
  const Comm world = Comm::world();
  const std::string base = R"(
termination: {cycles: 5}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  a:
    mesh: {generate: box, min: [0, 0, 0], max: [0.01, 0.01, 0.01], divisions: [2, 2, 2]}
    material: steel
    rigid: true
  b:
    mesh: {generate: box, min: [0, 0, 0.02], max: [0.01, 0.01, 0.03], divisions: [2, 2, 2]}
    material: steel
)";
  auto expect_error = [&](const std::string& deck, const std::string& fragment) {
    try {
      Simulation sim(test::deck(deck, "deck.yaml"), world);
      ADD_FAILURE() << "no error for " << fragment;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  expect_error(base + "boundary_conditions:\n  - {set: a.zmin, fix: [z]}\n",
               "deck.yaml:14: boundary_conditions[0]: this condition holds nodes of the rigid "
               "part a");
  expect_error(base + "    rigid: true\n", "every part is rigid");
  // Rotations hold a rigid body only; a body is held whole (its part), not by a box of it.
  expect_error(base + "boundary_conditions:\n  - {set: b.zmin, fix: [z, rx]}\n",
               "rotations (rx, ry, rz, angular_velocity, rotation) are a rigid body's");
  expect_error(base + "boundary_conditions:\n  - {part: b, angular_velocity: [0, 0, 1.0]}\n",
               "rotations (rx, ry, rz, angular_velocity, rotation) are a rigid body's");
  expect_error(base + "boundary_conditions:\n  - {set: {part: a, box: {min: [-1, -1, -1], "
                      "max: [1, 1, 1]}}, fix: all}\n",
               "a rigid body is held or driven whole (`part: a`");
  // Two rigid parts that share nodes (a keyword deck's two bricks, parts 1 and 2 of
  // *MAT_RIGID, and a third, deformable brick apart).
  std::string k = R"(*KEYWORD
*CONTROL_TERMINATION
   1.0E-05
*PART
lower
         1         1         1
upper
         2         1         1
free
         3         1         2
*SECTION_SOLID
         1         1
*MAT_RIGID
1,7850.0,2.0E+11,0.3


*MAT_ELASTIC
2,7850.0,2.0E+11,0.3
)";
  k += test::two_bricks_keyword_mesh;
  k = k.replace(k.find("       2       1       5"), 24, "       2       2       5");
  k += R"(*NODE
      21             5.0             0.0             0.0
      22             6.0             0.0             0.0
      23             6.0             1.0             0.0
      24             5.0             1.0             0.0
      25             5.0             0.0             1.0
      26             6.0             0.0             1.0
      27             6.0             1.0             1.0
      28             5.0             1.0             1.0
*ELEMENT_SOLID
       3       3      21      22      23      24      25      26      27      28
*END
)";
  try {
    Simulation sim(parse_keyword_deck(k, "model.k", "."), world);
    ADD_FAILURE() << "no error for rigid parts sharing nodes";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rigid bodies of parts part1 and part2 share 4 nodes"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("merge_with"), std::string::npos) << e.what();
  }
}

// A thin rigid plate that a fast node can cross within one step is warned of at setup
// (QA round 29: a block at 100 m/s passed through a 20 um rigid plate unseen, since rigid
// elements set no step and contact reaches depth_fraction of a face's element depth). The
// same deck with a 0.1 mm plate (7 um a step against a reach of 50 um) gets no warning.
TEST(RigidBody, ThinRigidPartsAreWarnedOf) {
  const Comm world = Comm::world();
  auto warned = [&](double thickness) {
    const std::string deck = fmt::format(R"(
termination: {{time: 1.0e-5}}
materials:
  steel: {{model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}}
parts:
  plate:
    mesh: {{generate: box, min: [0, 0, -{}], max: [0.01, 0.01, 0], divisions: [2, 2, 1]}}
    material: steel
    rigid: true
  block:
    mesh: {{generate: box, min: [0.002, 0.002, 0.0001], max: [0.008, 0.008, 0.0061],
           divisions: [3, 3, 3]}}
    material: steel
initial_conditions:
  - {{part: block, velocity: [0, 0, -100.0]}}
contact:
  - {{type: general}}
)",
                                         thickness);
    Simulation sim(test::deck(deck), world);
    for (const auto& w : sim.warnings())
      if (w.find("can pass through unseen") != std::string::npos) return true;
    return false;
  };
  EXPECT_TRUE(warned(2e-5));
  EXPECT_FALSE(warned(1e-4));
}

// 3. A free rigid box (and a deformable cube far away: anvil needs one) set moving about
// its centre of mass.
TEST(RigidBody, InitialVelocityAboutTheCentreOfMass) {
  const Comm world = Comm::world();
  const Config config = test::deck(R"(
termination: {cycles: 200}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  body:
    mesh: {generate: box, min: [0.001, 0.002, 0.003], max: [0.031, 0.012, 0.008], divisions: [6, 2, 1]}
    material: steel
    rigid: true
  far:
    mesh: {generate: box, min: [1, 1, 1], max: [1.01, 1.01, 1.01], divisions: [1, 1, 1]}
    material: steel
initial_conditions:
  - {part: body, velocity: [3.0, -2.0, 1.0], angular_velocity: [40.0, 70.0, 300.0],
     center: mass_center}
)");
  Simulation sim(config, world);
  // The body's nodes (those left of x = 0.5), their momentum and angular momentum.
  const BodyMoments start = body_moments(sim, world);
  const Vec3 v0 = start.velocity, L0 = start.L, c0 = start.centre;
  // At t = 0 the centre moves at V and the spin is omega about it: L = I omega.
  const Vec3 V{3.0, -2.0, 1.0}, w{40.0, 70.0, 300.0};
  Vec3 Iw{0, 0, 0};
  {
    const auto& nd = sim.nodes();
    Vec3 s{0, 0, 0};
    for (std::size_t n = 0; n < nd.size(); ++n) {
      if (!sim.fe().node_owned[n] || nd.x[0][n] > 0.5) continue;
      const Vec3 r = Vec3{nd.x[0][n], nd.x[1][n], nd.x[2][n]} - c0;
      s += nd.mass[n] * cross(r, cross(w, r));
    }
    for (int i = 0; i < 3; ++i) Iw[i] = world.sum(s[i]);
  }
  EXPECT_LT(norm(v0 - V), 1e-12 * norm(V));
  EXPECT_LT(norm(L0 - Iw), 1e-12 * norm(Iw));
  while (!sim.finished()) sim.step();
  const BodyMoments end = body_moments(sim, world);
  const Vec3 v1 = end.velocity, L1 = end.L;
  // v(n - 1/2) at the end: the centre's velocity is V, and the angular momentum kept.
  if (world.rank() == 0)
    std::printf("rigid body about its centre of mass: centre velocity off by %.2e of |V|, "
                "angular momentum by %.2e of |I w| after 200 steps\n",
                norm(v1 - V) / norm(V), norm(L1 - L0) / norm(L0));
  EXPECT_LT(norm(v1 - V), 1e-12 * norm(V));
  EXPECT_LT(norm(L1 - L0), 1e-12 * norm(L0));
  // history.csv's rigid.body.* (LS-DYNA's RBDOUT): the centre's displacement V t at the
  // sample's time (the start of the last step) and its velocity V over the step.
  const Sample s = sim.sample();
  ASSERT_EQ(s.rigid_bodies.size(), 9u);
  const Vec3 u{s.rigid_bodies[0], s.rigid_bodies[1], s.rigid_bodies[2]};
  const Vec3 v{s.rigid_bodies[3], s.rigid_bodies[4], s.rigid_bodies[5]};
  const double t_sample = sim.clock().time - sim.clock().dt;
  EXPECT_LT(norm(u - t_sample * V), 1e-12 * norm(V) * t_sample);
  EXPECT_LT(norm(v - V), 1e-12 * norm(V));
}

// Tests 5 and 6: a rigid steel box 30 x 10 x 5 mm at the origin, and a deformable cube far
// away (a model of rigid parts only is refused).
const char* const box_and_far = R"(materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  body:
    mesh: {generate: box, min: [0, 0, 0], max: [0.03, 0.01, 0.005], divisions: [6, 2, 1]}
    material: steel
    rigid: true
  far:
    mesh: {generate: box, min: [1, 1, 1], max: [1.01, 1.01, 1.01], divisions: [1, 1, 1]}
    material: steel
)";

// 5. A held rotation's moment (history.csv bcN.mx, my, mz): a free rigid box whose
//    rotations a condition fixes, pushed by a constant force F at one corner. Statics of
//    the rigid body: its centre accelerates as F / M and it does not turn, so the held
//    rotations take the moment -(r x F) about the centre of mass, r the corner's offset
//    from it (which the body's translation keeps). Tolerance: 1e-12 of |r x F| at every
//    sample; the translation's reaction (bcN.fx, fy, fz) 0 (nothing holds it).
TEST(RigidBody, HeldRotationsTakeTheMomentOfTheLoads) {
  const Comm world = Comm::world();
  const Config config = test::deck("termination: {cycles: 100}\n" + std::string(box_and_far) +
                                   R"(node_sets:
  corner: {part: body, box: {min: [0.029, 0.009, 0.004], max: [0.031, 0.011, 0.006]}}
loads:
  - {set: corner, force: [100.0, -250.0, 400.0]}
boundary_conditions:
  - {part: body, fix: [rx, ry, rz]}
)");
  Simulation sim(config, world);
  const Vec3 F{100.0, -250.0, 400.0};
  const Vec3 r = Vec3{0.03, 0.01, 0.005} - Vec3{0.015, 0.005, 0.0025}; // corner - centre
  const Vec3 expected = -1.0 * cross(r, F);
  double worst = 0;
  int rows = 0;
  while (!sim.finished()) {
    sim.step();
    const Sample s = sim.sample();
    ASSERT_EQ(s.reaction_moment.size(), 3u);
    for (int i = 0; i < 3; ++i) {
      worst =
          std::max(worst, std::abs(s.reaction_moment[static_cast<std::size_t>(i)] - expected[i]));
      EXPECT_EQ(s.reaction[static_cast<std::size_t>(i)], 0.0);
    }
    ++rows;
  }
  if (world.rank() == 0)
    std::printf("held rotations: moment off by %.2e of |r x F| = %.4g N m over %d samples\n",
                worst / norm(expected), norm(expected), rows);
  EXPECT_LT(worst, 1e-12 * norm(expected));
}

// 6. A rotation prescribed as an angle (`rotation`, LS-DYNA's *BOUNDARY_PRESCRIBED_MOTION_RIGID
//    DOF 7 VAD 2): a rigid box held in x, y, z, rx and ry and turned about z by 1.3 rad
//    along a curve that ramps over the run. Every step turns the body by the curve's change
//    exactly (the held spin's Cayley parameter is tan(dtheta / 2)), so at the end a corner
//    sits at the rigid rotation of its start by 1.3 rad about the centre. Tolerance 1e-12 of
//    the corner's distance from the centre.
TEST(RigidBody, RotationPrescribedAsAnAngle) {
  const Comm world = Comm::world();
  const Config config = test::deck("termination: {time: 2.0e-5}\n" + std::string(box_and_far) +
                                   R"(boundary_conditions:
  - {part: body, fix: [x, y, z, rx, ry]}
  - {part: body, rotation: [0, 0, 1.3], curve: [[0, 0], [5.0e-6, 0.1], [2.0e-5, 1]]}
probes:
  - {name: corner, at: [0.03, 0.01, 0.005]}
)");
  Simulation sim(config, world);
  while (!sim.finished()) sim.step();
  const Vec3 c{0.015, 0.005, 0.0025}, r0 = Vec3{0.03, 0.01, 0.005} - c;
  const double a = 1.3;
  const Vec3 expected{c.x + std::cos(a) * r0.x - std::sin(a) * r0.y,
                      c.y + std::sin(a) * r0.x + std::cos(a) * r0.y, c.z + r0.z};
  // The corner node's position at the end (the node nearest the corner's start).
  const auto& nd = sim.nodes();
  Vec3 at{0, 0, 0};
  for (std::size_t n = 0; n < nd.size(); ++n)
    if (sim.fe().node_owned[n] && nd.x0[0][n] == 0.03 && nd.x0[1][n] == 0.01 &&
        nd.x0[2][n] == 0.005)
      at = Vec3{nd.x[0][n], nd.x[1][n], nd.x[2][n]};
  for (int i = 0; i < 3; ++i) at[i] = world.sum(at[i]);
  const double off = norm(at - expected);
  if (world.rank() == 0)
    std::printf("rotation prescribed as an angle: corner off by %.2e of its radius after %lld "
                "steps\n",
                off / norm(r0), static_cast<long long>(sim.clock().cycle));
  EXPECT_LT(off, 1e-12 * norm(r0));
}

// 4. The driven plate: the keyword deck of a column of N cubes of side h on a rigid plate.
std::string driven_column_deck(int N, double h, double V, double end) {
  std::string k = fmt::format(R"(*KEYWORD
*CONTROL_TERMINATION
{:>10.4E}
*PART
column
         1         1         1
plate
         2         1         2
*SECTION_SOLID
         1         1
*MAT_ELASTIC
1,7850.0,2.0E+11,0.3
*MAT_RIGID
2,7850.0,2.0E+11,0.3
1.0,4.0,7.0

*DEFINE_CURVE
         9
                 0.0                 1.0
                 1.0                 1.0
*BOUNDARY_PRESCRIBED_MOTION_RIGID
2,3,0,9,{}
*NODE
)",
                              end, V);
  // Layer k of the column at z = k h (ids 4k + 1..4k + 4); the plate's lower face at -h.
  const double xy[4][2] = {{0, 0}, {h, 0}, {h, h}, {0, h}};
  for (int layer = -1; layer <= N; ++layer)
    for (int a = 0; a < 4; ++a)
      k += fmt::format("{},{},{},{}\n", layer < 0 ? 1001 + a : 4 * layer + a + 1, xy[a][0],
                       xy[a][1], layer * h);
  k += "*ELEMENT_SOLID\n";
  for (int e = 0; e < N; ++e)
    k += fmt::format("{},1,{},{},{},{},{},{},{},{}\n", e + 1, 4 * e + 1, 4 * e + 2, 4 * e + 3,
                     4 * e + 4, 4 * e + 5, 4 * e + 6, 4 * e + 7, 4 * e + 8);
  k += fmt::format("{},2,1001,1002,1003,1004,1,2,3,4\n", N + 1);
  // The column's nodes above the base held laterally (uniaxial strain).
  k += "*SET_NODE_LIST_GENERATE\n1\n";
  k += fmt::format("5,{}\n", 4 * N + 4);
  k += "*BOUNDARY_SPC_SET\n1,0,1,1,0\n*END\n";
  return k;
}

TEST(RigidBody, DrivenPlateSendsTheOneDimensionalWave) {
  const Comm world = Comm::world();
  const int N = 100;
  const double h = 0.0005, V = 2.0, length = N * h;
  const double c = c_wave, t_end = 1.6 * length / c;
  Config config = parse_keyword_deck(driven_column_deck(N, h, V, t_end), "column.k", ".");
  ASSERT_EQ(config.boundary_conditions.size(), 3u); // the plate's hold, its drive, the sides
  Simulation sim(config, world);
  double force = 0, count = 0;
  bool exact = true;
  while (!sim.finished()) {
    sim.step();
    const Sample s = sim.sample();
    const RigidMotion& m = sim.rigid_motions().at(0);
    exact = exact && m.velocity == Vec3{0, 0, V} && m.omega == Vec3{0, 0, 0};
    if (s.time > 0.3 * length / c && s.time < 0.9 * length / c) {
      force += s.reaction.at(3 * 1 + 2); // bc1: the drive, z
      count += 1;
    }
  }
  force /= count;
  // Mean axial stress of the lower quarter (behind the front).
  double sum = 0, n = 0;
  for (const auto& blk : sim.blocks()) {
    if (blk.rigid) continue;
    for (int e = 0; e < blk.size(); ++e) {
      double z = 0;
      for (int q = 0; q < 8; ++q) z += sim.nodes().x[2][blk.conn[q][e]] / 8;
      if (z < 0.25 * length) {
        sum += blk.stress[2][e];
        n += 1;
      }
    }
  }
  const double stress = world.sum(sum) / world.sum(n);
  const double f_ref = rho * c * V * h * h, s_ref = -rho * c * V;
  if (world.rank() == 0)
    std::printf("driven rigid plate: driver force %.5e N (1-D theory %.5e, rel %.2e), stress "
                "%.5e Pa (theory %.5e, rel %.2e)\n",
                force, f_ref, test::relative_error(force, f_ref), stress, s_ref,
                test::relative_error(stress, s_ref));
  EXPECT_TRUE(exact) << "the plate's held velocity and spin";
  // history.csv's rigid.plate.*: the held components exactly, the centre at V t.
  const Sample last = sim.sample();
  ASSERT_EQ(last.rigid_bodies.size(), 9u);
  EXPECT_EQ(last.rigid_bodies[0], 0.0);
  EXPECT_EQ(last.rigid_bodies[1], 0.0);
  EXPECT_EQ(last.rigid_bodies[5], V);
  for (int k = 6; k < 9; ++k) EXPECT_EQ(last.rigid_bodies[static_cast<std::size_t>(k)], 0.0);
  const double t_sample = sim.clock().time - sim.clock().dt;
  EXPECT_NEAR(last.rigid_bodies[2], V * t_sample, 1e-12 * V * t_sample);
  EXPECT_LT(test::relative_error(force, f_ref), 0.01);
  EXPECT_LT(test::relative_error(stress, s_ref), 0.01);
}

struct WallDrop {
  std::vector<double> rows; // per step: the wall's force, then the body's motion
  double behind = 0, px_worst = 0, impulse = 0, vz0 = 0, vz1 = 0, balance = 0;
};

WallDrop drop_on_wall(const Comm& comm) {
  Simulation sim(test::deck(R"(
termination: {time: 4.0e-4}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  cube:
    mesh: {generate: box, min: [0, 0, 0.0005], max: [0.01, 0.01, 0.0105], divisions: [2, 2, 2]}
    material: steel
    rigid: true
  other:
    mesh: {generate: box, min: [0.05, 0, 0.01], max: [0.06, 0.01, 0.02], divisions: [1, 1, 1]}
    material: steel
initial_conditions:
  - {part: cube, velocity: [3.0, 0, -10.0], angular_velocity: [0, 1000.0, 0], center: mass_center}
rigid_walls:
  - {point: [0, 0, 0], normal: [0, 0, 1]}
)"),
                 comm);
  WallDrop r;
  const double M = 7850 * 1e-6;
  bool first = true;
  while (!sim.finished()) {
    sim.step();
    const Sample s = sim.sample();
    const auto& nd = sim.nodes();
    double lowest = 1;
    for (std::size_t n = 0; n < nd.size(); ++n)
      if (nd.x0[0][n] < 0.02) lowest = std::min(lowest, nd.x[2][n]);
    r.behind = std::max(r.behind, -comm.min(lowest));
    // The body's velocity over the step (rigid_bodies: ux, uy, uz, vx, vy, vz, wx, wy, wz).
    const double vx = s.rigid_bodies[3], vz = s.rigid_bodies[5];
    r.px_worst = std::max(r.px_worst, std::abs(vx - 3.0) / 3.0);
    if (first) r.vz0 = vz;
    first = false;
    r.vz1 = vz;
    // (The force is the step's impulses over the interval dt_avg around t(n): the steps
    // are all equal here, the cube of `other` setting them, so dt_avg is dt.)
    r.impulse += s.wall_force[0] * s.dt;
    r.rows.push_back(s.wall_force[0]);
    r.rows.insert(r.rows.end(), s.rigid_bodies.begin(), s.rigid_bodies.end());
    r.balance = sim.balance_error(s);
  }
  r.impulse /= M; // as a change of velocity
  return r;
}

TEST(RigidBody, FreeBodyLandsOnAWall) {
  const Comm world = Comm::world();
  const WallDrop r = drop_on_wall(world);
  if (world.rank() == 0)
    std::printf("rigid cube on a wall: deepest node behind it %.1e m, x momentum %.1e, "
                "impulse / M %.6f m/s against the change of vz %.6f m/s, balance %.1e\n",
                r.behind, r.px_worst, r.impulse, r.vz1 - r.vz0, r.balance);
  EXPECT_LT(r.behind, 1e-12);
  EXPECT_LT(r.px_worst, 1e-12);
  EXPECT_GT(r.vz1, 0.0); // it left the wall
  EXPECT_NEAR(r.impulse, r.vz1 - r.vz0, 1e-9 * std::abs(r.vz0));
  EXPECT_LT(r.balance, 1e-12);
  if (world.rank() != 0) return;
  const WallDrop one = drop_on_wall(Comm::self());
  ASSERT_EQ(one.rows.size(), r.rows.size());
  EXPECT_EQ(differing_bits(one.rows, r.rows), 0u)
      << "wall forces and body motions differing from the one-rank run";
}

TEST(RigidBody, MergedPartsMoveAsOneBody) {
  const Comm world = Comm::world();
  const std::string deck = R"(
termination: {cycles: 300}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  head:
    mesh: {generate: box, min: [0, 0, 0], max: [0.01, 0.01, 0.01], divisions: [2, 2, 2]}
    material: steel
    rigid: true
  tail:
    mesh: {generate: box, min: [0.02, 0, 0], max: [0.04, 0.005, 0.005], divisions: [2, 1, 1]}
    material: steel
    rigid: true
    merge_with: head
  other:
    mesh: {generate: box, min: [1, 1, 1], max: [1.01, 1.01, 1.01], divisions: [1, 1, 1]}
    material: steel
initial_conditions:
  - {part: head, velocity: [2.0, -1.0, 0.5], angular_velocity: [100.0, -50.0, 200.0],
     center: mass_center}
probes:
  - {name: h, at: [0, 0, 0]}
  - {name: t, at: [0.04, 0.005, 0.005]}
)";
  const double M = 7850 * (1e-6 + 0.02 * 0.005 * 0.005);
  const Vec3 a0{0, 0, 0}, b0{0.04, 0.005, 0.005};
  {
    Simulation sim(test::deck(deck), world);
    double worst = 0;
    std::size_t columns = 0;
    while (!sim.finished()) {
      sim.step();
      const Sample s = sim.sample();
      columns = s.rigid_bodies.size();
      const Vec3 a = a0 + Vec3{s.probes[0], s.probes[1], s.probes[2]};
      const Vec3 b = b0 + Vec3{s.probes[6], s.probes[7], s.probes[8]};
      worst = std::max(worst, std::abs(norm(b - a) / norm(b0 - a0) - 1));
    }
    const RigidMotion& m = sim.rigid_motions().at(0);
    if (world.rank() == 0)
      std::printf("merged rigid body: mass %.6e kg (%.6e), velocity (%.12f, %.12f, %.12f), "
                  "distance between the parts' nodes %.1e\n",
                  m.mass, M, m.velocity.x, m.velocity.y, m.velocity.z, worst);
    EXPECT_EQ(sim.rigid_motions().size(), 1u);
    EXPECT_EQ(columns, 9u);
    EXPECT_NEAR(m.mass, M, 1e-12 * M);
    EXPECT_LT(norm(m.velocity - Vec3{2.0, -1.0, 0.5}), 1e-12 * 2.0);
    EXPECT_LT(worst, 1e-12);
  }
  // A condition on the merged part holds the body.
  Simulation held(test::deck(deck + "boundary_conditions:\n  - {part: tail, fix: [z]}\n"), world);
  for (int n = 0; n < 20; ++n) held.step();
  EXPECT_EQ(held.rigid_motions().at(0).velocity.z, 0.0);
  EXPECT_NE(held.rigid_motions().at(0).velocity.x, 0.0);
}

TEST(RigidBody, ASlenderBarTumblesFree) {
  const Comm world = Comm::world();
  Simulation sim(test::deck(R"(
termination: {time: 2.0e-3}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  bar:
    mesh: {generate: box, min: [-0.1, -0.005, 0.055], max: [0.1, 0.005, 0.065], divisions: [20, 1, 1]}
    material: steel
    rigid: true
  dummy:
    mesh: {generate: box, min: [1, 1, 1], max: [1.005, 1.005, 1.005], divisions: [1, 1, 1]}
    material: steel
initial_conditions:
  - {part: bar, velocity: [0, 0, 0], angular_velocity: [-1130.0, 183.0, 786.0], center: mass_center}
boundary_conditions:
  - {part: dummy, fix: all}
)"),
                 world);
  sim.step();
  const Vec3 L0 = body_moments(sim, world).L;
  while (!sim.finished()) sim.step(); // (threw "spins too fast" at 0.29 ms)
  const Vec3 L1 = body_moments(sim, world).L;
  if (world.rank() == 0)
    std::printf("slender bar tumbling: t = %.3g s, angular momentum change %.1e\n",
                sim.clock().time, norm(L1 - L0) / norm(L0));
  EXPECT_GE(sim.clock().time, 2.0e-3 * (1 - 1e-12));
  EXPECT_LT(norm(L1 - L0), 1e-9 * norm(L0));
}

} // namespace
