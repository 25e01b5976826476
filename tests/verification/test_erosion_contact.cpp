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
