// The LS-DYNA keyword deck of the copper Taylor bar (tests/data/decks/taylor_bar.k) is
// the YAML example (examples/taylor_bar.yaml) written for LS-DYNA: the same mesh, material,
// velocity, constraint, hourglass control and termination.
//
// What may differ, and the tolerances:
// - The mesh file stores coordinates in LS-DYNA's 16-character fields, 10 significant
//   digits: every coordinate within 6e-12 m of the generated one (half a unit in the 10th
//   digit of a coordinate below 0.1 m); connectivity and numbering identical.
// - *MAT_PLASTIC_KINEMATIC gives the tangent modulus ETAN = 99914602.9 Pa (10 characters);
//   E ETAN / (E - ETAN) is the YAML deck's hardening modulus 0.1 GPa within 1e-10.
// - The rounded coordinates change element sizes (about 0.3 mm) by up to 1.7e-8 relative,
//   and with them the stable time step: after 300 cycles the node positions of the two
//   runs must agree within 2e-8 of the largest displacement, time and energies within 2e-8
//   relative. Measured on 2 ranks: 1.05e-9 of the displacement (2.7e-12 m of 2.57 mm),
//   time 1.04e-9, internal energy 9.8e-10 (2026-11-24).
// - With the keyword file's own mesh in the YAML deck (`mesh: {file: taylor_bar_mesh.k}`)
//   and the hardening modulus the keyword reader derives, the two runs are the same bits.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <span>

#include <fmt/format.h>

#include "anvil/io/deck.hpp"
#include "anvil/io/input.hpp"
#include "anvil/io/keyword.hpp"
#include "anvil/mesh/generators.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

std::string decks() {
  return std::string(test::source_dir()) + "/tests/data/decks/";
}

constexpr int cycles = 300;

void run_cycles(Simulation& sim) {
  for (int i = 0; i < cycles && !sim.finished(); ++i) sim.step();
}

TEST(KeywordTaylorBar, MeshFileIsTheGeneratedCylinder) {
  CylinderSpec spec;
  spec.radius = 3.2e-3;
  spec.length = 32.4e-3;
  spec.divisions = {8, 40};
  const Mesh gen = generate_cylinder(spec);
  const Mesh kw = read_keyword_mesh(decks() + "taylor_bar_mesh.k");
  ASSERT_EQ(kw.num_nodes(), gen.num_nodes());
  ASSERT_EQ(kw.blocks.size(), 1u);
  ASSERT_EQ(kw.blocks[0].elements, gen.blocks[0].elements);
  double worst = 0;
  for (std::int64_t n = 0; n < gen.num_nodes(); ++n)
    for (int i = 0; i < 3; ++i) worst = std::max(worst, std::abs(kw.nodes[n][i] - gen.nodes[n][i]));
  EXPECT_LT(worst, 6e-12);
  EXPECT_EQ(kw.node_sets.at("nodeset_1"), gen.node_sets.at("bottom"));
}

TEST(KeywordTaylorBar, ConfigMatchesTheYamlDeck) {
  const Config k = read_input(decks() + "taylor_bar.k");
  const Config y = read_input(std::string(test::source_dir()) + "/examples/taylor_bar.yaml");
  EXPECT_EQ(k.title, y.title);
  EXPECT_EQ(k.end_time, y.end_time);
  EXPECT_EQ(k.time_step_scale, y.time_step_scale);
  EXPECT_EQ(k.fields_every, y.fields_every);
  EXPECT_EQ(k.history_every, y.history_every);
  ASSERT_EQ(k.materials.size(), 1u);
  EXPECT_EQ(k.materials[0].model, y.materials[0].model);
  for (const auto& [name, v] : y.materials[0].params) {
    SCOPED_TRACE(name);
    EXPECT_LT(test::relative_error(k.materials[0].params.at(name), v), 1e-10);
  }
  ASSERT_EQ(k.parts.size(), 1u);
  EXPECT_EQ(k.parts[0].hourglass.model, y.parts[0].hourglass.model);
  EXPECT_EQ(k.parts[0].hourglass.coefficient, y.parts[0].hourglass.coefficient);
  EXPECT_EQ(k.parts[0].bulk_viscosity.linear, y.parts[0].bulk_viscosity.linear);
  EXPECT_EQ(k.parts[0].bulk_viscosity.quadratic, y.parts[0].bulk_viscosity.quadratic);
  ASSERT_EQ(k.initial_conditions.size(), 1u);
  EXPECT_EQ(k.initial_conditions[0].velocity, y.initial_conditions[0].velocity);
  ASSERT_EQ(k.boundary_conditions.size(), 1u);
  EXPECT_EQ(k.boundary_conditions[0].fix, y.boundary_conditions[0].fix);
  EXPECT_TRUE(k.warnings.empty()) << k.warnings.front();
}

// Positions after `cycles` cycles of both runs: max |x_k - x_y| and the largest
// displacement, over this rank's nodes (global ids must match).
struct Compare {
  double dx = 0, umax = 0;
  bool same_bits = true;
};
Compare compare(const Simulation& a, const Simulation& b) {
  Compare c;
  EXPECT_EQ(a.fe().node_gid, b.fe().node_gid);
  const auto& na = a.nodes();
  const auto& nb = b.nodes();
  for (std::size_t n = 0; n < na.size(); ++n)
    for (int i = 0; i < 3; ++i) {
      c.dx = std::max(c.dx, std::abs(na.x[i][n] - nb.x[i][n]));
      c.umax = std::max(c.umax, std::abs(nb.x[i][n] - nb.x0[i][n]));
      c.same_bits = c.same_bits && na.x[i][n] == nb.x[i][n] && na.v[i][n] == nb.v[i][n];
    }
  c.dx = a.comm().max(c.dx);
  c.umax = a.comm().max(c.umax);
  c.same_bits = a.comm().min(static_cast<std::int64_t>(c.same_bits)) == 1;
  return c;
}

