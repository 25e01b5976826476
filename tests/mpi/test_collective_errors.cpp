// Bad input found by one rank only (an inverted element in an imported mesh lives on the
// rank that owns it) must stop every rank with the same InputError, not leave the others
// waiting in a collective. Regression test for a hang found with an imported mesh.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "anvil/core/error.hpp"
#include "anvil/io/decompose.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

TEST(CollectiveErrors, InvertedElementOnOneRankStopsAllRanks) {
  const Comm world = Comm::world();
  const auto dir = std::filesystem::temp_directory_path() / "anvil_collective_errors";
  const auto mesh = dir / "inverted.msh";
  if (world.rank() == 0) {
    std::filesystem::create_directories(dir);
    std::stringstream in;
    in << std::ifstream(std::string(test::source_dir()) + "/tests/data/meshes/box_2x2x2.msh")
              .rdbuf();
    std::string text = in.str();
    // First hexahedron "12 1 13 25 16 5 17 26 20": swap its bottom and top faces.
    const std::string good = "12 1 13 25 16 5 17 26 20";
    const auto at = text.find(good);
    ASSERT_NE(at, std::string::npos);
    text.replace(at, good.size(), "12 5 17 26 20 1 13 25 16");
    std::ofstream(mesh) << text;
  }
  world.barrier();
  const Config c = test::deck(R"(
termination: {cycles: 1}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  box:
    mesh: {file: )" + mesh.string() +
                              R"(}
    material: steel
)");
  try {
    Simulation sim(c, world);
    FAIL() << "no error for an inverted element";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("non-positive volume"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("element 1 of part box"), std::string::npos) << e.what();
  }
}

// QA D3: `anvil decompose -o DIR` where DIR cannot be created: rank 0 failed alone and
// the other ranks waited in a barrier for ever. Every rank now throws rank 0's error.
TEST(CollectiveErrors, DecomposeIntoAnImpossibleDirectoryStopsAllRanks) {
  const Config c = test::deck(R"(
termination: {cycles: 1}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  box:
    mesh: {generate: box, min: [0, 0, 0], max: [1, 1, 1], divisions: [2, 2, 4]}
    material: steel
)");
  try {
    write_decomposition(c, "/proc/anvil_no_such_directory", Comm::world());
    FAIL() << "no error for an output directory that cannot be created";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot create output directory"), std::string::npos)
        << e.what();
  }
}

} // namespace
