// External loads: the pressure kernel's corner forces against their definition, the deck's
// `loads` and its errors, and the LS-DYNA *LOAD_NODE / *LOAD_SEGMENT cards and theirs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "anvil/core/error.hpp"
#include "anvil/fe/pressure.hpp"
#include "anvil/io/keyword.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/solver/model.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

// f_a = -integral of N_a (x,xi x x,eta) over [-1, 1]^2 by the midpoint rule on an n x n
// grid (converges as 1/n^2): the reference the kernel's 2 x 2 Gauss rule must meet.
void midpoint_forces(const double (&x)[4][3], int n, double (&f)[4][3]) {
  static constexpr double xa[4] = {-1, 1, 1, -1}, ea[4] = {-1, -1, 1, 1};
  for (auto& fa : f) fa[0] = fa[1] = fa[2] = 0.0;
  const double h = 2.0 / n;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double xi = -1 + (i + 0.5) * h, eta = -1 + (j + 0.5) * h;
      double a[3] = {0, 0, 0}, b[3] = {0, 0, 0};
      for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 3; ++k) {
          a[k] += 0.25 * xa[c] * (1 + ea[c] * eta) * x[c][k];
          b[k] += 0.25 * ea[c] * (1 + xa[c] * xi) * x[c][k];
        }
      const double nrm[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                             a[0] * b[1] - a[1] * b[0]};
      for (int c = 0; c < 4; ++c) {
        const double N = 0.25 * (1 + xa[c] * xi) * (1 + ea[c] * eta);
        for (int k = 0; k < 3; ++k) f[c][k] -= N * nrm[k] * h * h;
      }
    }
}

// Reference: the definition (pressure.hpp), integrated finely; a flat square's corners
// each take a quarter of its area; any face's forces sum to minus its vector area
// (x2 - x0) x (x3 - x1) / 2. Tolerances: round-off (1e-15 of the area) for the exact
// cases, the midpoint rule's error (1e-5 at n = 400) for the integral.
TEST(Pressure, CornerForcesAreTheConsistentOnes) {
  const double square[4][3] = {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}};
  double f[4][3];
  unit_pressure_forces(square, f);
  for (const auto& fa : f) {
    EXPECT_NEAR(fa[0], 0.0, 1e-15);
    EXPECT_NEAR(fa[1], 0.0, 1e-15);
    EXPECT_NEAR(fa[2], -1.0, 1e-15); // area 4 / 4 corners, against the +z normal
  }
  // A warped, skewed face far from the origin.
  const double warped[4][3] = {
      {100.0, 50.0, 3.0}, {101.3, 50.2, 3.4}, {101.1, 51.5, 2.7}, {99.8, 51.1, 3.2}};
  unit_pressure_forces(warped, f);
  double d1[3], d2[3];
  for (int k = 0; k < 3; ++k) {
    d1[k] = warped[2][k] - warped[0][k];
    d2[k] = warped[3][k] - warped[1][k];
  }
  const double area[3] = {0.5 * (d1[1] * d2[2] - d1[2] * d2[1]),
                          0.5 * (d1[2] * d2[0] - d1[0] * d2[2]),
                          0.5 * (d1[0] * d2[1] - d1[1] * d2[0])};
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(f[0][k] + f[1][k] + f[2][k] + f[3][k], -area[k], 1e-13);
  double ref[4][3];
  midpoint_forces(warped, 400, ref);
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(f[c][k], ref[c][k], 1e-5) << c << " " << k;
  // The same face moved: the same forces to round-off of the moved coordinates.
  double moved[4][3], g[4][3];
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 3; ++k) moved[c][k] = warped[c][k] - 100.0;
  unit_pressure_forces(moved, g);
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(f[c][k], g[c][k], 1e-12);
}

const char* block = R"(
termination: {time: 1.0e-6}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  blk:
    mesh: {generate: box, min: [0, 0, 0], max: [0.01, 0.01, 0.01], divisions: [4, 4, 4]}
    material: steel
)";

