// Eroding contact (LS-DYNA's *CONTACT_ERODING_*; Belytschko and Lin 1987, "A
// three-dimensional impact-penetration algorithm with erosion"): when an element erodes,
// the faces it covered join the contact surface, so a penetrator meets the material
// behind the eroded layer instead of passing through it. A tungsten-carbide block
// (2 x 2 x 4 mm, elastic) strikes a steel target (8 x 8 x 4 mm, J2, erosion at 8%
// plastic strain, base clamped) at 400 m/s: examples/eroding_penetration.yaml.
// Reference: the contact condition itself, as for the can crush (DESIGN.md section 5): no
// projectile node penetrates a live target element deeper than a tenth of the element
// size (0.1 mm), behind all six of the element's face planes, every cycle; and the
// projectile's tip never reaches the clamped base (z = -4 mm). Before the exposed faces
// joined contact the projectile passed through the two lower layers and the base (tip at
// -4.21 mm). The penalty scale is 1: with 0.1 (PRONTO's default) a corner node of the
// projectile, paired with an exposed face, sank 0.129 mm into it under the penalty's
// softness at this speed (measured; 0.037 mm with 1).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "anvil/core/vec3.hpp"
#include "anvil/io/deck.hpp"
#include "anvil/mesh/mesh.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

TEST(ErosionContact, ExposedFacesStopThePenetrator) {
  const Comm world = Comm::world();
  ASSERT_EQ(world.size(), 1) << "the check reads every element and node on one rank";
  Simulation sim(read_deck(std::string(test::source_dir()) + "/examples/eroding_penetration.yaml"),
                 world);
  const auto& blocks = sim.blocks();
  ASSERT_EQ(blocks.size(), 2u);
  const HexBlock& target = blocks[0];
  std::set<int> proj_nodes;
  for (int e = 0; e < blocks[1].size(); ++e)
    for (int a = 0; a < 8; ++a) proj_nodes.insert(blocks[1].conn[a][static_cast<std::size_t>(e)]);
  const auto& x = sim.nodes().x;
  double deepest = 0, lowest_tip = 0;
  std::string where;
  while (!sim.finished()) {
    sim.step();
    for (int n : proj_nodes) lowest_tip = std::min(lowest_tip, x[2][static_cast<std::size_t>(n)]);
    for (int e = 0; e < target.size(); ++e) {
      const auto k = static_cast<std::size_t>(e);
      if (target.alive[k] == 0.0) continue;
      // The element's six faces as planes (centre, outward normal from the diagonals):
      // a node behind all six is inside, as deep as the least of its distances.
      Vec3 c[6], nrm[6];
      for (int s = 0; s < 6; ++s) {
        Vec3 p[4];
        for (int a = 0; a < 4; ++a) {
          const auto l = static_cast<std::size_t>(target.conn[hex_faces[s][a]][k]);
          p[a] = {x[0][l], x[1][l], x[2][l]};
        }
        c[s] = 0.25 * (p[0] + p[1] + p[2] + p[3]);
        const Vec3 n = cross(p[2] - p[0], p[3] - p[1]);
        nrm[s] = n * (1 / norm(n));
      }
      for (int n : proj_nodes) {
        const auto l = static_cast<std::size_t>(n);
        const Vec3 q{x[0][l], x[1][l], x[2][l]};
        double depth = 1e300;
        for (int s = 0; s < 6; ++s) depth = std::min(depth, -dot(q - c[s], nrm[s]));
        if (depth > deepest) {
          deepest = depth;
          where = fmt::format("element {} at t = {:.3e} s", target.gid[k] + 1, sim.clock().time);
        }
      }
    }
  }
  std::int64_t eroded = 0;
  for (int e = 0; e < target.size(); ++e) eroded += target.alive[static_cast<std::size_t>(e)] == 0;
  std::printf("eroding contact: %lld elements eroded, deepest projectile node %.4f mm inside a "
              "live element (%s), lowest tip %.3f mm\n",
              static_cast<long long>(eroded), deepest * 1e3, where.c_str(), lowest_tip * 1e3);
  EXPECT_GT(eroded, 16); // more than the first layer's elements under the projectile
  EXPECT_LT(deepest, 1e-4);
  EXPECT_GT(lowest_tip, -0.004);
}

