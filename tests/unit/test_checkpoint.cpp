// The checkpoint file format (io/checkpoint.hpp): a file keeps every section bit for bit,
// particles, eroded elements, thick-shell points, the mesh fingerprint and both .pvd lists
// included; a file that is damaged (checksum), truncated, extended, inconsistent, of an
// older format or of an unknown one is an InputError naming it. The restart itself is
// tested end to end by tests/regression (test_restart.sh, test_restart_sph.sh) and its
// refusals on every rank by tests/mpi/test_collective_errors.cpp.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "anvil/core/error.hpp"
#include "anvil/io/checkpoint.hpp"
#include "anvil/io/files.hpp"

namespace {

using anvil::Checkpoint;

std::string temp_path(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / "anvil_checkpoint_test";
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

Checkpoint sample() {
  Checkpoint c;
  c.deck = "deck.yaml";
  c.time = 1.0 / 3.0;
  c.cycle = 42;
  c.dt = 1e-7 / 3.0;
  c.dt_prev = 2e-7 / 3.0;
  c.dt_initial = 1e-7;
  c.outputs.next_fields = 0.5;
  c.outputs.next_history = 0.4;
  c.outputs.next_checkpoint = 0.6;
  c.outputs.field_count = 2;
  c.outputs.pvd = {{0.0, "fields/step_000000.pvtu"}, {0.25, "fields/step_000001.pvtu"}};
  c.outputs.particle_pvd = {{0.0, "fields/particles_step_000000.pvtu"},
                            {0.25, "fields/particles_step_000001.pvtu"}};
  c.model_nodes = 2;
  c.node_gid = {0, 1};
  for (int k = 0; k < 2 * Checkpoint::node_values; ++k) c.node_data.push_back(0.1 * k + 1e-17);
  c.node_face = {-1, 3};
  c.model_elements = 1;
  c.element_gid = {0};
  for (int k = 0; k < Checkpoint::element_values; ++k) c.element_data.push_back(k / 7.0);
  c.element_eroded = {1};
  c.model_particles = 3;
  c.particle_gid = {0, 1, 2};
  for (int k = 0; k < 3 * Checkpoint::particle_values; ++k)
    c.particle_data.push_back(k / 11.0 - 1.0);
  c.particle_face = {-1, 5, -1};
  c.point_gid = {0};
  for (int k = 0; k < Checkpoint::point_values; ++k) c.point_data.push_back(k / 13.0 + 0.5);
  c.point_count = {3};
  c.mesh_fingerprint = 0xfedcba9876543210ULL;
  return c;
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// The bytes of `c` as written.
std::string written(const Checkpoint& c, const std::string& name) {
  const std::string path = temp_path(name);
  anvil::write_checkpoint(path, c);
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Expects reading `bytes` (as file `name`, unique to its test: ctest runs tests in
// parallel) to throw an InputError naming the file and
// saying `fragment`.
void expect_refused(const std::string& bytes, const std::string& name,
                    const std::string& fragment) {
  const std::string path = temp_path(name);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  try {
    anvil::read_checkpoint(path);
    ADD_FAILURE() << name << ": accepted";
  } catch (const anvil::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(Checkpoint, RoundTripKeepsParticlesAndBothSeries) {
  const Checkpoint c = sample();
  const std::string path = temp_path("round_trip.anvil");
  anvil::write_checkpoint(path, c);
  const Checkpoint r = anvil::read_checkpoint(path);
  EXPECT_EQ(r.file, path);
  EXPECT_EQ(r.cycle, c.cycle);
  EXPECT_EQ(std::memcmp(&r.time, &c.time, sizeof c.time), 0);
  EXPECT_TRUE(same_bits(r.node_data, c.node_data));
  EXPECT_TRUE(same_bits(r.element_data, c.element_data));
  EXPECT_EQ(r.element_eroded, c.element_eroded);
  EXPECT_EQ(r.model_particles, 3);
  EXPECT_TRUE(same_bits(r.particle_gid, c.particle_gid));
  EXPECT_TRUE(same_bits(r.particle_data, c.particle_data));
  EXPECT_TRUE(same_bits(r.particle_face, c.particle_face));
  EXPECT_TRUE(same_bits(r.point_gid, c.point_gid));
  EXPECT_TRUE(same_bits(r.point_data, c.point_data));
  EXPECT_EQ(r.point_count, c.point_count);
  EXPECT_EQ(r.outputs.pvd, c.outputs.pvd);
  EXPECT_EQ(r.outputs.particle_pvd, c.outputs.particle_pvd);
  EXPECT_EQ(r.mesh_fingerprint, c.mesh_fingerprint);
}

TEST(Checkpoint, InconsistentParticleCountNamesTheFile) {
  Checkpoint c = sample();
  c.model_particles = 4; // the header says 4, the sections hold 3
  const std::string path = temp_path("inconsistent.anvil");
  anvil::write_checkpoint(path, c);
  try {
    anvil::read_checkpoint(path);
    FAIL() << "an inconsistent checkpoint was accepted";
  } catch (const anvil::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

// A write that fails leaves no temporary behind (and the previous file as it was): here
// the rename fails, the target being a directory.
TEST(Checkpoint, FailedAtomicWriteLeavesNoTemporary) {
  const auto dir = std::filesystem::temp_directory_path() / "anvil_atomic_write_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "target");
  const std::string target = (dir / "target").string();
  EXPECT_THROW(anvil::write_file_atomic(target, "content"), anvil::InputError);
  EXPECT_FALSE(std::filesystem::exists(target + ".tmp"));
  EXPECT_TRUE(std::filesystem::is_directory(target));
  std::filesystem::remove_all(dir);
}

TEST(Checkpoint, UnknownVersionIsRefused) {
  std::string s = written(sample(), "version9.anvil");
  s[7] = '9';
  expect_refused(s, "version9.anvil", "version 9");
}

// Files of formats 1 to 4 had no checksum: refused, with what to do.
TEST(Checkpoint, OlderFormatIsRefused) {
  for (const char v : {'1', '4'}) {
    std::string s = written(sample(), "older.anvil");
    s[7] = v;
    expect_refused(s, "older.anvil", "written by an older anvil");
  }
}

// One flipped bit anywhere past the magic (a velocity, a count, the header) is refused.
TEST(Checkpoint, FlippedBitIsRefused) {
  const std::string good = written(sample(), "flip_source.anvil");
  for (std::size_t at = 8; at < good.size(); at += 7) {
    SCOPED_TRACE(at);
    std::string s = good;
    s[at] = static_cast<char>(s[at] ^ 0x10);
    expect_refused(s, "flipped.anvil", "checkpoint");
  }
  std::string s = good;
  s[s.size() - 100] = static_cast<char>(s[s.size() - 100] ^ 0x01); // in the thick-shell data
  expect_refused(s, "flipped.anvil", "is corrupt: its checksum does not match");
}

TEST(Checkpoint, TruncatedOrExtendedFileIsRefused) {
  const std::string good = written(sample(), "cut_source.anvil");
  expect_refused(good.substr(0, good.size() - 1), "short.anvil", "is truncated");
  expect_refused(good.substr(0, 12), "short.anvil", "is truncated");
  expect_refused("", "empty.anvil", "not an anvil checkpoint");
  expect_refused(good + "garbage", "long.anvil", "is corrupt: 7 bytes follow its end");
}

// Sections that pass the checksum but cannot come from a run (a writer's bug) are refused
// too: ids out of order, a non-finite value.
TEST(Checkpoint, ImpossibleContentIsRefused) {
  Checkpoint c = sample();
  c.node_gid = {1, 0};
  expect_refused(written(c, "order.anvil"), "order.anvil", "node ids are not ascending");
  c = sample();
  c.node_data[Checkpoint::node_values + 1] = std::numeric_limits<double>::quiet_NaN();
  expect_refused(written(c, "nan.anvil"), "nan.anvil", "non-finite value for node 2");
  c = sample();
  c.point_count = {6};
  expect_refused(written(c, "points.anvil"), "points.anvil", "is inconsistent");
}

} // namespace