TEST(KeywordTaylorBar, RunsLikeTheYamlDeck) {
  const Comm world = Comm::world();
  const Config k = read_input(decks() + "taylor_bar.k");
  const Config y = read_input(std::string(test::source_dir()) + "/examples/taylor_bar.yaml");
  Simulation sk(k, world), sy(y, world);
  run_cycles(sk);
  run_cycles(sy);
  ASSERT_EQ(sk.clock().cycle, sy.clock().cycle);
  const Compare c = compare(sk, sy);
  const Sample a = sk.sample(), b = sy.sample();
  if (world.rank() == 0)
    std::printf("keyword vs YAML after %d cycles: max position difference %.3e m = %.3e of the "
                "largest displacement %.4e m; time %.3e (rel %.2e), internal energy rel %.2e, "
                "kinetic rel %.2e\n",
                cycles, c.dx, c.dx / c.umax, c.umax, sk.clock().time,
                test::relative_error(sk.clock().time, sy.clock().time),
                test::relative_error(a.internal, b.internal),
                test::relative_error(a.kinetic, b.kinetic));
  EXPECT_LT(c.dx, 2e-8 * c.umax);
  EXPECT_LT(test::relative_error(sk.clock().time, sy.clock().time), 2e-8);
  EXPECT_LT(test::relative_error(a.internal, b.internal), 2e-8);
  EXPECT_LT(test::relative_error(a.kinetic, b.kinetic), 2e-8);
}

// The YAML deck of the keyword deck k with the keyword file's own mesh; `part_extra` is
// added to the part's keys.
Config same_mesh_yaml(const Config& k, const std::string& part_extra = "") {
  const std::string yaml =
      fmt::format(R"(title: Taylor bar, copper, 227 m/s
termination: {{time: 8.0e-5}}
time_step: {{scale: 0.9}}
materials:
  copper: {{model: j2_plasticity, density: 8930, youngs_modulus: 117.0e9,
           poissons_ratio: 0.35, yield_stress: 0.4e9, hardening_modulus: {:.17g}}}
parts:
  bar:
    mesh: {{file: {}taylor_bar_mesh.k}}
    material: copper
    hourglass: {{model: viscous, coefficient: 0.05}}{}
node_sets:
  impact_face: {{part: bar, box: {{min: [-1, -1, -1.0e-9], max: [1, 1, 1.0e-9]}}}}
initial_conditions:
  - {{part: bar, velocity: [0, 0, -227.0]}}
boundary_conditions:
  - {{set: impact_face, fix: [z]}}
)",
                  k.materials[0].params.at("hardening_modulus"), decks(), part_extra);
  return parse_deck(yaml, "same_mesh.yaml");
}

TEST(KeywordTaylorBar, SameMeshAndMaterialGiveTheSameBits) {
  const Comm world = Comm::world();
  const Config k = read_input(decks() + "taylor_bar.k");
  const Config y = same_mesh_yaml(k);
  Simulation sk(k, world), sy(y, world);
  run_cycles(sk);
  run_cycles(sy);
  ASSERT_EQ(sk.clock().cycle, sy.clock().cycle);
  const Compare c = compare(sk, sy);
  EXPECT_TRUE(c.same_bits) << "max position difference " << c.dx;
  EXPECT_EQ(sk.clock().time, sy.clock().time);
}

// FS of *MAT_PLASTIC_KINEMATIC (LS-DYNA: "effective plastic strain for eroding elements")
// is the YAML part key erosion.plastic_strain: with FS = 0.3 the keyword deck erodes the
// same elements as the YAML deck with `erosion: {plastic_strain: 0.3}`, to the bit. (The
// impact face passes 0.3 within the 300 cycles: elements must have eroded.)
TEST(KeywordTaylorBar, FailureStrainErodesLikeTheYamlKey) {
  const Comm world = Comm::world();
  std::ifstream in(decks() + "taylor_bar.k");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string fs_card = "       0.0       0.0       0.0       0.0\n";
  const auto at = text.find(fs_card);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, fs_card.size(), "       0.0       0.0       0.3       0.0\n");
  const Config k = parse_keyword_deck(text, decks() + "taylor_bar_fs.k", decks());
  ASSERT_EQ(k.parts.at(0).erosion.plastic_strain, 0.3);
  const Config y = same_mesh_yaml(k, "\n    erosion: {plastic_strain: 0.3}");
  Simulation sk(k, world), sy(y, world);
  run_cycles(sk);
  run_cycles(sy);
  ASSERT_EQ(sk.clock().cycle, sy.clock().cycle);
  std::array<std::int64_t, 2> eroded{sk.eroded_local(), sy.eroded_local()};
  world.sum(std::span<std::int64_t>(eroded));
  const auto [eroded_k, eroded_y] = eroded;
  if (world.rank() == 0)
    std::printf("FS = 0.3: %lld elements eroded in %d cycles (YAML deck: %lld)\n",
                static_cast<long long>(eroded_k), cycles, static_cast<long long>(eroded_y));
  EXPECT_GT(eroded_k, 0);
  EXPECT_EQ(eroded_k, eroded_y);
  const Compare c = compare(sk, sy);
  EXPECT_TRUE(c.same_bits) << "max position difference " << c.dx;
}

} // namespace