// An eroded element is deleted: its material state stays as it was when it eroded,
// whatever its nodes do after. A copper block strikes a thick-shell Johnson-Cook plate
// (3 points through the wall) that erodes at 5% plastic strain; the block erodes on
// inversion and has stiffness hourglass control. Reference: deletion (LS-DYNA's eroded
// elements are no longer integrated); tolerance: the same bits for every eroded element's
// plastic strain and temperature (element and points) and hourglass forces from its
// erosion to the end, all finite. Before, the kernel kept integrating them: plastic strain
// 4e15, temperature -1.7e6 K, then non-finite values that made every later checkpoint
// unreadable (QA round 12).
TEST(ErosionContact, ErodedElementsKeepTheirState) {
  const std::string deck = R"(
termination: {time: 1.5e-5}
materials:
  steel: {model: johnson_cook, density: 7800, youngs_modulus: 200.0e9, poissons_ratio: 0.3,
          A: 3.0e8, B: 5.0e8, n: 0.3, C: 0.02, m: 1.0, melt_temperature: 1800, specific_heat: 450}
  copper: {model: j2_plasticity, density: 8930, youngs_modulus: 117.0e9, poissons_ratio: 0.35,
           yield_stress: 0.2e9, hardening_modulus: 0.1e9}
parts:
  plate:
    mesh: {generate: box, min: [-0.004, -0.004, -0.001], max: [0.004, 0.004, 0.0], divisions: [16, 16, 1]}
    material: steel
    thick_shell: {points: 3}
    erosion: {plastic_strain: 0.05, inverted: true}
  proj:
    mesh: {generate: box, min: [-0.0012, -0.0012, 0.0001], max: [0.0012, 0.0012, 0.0025], divisions: [6, 6, 6]}
    material: copper
    hourglass: {model: stiffness, coefficient: 0.05}
    erosion: {plastic_strain: 0.5, inverted: true}
initial_conditions:
  - {part: proj, velocity: [0, 0, -350.0]}
boundary_conditions:
  - {set: plate.xmin, fix: all}
  - {set: plate.xmax, fix: all}
contact:
  - {type: general, parts: all, penalty_scale: 0.5}
)";
  const Comm world = Comm::world();
  Simulation sim(test::deck(deck), world);
  // Each block's state of an element, as one list of values.
  auto state = [](const HexBlock& b, std::size_t e) {
    std::vector<double> v;
    if (!b.plastic_strain.empty()) v.push_back(b.plastic_strain[e]);
    if (!b.temperature.empty()) v.push_back(b.temperature[e]);
    for (const auto& p : b.point_plastic_strain) v.push_back(p[e]);
    for (const auto& p : b.point_temperature) v.push_back(p[e]);
    for (const auto& h : b.hourglass_force)
      if (!h.empty()) v.push_back(h[e]);
    return v;
  };
  std::vector<std::vector<std::vector<double>>> frozen(sim.blocks().size());
  std::int64_t eroded = 0, changed = 0, nonfinite = 0;
  while (!sim.finished()) {
    sim.step();
    for (std::size_t k = 0; k < sim.blocks().size(); ++k) {
      const HexBlock& b = sim.blocks()[k];
      frozen[k].resize(static_cast<std::size_t>(b.size()));
      for (std::size_t e = 0; e < frozen[k].size(); ++e) {
        if (b.alive[e] != 0.0) continue;
        const std::vector<double> now = state(b, e);
        for (double x : now) nonfinite += !std::isfinite(x);
        if (frozen[k][e].empty()) {
          frozen[k][e] = now;
          ++eroded;
        } else if (std::memcmp(now.data(), frozen[k][e].data(), now.size() * sizeof(double)) != 0) {
          ++changed;
        }
      }
    }
  }
  eroded = world.sum(eroded);
  changed = world.sum(changed);
  nonfinite = world.sum(nonfinite);
  if (world.rank() == 0)
    std::printf("eroded elements' state: %lld eroded, %lld element-cycles changed after "
                "erosion, %lld non-finite values\n",
                static_cast<long long>(eroded), static_cast<long long>(changed),
                static_cast<long long>(nonfinite));
  EXPECT_GT(eroded, 4);
  EXPECT_EQ(changed, 0);
  EXPECT_EQ(nonfinite, 0);
}

// An `erosion` key that never erodes changes nothing: the faces between the part's
// elements stay dormant and the nodes inside it are searched for no pair until an
// element of theirs erodes. Reference: the same deck without the key; tolerance: the same
// bits (positions and velocities of every node after 141 cycles). Before the nodes inside
// were dormant, one of them paired with the projectile's face at cycle 86 (QA, 0.5 mm
// elements, 400 m/s).
TEST(ErosionContact, ErosionThatNeverHappensChangesNothing) {
  const std::string deck = R"(
termination: {time: 4.0e-6}
materials:
  tgt: {model: j2_plasticity, density: 7800, youngs_modulus: 200.0e9, poissons_ratio: 0.3,
        yield_stress: 3.0e8, hardening_modulus: 1.0e9}
  wc: {model: elastic, density: 15000, youngs_modulus: 600.0e9, poissons_ratio: 0.22}
parts:
  target:
    mesh: {generate: box, min: [-0.004, -0.004, -0.004], max: [0.004, 0.004, 0.0], divisions: [16, 16, 8]}
    material: tgt
  proj:
    mesh: {generate: box, min: [-0.001, -0.001, 0.0001], max: [0.001, 0.001, 0.0041], divisions: [4, 4, 8]}
    material: wc
initial_conditions:
  - {part: proj, velocity: [0, 0, -400.0]}
boundary_conditions:
  - {set: target.zmin, fix: all}
contact:
  - {type: general, parts: all, penalty_scale: 0.1}
)";
  std::string eroding = deck;
  const std::string at = "    material: tgt\n";
  eroding.insert(eroding.find(at) + at.size(), "    erosion: {plastic_strain: 100.0}\n");
  const Comm world = Comm::world();
  auto final_state = [&](const std::string& text) {
    Simulation sim(test::deck(text), world);
    while (!sim.finished()) sim.step();
    std::vector<double> state;
    for (int i = 0; i < 3; ++i) {
      state.insert(state.end(), sim.nodes().x[i].begin(), sim.nodes().x[i].end());
      state.insert(state.end(), sim.nodes().v[i].begin(), sim.nodes().v[i].end());
    }
    return state;
  };
  const std::vector<double> a = final_state(deck), b = final_state(eroding);
  ASSERT_EQ(a.size(), b.size());
  std::size_t differing = 0;
  for (std::size_t k = 0; k < a.size(); ++k)
    differing += std::memcmp(&a[k], &b[k], sizeof(double)) != 0;
  EXPECT_EQ(differing, 0u);
}

} // namespace
