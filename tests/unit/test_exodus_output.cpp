// Exodus II output read back: the file of a 1-rank run is a mesh that anvil's own Exodus
// reader reads (the model's mesh at its reference position), with one time step per field
// output whose variables the Exodus C API returns; `output.format` is a checked deck key.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <exodusII.h>
#include <fmt/format.h>
#include <netcdf.h>

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
  int format = 0;
  ASSERT_EQ(nc_inq_format(id, &format), NC_NOERR);
  EXPECT_EQ(format, NC_FORMAT_64BIT_OFFSET); // ids that fit 32 bits: classic, kill-safe
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

// Names longer than the file holds are cut on a character boundary and kept distinct.
TEST(ExodusOutput, LongNamesAreCutDistinct) {
  const std::string p(85, 'p');
  const auto names = exodus_names({p + "_one", p + "_two", "short", p + "_three"}, 80);
  ASSERT_EQ(names.size(), 4u);
  EXPECT_EQ(names[0], std::string(80, 'p'));
  EXPECT_EQ(names[1], std::string(78, 'p') + "~2");
  EXPECT_EQ(names[2], "short");
  EXPECT_EQ(names[3], std::string(78, 'p') + "~3");
  // A name that fits is never changed, even when a cut one would take it.
  const auto kept = exodus_names({p, std::string(80, 'p')}, 80);
  EXPECT_EQ(kept[1], std::string(80, 'p'));
  EXPECT_EQ(kept[0], std::string(78, 'p') + "~2");
  // "ü" is two bytes: a cut never splits it.
  const std::string u = std::string(79, 'a') + "\xC3\xBC" + "b";
  EXPECT_EQ(exodus_names({u}, 80)[0], std::string(79, 'a'));
  EXPECT_EQ(exodus_names({u}, 81)[0], std::string(79, 'a') + "\xC3\xBC");
}

// Mesh file ids above 2^31 - 1 (Gmsh tags here; LS-DYNA LONG ids and int64 Exodus maps
// alike) are written as 64-bit id maps, so the model runs with Exodus output and the file
// carries the ids (QA round 13). The model mixes the file with a generated part, whose
// nodes take their position in the model and whose elements their position in the part
// (docs/deck.md, output). The title and the part names, too long for the file, are cut on
// character boundaries, distinct, without the Exodus library's own warning.
TEST(ExodusOutput, LargeIdsAreWrittenAs64BitMaps) {
  const auto dir = fs::temp_directory_path() / fmt::format("anvil_exodus_big_{}", ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::int64_t t = std::int64_t{1} << 40, e = (std::int64_t{1} << 41) + 5;
  // One unit-cube hexahedron; node tags 2^40 + 1, 2^40 + 3, ... (sparse).
  const double xyz[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                            {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  std::string msh = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 1\n"
                    "1 0 0 0 1 1 1 0 0\n$EndEntities\n$Nodes\n";
  msh += fmt::format("1 8 {} {}\n3 1 0 8\n", t + 1, t + 15);
  for (int n = 0; n < 8; ++n) msh += fmt::format("{}\n", t + 1 + 2 * n);
  for (const auto& x : xyz) msh += fmt::format("{} {} {}\n", x[0], x[1], x[2]);
  msh += fmt::format("$EndNodes\n$Elements\n1 1 {0} {0}\n3 1 5 1\n{0}", e);
  for (int n = 0; n < 8; ++n) msh += fmt::format(" {}", t + 1 + 2 * n);
  msh += "\n$EndElements\n";
  std::ofstream(dir / "big.msh") << msh;
  const std::string p(85, 'p');
  const std::string title = std::string(79, 'T') + "\xC3\xBC" + "xxxx";
  std::ofstream(dir / "deck.yaml") << fmt::format(R"(title: {0}
termination: {{cycles: 3}}
materials:
  steel: {{model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}}
parts:
  {1}_one:
    mesh: {{file: big.msh}}
    material: steel
  {1}_two:
    mesh: {{generate: box, min: [0, 0, 1.5], max: [1, 1, 2.5], divisions: [1, 1, 2]}}
    material: steel
output: {{fields_every: 1.0e-6, format: exodus}}
)",
                                                  title, p);
  const std::string cmd = fmt::format("'{}' run '{}' -q -o '{}' 2>&1", test::anvil_binary(),
                                      (dir / "deck.yaml").string(), (dir / "out").string());
  FILE* pipe = ::popen(cmd.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buf[4096];
  while (std::size_t n = std::fread(buf, 1, sizeof buf, pipe)) output.append(buf, n);
  ASSERT_EQ(::pclose(pipe), 0) << output;
  EXPECT_EQ(output, ""); // no warning of the Exodus library's about long names

  const std::string file = (dir / "out" / "results.exo").string();
  int cpu = sizeof(double), io = 0;
  float version = 0;
  const int id = ex_open(file.c_str(), EX_READ | EX_ALL_INT64_API, &cpu, &io, &version);
  ASSERT_GE(id, 0);
  EXPECT_NE(ex_int64_status(id) & EX_MAPS_INT64_DB, 0);
  ex_init_params init{};
  ASSERT_EQ(ex_get_init_ext(id, &init), 0);
  EXPECT_EQ(std::string(init.title), std::string(79, 'T')); // not half of the "ü"
  ASSERT_EQ(init.num_nodes, 8 + 12);
  ASSERT_EQ(init.num_elem, 1 + 2);
  std::vector<std::int64_t> nodes(20), elements(3);
  ASSERT_EQ(ex_get_id_map(id, EX_NODE_MAP, nodes.data()), 0);
  ASSERT_EQ(ex_get_id_map(id, EX_ELEM_MAP, elements.data()), 0);
  std::sort(nodes.begin(), nodes.end());
  std::vector<std::int64_t> want;
  for (int n = 9; n <= 20; ++n) want.push_back(n); // the box: 9..20, after the file's 8
  for (int n = 0; n < 8; ++n) want.push_back(t + 1 + 2 * n);
  EXPECT_EQ(nodes, want);
  EXPECT_EQ(elements, (std::vector<std::int64_t>{e, 1, 2})); // the box: 1, 2 in the part
  ASSERT_EQ(ex_set_max_name_length(id, 80), 0);
  char n1[81] = {}, n2[81] = {};
  char* names[2] = {n1, n2};
  ASSERT_EQ(ex_get_names(id, EX_ELEM_BLOCK, names), 0);
  EXPECT_EQ(std::string(n1), std::string(80, 'p'));
  EXPECT_EQ(std::string(n2), std::string(78, 'p') + "~2");
  ex_close(id);
  // anvil reads the file back (a netCDF-4 file, read in a child process).
  const Mesh m = read_exodus(file);
  EXPECT_EQ(m.num_elements(), 3);
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