// The error message of a deck that should not run, or "" if it builds.
std::string model_error(const std::string& text) {
  try {
    const Config c = test::deck(text, "deck.yaml");
    const Comm self = Comm::self();
    Simulation sim(c, self);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Deck, Loads) {
  const Config c = test::deck(std::string(block) + R"(loads:
  - {surface: blk.zmax, pressure: 1.0e6}
  - {set: blk.xmax, force: [0, 0, -5.0], curve: [[0, 0], [1.0e-6, 1]]}
)");
  ASSERT_EQ(c.loads.size(), 2u);
  EXPECT_EQ(c.loads[0].kind, Load::Kind::pressure);
  EXPECT_EQ(c.loads[0].pressure, 1.0e6);
  EXPECT_EQ(c.loads[0].target.name, "blk.zmax");
  EXPECT_FALSE(c.loads[0].curve);
  EXPECT_EQ(c.loads[1].kind, Load::Kind::force);
  EXPECT_EQ(c.loads[1].force, (Vec3{0, 0, -5.0}));
  EXPECT_EQ(c.loads[1].curve->at(0.5e-6), 0.5);
  // The faces: the 16 of the top, and of a box selection those whose four corners it holds
  // (a box over the top's edge holds a row of faces of the top and of the side under it,
  // and the corner face of each of the two sides at its ends).
  const Mesh mesh = build_mesh(c);
  EXPECT_EQ(resolve_surface(mesh, c, c.loads[0].target).size(), 16u);
  Selection edge;
  edge.box = Box3{{0, 0, 0.0074}, {0.01, 0.0026, 0.011}};
  EXPECT_EQ(resolve_surface(mesh, c, edge).size(), 4u + 4u + 2u); // top, y = 0, x = 0 and 0.01
  const Comm self = Comm::self();
  Simulation sim(c, self);
  EXPECT_EQ(sim.load_targets(), (std::vector<std::int64_t>{16, 25}));
  const auto area = sim.pressed_area(); // the top, 1 cm square; none for the force
  EXPECT_NEAR(area[0], 1e-4, 1e-18);
  EXPECT_EQ(area[1], 0.0);

  auto error = [&](const std::string& item) {
    return model_error(std::string(block) + "loads:\n  - " + item + "\n");
  };
  auto has = [](const std::string& msg, const std::string& part) {
    return msg.find(part) != std::string::npos;
  };
  EXPECT_TRUE(has(error("{surface: blk.zmax}"), "deck.yaml:10: loads[0]: give exactly one of"));
  EXPECT_TRUE(has(error("{surface: blk.zmax, pressure: 1, force: [0, 0, 1]}"), "exactly one"));
  EXPECT_TRUE(has(error("{set: blk.zmax, pressure: 1}"), "write surface, not set"));
  EXPECT_TRUE(has(error("{surface: blk.zmax, force: [0, 0, 1]}"), "write set, not surface"));
  EXPECT_TRUE(has(error("{pressure: 1}"), "loads[0].surface"));
  EXPECT_TRUE(has(error("{surface: blk.top, pressure: 1}"), "node set 'blk.top' does not exist"));
  EXPECT_TRUE(
      has(error("{surface: blk.zmax, pressure: 1, curve: [[1, 0], [0, 1]]}"), "loads[0].curve"));
  EXPECT_TRUE(has(error("{surface: blk.zmax, pressure: 1, ramp: 2}"), "unknown key 'ramp'"));
  EXPECT_TRUE(has(error("{surface: blk.zmax, pressure: 1, curve: [[-1.7e308, 0], [1.7e308, 1]]}"),
                  "span more than a number can hold"));
  EXPECT_TRUE(
      has(error("{surface: blk.zmax, pressure: 1e308, curve: [[0, 0], [1, 10]]}"), "overflows"));
  // Selections that hold no face of the surface: an inner box, and a single edge's nodes.
  EXPECT_TRUE(has(error("{surface: {box: {min: [0.004, 0.004, 0.004], max: [0.006, 0.006, "
                        "0.006]}}, pressure: 1}"),
                  "loads[0].surface: the selection holds no face of the model's surface"));
  EXPECT_TRUE(has(error("{surface: {box: {min: [0, 0, 0], max: [0.01, 0, 0]}}, pressure: 1}"),
                  "no four are the corners"));
  EXPECT_EQ(error("{surface: {part: blk}, pressure: 1}"), "");
  // A load born at or after the end never acts: warned of (QA round 26).
  const Config late = test::deck(std::string(block) +
                                 "loads:\n  - {surface: blk.zmax, pressure: 1.0e6, birth: 1.0}\n");
  Simulation unborn(late, self);
  ASSERT_FALSE(unborn.warnings().empty());
  EXPECT_TRUE(
      has(unborn.warnings().back(), "the load is born at t = 1 s, not before the end time"));
}

// A mesh file's side set is a surface (tests/data/meshes/box_2x2x2.exo: side set `top`, 4
// faces of 0.5 m^2, after a generated part, so its elements are renumbered); a mistyped
// name lists both kinds of sets, and a side set given to `set` says what it is (QA round
// 25: both said "node set ... not defined").
TEST(Deck, LoadsOnMeshFileSideSets) {
  const std::string deck = fmt::format(R"(
termination: {{cycles: 3}}
materials:
  steel: {{model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}}
parts:
  gen:
    mesh: {{generate: box, min: [5, 0, 0], max: [6, 1, 1], divisions: [1, 1, 1]}}
    material: steel
  m:
    mesh: {{file: {}/tests/data/meshes/box_2x2x2.exo}}
    material: steel
loads:
  - LOAD
)",
                                       test::source_dir());
  auto with = [&](const std::string& item) {
    std::string t = deck;
    t.replace(t.find("LOAD"), 4, item);
    return t;
  };
  const Config c = test::deck(with("{surface: m.top, pressure: 1.0e5}"));
  const Comm self = Comm::self();
  Simulation sim(c, self);
  EXPECT_EQ(sim.load_targets(), (std::vector<std::int64_t>{4}));
  EXPECT_NEAR(sim.pressed_area()[0], 2.0, 1e-12);
  EXPECT_NE(model_error(with("{surface: m.topp, pressure: 1}"))
                .find("'m.topp' is neither a side set nor a node set (the part has "),
            std::string::npos);
  EXPECT_NE(model_error(with("{set: m.top, force: [0, 0, 1]}"))
                .find("'m.top' is a side set (faces), not a node set"),
            std::string::npos);
}

