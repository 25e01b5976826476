// Exodus II output read back: the file of a 1-rank run is a mesh that anvil's own Exodus
// reader reads (the model's mesh at its reference position), with one time step per field
// output whose variables the Exodus C API returns; `output.format` is a checked deck key.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <exodusII.h>
#include <fmt/format.h>

#include "anvil/core/error.hpp"
#include "anvil/io/exodus.hpp"
#include "anvil/mesh/read_exodus.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;
namespace fs = std::filesystem;

const char* deck = R"(title: exodus unit
termination: {cycles: 40}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  block:
    mesh: {generate: box, min: [0, 0, 0], max: [0.01, 0.02, 0.03], divisions: [2, 3, 4]}
    material: steel
  lid:
    mesh: {generate: box, min: [0, 0, 0.031], max: [0.01, 0.02, 0.035], divisions: [2, 3, 1]}
    material: steel
initial_conditions:
  - {part: lid, velocity: [0, 0, -50.0]}
output: {fields_every: 1.0e-6, format: exodus}
)";

TEST(ExodusOutput, FileNames) {
  EXPECT_EQ(exodus_path("out", 1, 0), "out/results.exo");
  EXPECT_EQ(exodus_path("out", 4, 3), "out/results.exo.4.3");
  EXPECT_EQ(exodus_path("out", 12, 3), "out/results.exo.12.03");
  EXPECT_EQ(exodus_path("out", 100, 7), "out/results.exo.100.007");
}

TEST(ExodusOutput, ReadsBackAsMeshAndVariables) {
  const auto dir = fs::temp_directory_path() / fmt::format("anvil_exodus_unit_{}", ::getpid());
  fs::create_directories(dir);
  std::ofstream(dir / "deck.yaml") << deck;
  const std::string cmd = fmt::format("'{}' run '{}' -q -o '{}' 2>&1", test::anvil_binary(),
                                      (dir / "deck.yaml").string(), (dir / "out").string());
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  EXPECT_FALSE(fs::exists(dir / "out" / "results.pvd")); // exodus only
  const std::string file = (dir / "out" / "results.exo").string();

  // The mesh, through anvil's reader: both parts' blocks at their reference position.
  const Mesh m = read_exodus(file);
  ASSERT_EQ(m.blocks.size(), 2u);
  EXPECT_EQ(m.blocks[0].name, "block");
  EXPECT_EQ(m.blocks[1].name, "lid");
  EXPECT_EQ(m.blocks[0].elements.size(), 24u);
  EXPECT_EQ(m.blocks[1].elements.size(), 6u);
  double volume = 0;
  for (const auto& b : m.blocks)
    for (const auto& h : b.elements) {
      std::array<Vec3, 8> x;
      for (int a = 0; a < 8; ++a) x[a] = m.nodes[h[a]];
      volume += hex_volume(x);
    }
  EXPECT_NEAR(volume, 0.01 * 0.02 * 0.03 + 0.01 * 0.02 * 0.004, 1e-15);

  // The variables, through the Exodus C API.
  int cpu = sizeof(double), io = 0;
  float version = 0;
  const int id = ex_open(file.c_str(), EX_READ, &cpu, &io, &version);
  ASSERT_GE(id, 0);
  const int steps = static_cast<int>(ex_inquire_int(id, EX_INQ_TIME));
  EXPECT_GE(steps, 3);
  double t_last = 0;
  ex_get_time(id, steps, &t_last);
  int nvar = 0;
  ex_get_variable_param(id, EX_NODAL, &nvar);
  ASSERT_EQ(nvar, 6);
  char name[MAX_STR_LENGTH + 1] = {};
  ex_get_variable_name(id, EX_NODAL, 3, name);
  EXPECT_STREQ(name, "displacement_z");
  const auto nn = static_cast<std::size_t>(m.num_nodes());
  std::vector<double> uz(nn), vz(nn);
  ASSERT_GE(ex_get_var(id, steps, EX_NODAL, 3, 1, static_cast<int>(nn), uz.data()), 0);
  ASSERT_GE(ex_get_var(id, steps, EX_NODAL, 6, 1, static_cast<int>(nn), vz.data()), 0);
  // The lid moved down; the block's base did not move in z more than the lid did.
  double lid_uz = 0;
  for (std::size_t n = 0; n < nn; ++n) {
    EXPECT_TRUE(std::isfinite(uz[n]) && std::isfinite(vz[n]));
    if (m.nodes[n].z > 0.0345) lid_uz = uz[n];
  }
  EXPECT_NEAR(lid_uz, -50.0 * t_last, 1e-3 * 50.0 * t_last);
  ex_get_variable_param(id, EX_ELEM_BLOCK, &nvar);
  EXPECT_EQ(nvar, 10); // stress (6), von_mises, pressure, plastic_strain, fe_rank
  ex_close(id);
  fs::remove_all(dir);
}

TEST(ExodusOutput, FormatIsACheckedDeckKey) {
  const std::string base = "termination: {cycles: 1}\nmaterials:\n  s: {model: elastic, density: "
                           "1, youngs_modulus: 1, poissons_ratio: 0}\nparts:\n  p:\n    mesh: "
                           "{generate: box, min: [0,0,0], max: [1,1,1], divisions: [1,1,1]}\n    "
                           "material: s\n";
  EXPECT_EQ(test::deck(base).output_format, OutputFormat::vtu);
  EXPECT_EQ(test::deck(base + "output: {format: both}\n").output_format, OutputFormat::both);
  EXPECT_EQ(test::deck(base + "output: {format: exodus}\n").output_format, OutputFormat::exodus);
  try {
    test::deck(base + "output: {format: d3plot}\n");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("test.yaml:8: output.format"), std::string::npos)
        << e.what();
  }
}

} // namespace
