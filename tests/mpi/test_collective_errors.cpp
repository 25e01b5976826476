// Bad input found by one rank only (an inverted element in an imported mesh lives on the
// rank that owns it; a checkpoint that lacks what one rank holds) must stop every rank
// with the same InputError, not leave the others waiting in a collective. Regression
// tests for hangs found with an imported mesh and with restarts.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "anvil/core/error.hpp"
#include "anvil/io/checkpoint.hpp"
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
    // The file's element tag, not the element's position in the part.
    EXPECT_NE(std::string(e.what()).find("element 12 of part box"), std::string::npos) << e.what();
  }
}

// A deck of a bar and a thick-shell plate whose points through the thickness are `points`;
// `bar_divisions` the bar's mesh (the same counts in another layout make another mesh).
Config restart_deck(int points, const std::string& bar_divisions = "[4, 4, 16]") {
  return test::deck(R"(
termination: {cycles: 10}
materials:
  steel: {model: j2_plasticity, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3,
          yield_stress: 250.0e6, hardening_modulus: 1.0e9}
parts:
  bar:
    mesh: {generate: box, min: [0, 0, 0], max: [0.01, 0.01, 0.04], divisions: )" +
                    bar_divisions + R"(}
    material: steel
  plate:
    mesh: {generate: box, min: [0.02, 0, 0], max: [0.03, 0.01, 0.001], divisions: [2, 2, 1]}
    material: steel
    thick_shell: {points: )" +
                    std::to_string(points) +
                    R"(}
initial_conditions:
  - {part: bar, velocity: [0, 0, -50.0]}
)");
}

// The checkpoint of restart_deck(3) after two cycles, as every rank reads it from a file.
Checkpoint two_cycles(const Comm& world) {
  const auto path = std::filesystem::temp_directory_path() / "anvil_collective_errors" /
                    ("restart_np" + std::to_string(world.size()) + ".anvil");
  Simulation sim(restart_deck(3), world);
  sim.step();
  sim.step();
  const Checkpoint c = capture(sim, OutputState{});
  if (world.rank() == 0) {
    std::filesystem::create_directories(path.parent_path());
    write_checkpoint(path.string(), c);
  }
  world.barrier();
  return read_checkpoint(path.string());
}

// Restores `c` into a model of `deck` and expects the same InputError on every rank.
void expect_refused(const Comm& world, const Config& deck, const Checkpoint& c,
                    const std::string& fragment) {
  Simulation sim(deck, world);
  std::string message;
  try {
    sim.restore(c);
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_NE(message.find(fragment), std::string::npos)
      << "rank " << world.rank() << ": '" << message << "'";
  // Every rank threw the same error (and none is left in a collective: this returns).
  const auto lengths = world.allgather(static_cast<std::int64_t>(message.size()));
  for (const auto n : lengths) EXPECT_EQ(n, static_cast<std::int64_t>(message.size()));
}

TEST(CollectiveErrors, CheckpointLackingThickShellPointsStopsAllRanks) {
  const Comm world = Comm::world();
  const Checkpoint c = two_cycles(world);
  // The plate's elements follow the bar's 256: element 257 is the plate's first.
  expect_refused(world, restart_deck(5), c,
                 "thick_shell {points: 3} for element 257 (part plate, element 1 of the part), "
                 "the deck gives thick_shell {points: 5}");
}

TEST(CollectiveErrors, CheckpointLackingANodeStopsAllRanks) {
  const Comm world = Comm::world();
  Checkpoint c = two_cycles(world);
  // Without its last node (held by one rank only).
  const std::int64_t last = c.node_gid.back();
  c.node_gid.pop_back();
  c.node_data.resize(c.node_data.size() - Checkpoint::node_values);
  c.node_face.pop_back();
  expect_refused(world, restart_deck(3), c, "lacks node " + std::to_string(last + 1));
}

TEST(CollectiveErrors, CheckpointOfAnotherMeshIsRefused) {
  const Comm world = Comm::world();
  const Checkpoint c = two_cycles(world);
  // The same numbers of nodes and elements, another mesh.
  expect_refused(world, restart_deck(3, "[16, 4, 4]"), c, "was written for another mesh");
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