// Forces act on mesh nodes only; a pressure on faces of the mesh only.
TEST(Deck, LoadsOnParticlesAreRefused) {
  const std::string text = std::string(block) + R"(particles:
  ball: {generate: {shape: sphere, center: [0.03, 0, 0], radius: 2.0e-3, spacing: 1.0e-3},
         material: steel}
loads:
  - LOAD
)";
  auto error = [&](const std::string& item) {
    std::string t = text;
    t.replace(t.find("LOAD"), 4, item);
    return model_error(t);
  };
  EXPECT_NE(error("{set: {part: ball}, force: [1, 0, 0]}")
                .find("the selection holds 32 particles: forces act on the nodes of the mesh"),
            std::string::npos);
  EXPECT_NE(error("{surface: {part: ball}, pressure: 1}")
                .find("'ball' is a particle set: a pressure acts on the faces of the mesh"),
            std::string::npos);
}

// The two bricks of test_keyword.cpp, with a curve for the loads.
const std::string bricks = R"(*KEYWORD
*CONTROL_TERMINATION
   1.0E-04
*PART
steel
         1         1         1
*SECTION_SOLID
         1         1
*MAT_ELASTIC
         1    7850.0   2.0E+11       0.3
)" + std::string(test::two_bricks_keyword_mesh) +
                           R"(*DEFINE_CURVE
         3
                 0.0                 0.0
                 1.0                 1.0
)";

Config keyword(const std::string& cards) {
  return parse_keyword_deck(bricks + cards + "*END\n", "model.k", ".");
}

std::string keyword_error(const std::string& cards) {
  try {
    keyword(cards);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// *LOAD_NODE_POINT cards group by (DOF, LCID, SF) into node sets; *LOAD_NODE_SET loads a
// *SET_NODE_LIST; *LOAD_SEGMENT and *SET_SEGMENT faces become side sets of the elements'
// faces, those listed the other way round apart, with -SF (LS-DYNA presses against the
// segment's right-hand normal, anvil against the face's outward one).
TEST(Keyword, NodeAndSegmentLoads) {
  const Config c = keyword(R"(*LOAD_NODE_POINT
         9         3         3     -10.0
        10         3         3     -10.0
        11         1         3       2.0
*LOAD_NODE_SET
         7         2         3       4.0
*SET_SEGMENT
         5
         9        10        11        12
         1         2         3         4
*LOAD_SEGMENT_SET
         5         3     1.0E6
*LOAD_SEGMENT
         3     2.0E6       0.0         1         2         6         5
)");
  ASSERT_EQ(c.loads.size(), 6u);
  EXPECT_EQ(c.loads[0].target.name, "load_nodes_1");
  EXPECT_EQ(c.loads[0].force, (Vec3{0, 0, -10.0}));
  EXPECT_EQ(c.loads[1].target.name, "load_nodes_2");
  EXPECT_EQ(c.loads[1].force, (Vec3{2.0, 0, 0}));
  EXPECT_EQ(c.loads[2].target.name, "nodeset_7");
  EXPECT_EQ(c.loads[2].force, (Vec3{0, 4.0, 0}));
  EXPECT_EQ(c.loads[2].curve->at(0.25), 0.25);
  // The top (9-10-11-12, counter-clockwise from above: outward) and the bottom listed
  // 1-2-3-4 (counter-clockwise from above, so clockwise from outside, below: reversed).
  EXPECT_EQ(c.loads[3].target.name, "segset_5");
  EXPECT_EQ(c.loads[3].pressure, 1.0e6);
  EXPECT_EQ(c.loads[4].target.name, "segset_5_reversed");
  EXPECT_EQ(c.loads[4].pressure, -1.0e6);
  EXPECT_EQ(c.loads[5].target.name, "load_segments_1"); // 1-2-6-5: the y = 0 side, outward
  EXPECT_EQ(c.loads[5].pressure, 2.0e6);
  const Mesh mesh = build_mesh(c);
  EXPECT_EQ(mesh.node_sets.at("load_nodes_1"), (std::vector<std::int64_t>{8, 9}));
  auto faces = [&](std::size_t l) {
    std::vector<std::pair<std::int64_t, int>> out;
    for (const auto& s : resolve_surface(mesh, c, c.loads[l].target))
      out.emplace_back(s.element, s.face);
    return out;
  };
  using F = std::vector<std::pair<std::int64_t, int>>;
  EXPECT_EQ(faces(3), (F{{1, 5}})); // element 2's top
  EXPECT_EQ(faces(4), (F{{0, 4}})); // element 1's bottom
  EXPECT_EQ(faces(5), (F{{0, 0}})); // element 1's y = 0 side
  const Comm self = Comm::self();
  Simulation sim(c, self); // the sets resolve
  EXPECT_EQ(sim.load_targets(), (std::vector<std::int64_t>{2, 1, 4, 1, 1, 1}));

  auto has = [](const std::string& msg, const std::string& part) {
    return msg.find(part) != std::string::npos;
  };
  const std::string seg = "*LOAD_SEGMENT\n         3     2.0E6       0.0";
  EXPECT_TRUE(has(keyword_error(seg + "         1         2         7         8\n"),
                  "model.k:35: *LOAD_SEGMENT.N1: segment (1, 2, 7, 8) is not a face"));
  // A triangle N1 N2 N3 N3 is a face of a wedge, pyramid or tetrahedron only.
  EXPECT_TRUE(has(keyword_error(seg + "         1         2         6         6\n"),
                  "*LOAD_SEGMENT.N1: segment (1, 2, 6, 6) is not a face"));
  EXPECT_TRUE(has(keyword_error(seg + "         1         6         1         6\n"),
                  "*LOAD_SEGMENT.N4: segment (1, 6, 1, 6) repeats a node other than as a "
                  "triangle"));
  EXPECT_TRUE(has(keyword_error(seg + "         1         6         2         5\n"),
                  "does not go round its face in order"));
  EXPECT_TRUE(has(keyword_error(seg + "         1         2         6        99\n"),
                  "*LOAD_SEGMENT.N4: the segment refers to node 99"));
  EXPECT_TRUE(has(keyword_error(seg + "         1         2         6         5        13\n"),
                  "*LOAD_SEGMENT.N5: higher-order segments"));
  EXPECT_TRUE(has(keyword_error("*LOAD_SEGMENT\n         3     2.0E6   -1.0E-5         1         "
                                "2         6         5\n"),
                  "*LOAD_SEGMENT.AT: AT = -1e-05 is negative"));
  // DT of *LOAD_SEGMENT_SET: the pressure's death; nothing after it.
  const std::string segset = "*SET_SEGMENT\n         5\n         9        10        11        12\n";
  EXPECT_EQ(
      keyword(segset + "*LOAD_SEGMENT_SET\n         5         3     1.0E6    1.0E-5    3.0E-5\n")
          .loads.at(0)
          .death,
      3.0e-5);
  EXPECT_TRUE(has(keyword_error(segset + "*LOAD_SEGMENT_SET\n         5         3     1.0E6    "
                                         "1.0E-5    3.0E-5       xyz\n"),
                  "*LOAD_SEGMENT_SET.field 6: a *LOAD_SEGMENT_SET card holds SSID, LCID, SF, AT"));
  EXPECT_TRUE(has(keyword_error(segset + "*LOAD_SEGMENT_SET\n         5         3     1.0E6    "
                                         "3.0E-5    1.0E-5\n"),
                  "*LOAD_SEGMENT_SET.DT: DT = 1e-05 is not after AT = 3e-05"));
  // AT: the pressure's birth.
  EXPECT_EQ(keyword("*LOAD_SEGMENT\n         3     2.0E6    1.0E-5         1         2         6 "
                    "        5\n")
                .loads.at(0)
                .birth,
            1.0e-5);
  EXPECT_TRUE(has(keyword_error("*LOAD_SEGMENT_SET\n         8         3\n"),
                  "*LOAD_SEGMENT_SET.SSID: segment set 8 is not defined (*SET_SEGMENT)"));
  EXPECT_TRUE(has(keyword_error("*LOAD_SEGMENT_SET\n         5         4\n*SET_SEGMENT\n         "
                                "5\n         9        10        11        12\n"),
                  "*LOAD_SEGMENT_SET.LCID: curve 4 is not defined"));
  EXPECT_TRUE(has(keyword_error("*SET_SEGMENT\n         5\n"), "segment set 5 has no segments"));
  EXPECT_TRUE(has(keyword_error("*LOAD_NODE_POINT\n         9         4         3\n"),
                  "*LOAD_NODE_POINT.DOF: DOF = 4 is not supported"));
  EXPECT_TRUE(has(keyword_error("*LOAD_NODE_POINT\n         9         3         3       1.0"
                                "         2\n"),
                  "*LOAD_NODE_POINT.CID"));
  EXPECT_TRUE(has(keyword_error("*LOAD_NODE_SET\n         8         3         3\n"),
                  "*LOAD_NODE_SET.NSID: node set 8 is not defined"));
  EXPECT_TRUE(has(keyword_error("*LOAD_NODE_POINT\n        99         3         3\n"),
                  "*LOAD_NODE_POINT.NID: the load refers to node 99"));
  EXPECT_TRUE(has(keyword_error("*LOAD_NODE_POINT\n         9         3\n"),
                  "*LOAD_NODE_POINT.LCID: LCID must be the id of a *DEFINE_CURVE"));
}

// QA round 25: loads add up, as LS-DYNA's do: a node's or a segment's repeated card (or a
// segment listed twice in a set) loads it again, not once (a set holds a node or a face
// once, so the repeats go into sets of their own).
TEST(Keyword, RepeatedLoadCardsAddUp) {
  const Config c = keyword(R"(*LOAD_NODE_POINT
         9         3         3     -10.0
         9         3         3     -10.0
        10         3         3     -10.0
*SET_SEGMENT
         5
         9        10        11        12
         9        10        11        12
*LOAD_SEGMENT_SET
         5         3     1.0E6
*LOAD_SEGMENT
         3     2.0E6       0.0         1         2         6         5
         3     2.0E6       0.0         1         2         6         5
)");
  std::vector<std::string> names;
  for (const auto& l : c.loads) names.push_back(l.target.name);
  EXPECT_EQ(names,
            (std::vector<std::string>{"load_nodes_1", "load_nodes_2", "segset_5", "segset_5_2",
                                      "load_segments_1", "load_segments_1_2"}));
  const Mesh mesh = build_mesh(c);
  EXPECT_EQ(mesh.node_sets.at("load_nodes_1"), (std::vector<std::int64_t>{8, 9}));
  EXPECT_EQ(mesh.node_sets.at("load_nodes_2"), (std::vector<std::int64_t>{8}));
  const Comm self = Comm::self();
  Simulation sim(c, self);
  EXPECT_EQ(sim.load_targets(), (std::vector<std::int64_t>{2, 1, 1, 1, 1, 1}));
}

} // namespace
