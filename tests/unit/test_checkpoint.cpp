// The checkpoint file format (io/checkpoint.hpp): a version 4 file keeps every section
// bit for bit, particles, eroded elements, thick-shell points and both .pvd lists
// included; a version 1 file
// (written before particles and erosion were checkpointed) still reads, as a model without
// particles whose elements are all alive; a file whose
// sections disagree is an InputError naming it. The restart itself is tested end to end
// by tests/regression (test_restart.sh, test_restart_sph.sh).
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "anvil/core/error.hpp"
#include "anvil/io/checkpoint.hpp"

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
  return c;
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// A version 1 file, as the previous reader expected it: magic ANVILCK1, the header without
// the particle keys, no particle sections.
std::string version1(const Checkpoint& c) {
  nlohmann::json h;
  h["deck"] = c.deck;
  h["cycle"] = c.cycle;
  h["model_nodes"] = c.model_nodes;
  h["model_elements"] = c.model_elements;
  h["field_count"] = c.outputs.field_count;
  h["pvd"] = c.outputs.pvd;
  std::string s = "ANVILCK1";
  auto put = [&s](const auto& v) {
    const std::uint64_t n = v.size();
    s.append(reinterpret_cast<const char*>(&n), sizeof n);
    if (n) s.append(reinterpret_cast<const char*>(v.data()), n * sizeof(v[0]));
  };
  const std::string header = h.dump();
  put(std::vector<char>(header.begin(), header.end()));
  put(std::vector<double>{c.time, c.dt, c.dt_prev, c.dt_initial, 0, 0, c.outputs.next_fields,
                          c.outputs.next_history});
  put(std::vector<double>{c.outputs.next_checkpoint});
  put(c.node_gid);
  put(c.node_data);
  put(c.node_face);
  put(c.element_gid);
  put(c.element_data);
  return s;
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
}

TEST(Checkpoint, VersionOneReadsWithoutParticles) {
  Checkpoint c = sample();
  const std::string path = temp_path("version1.anvil");
  std::ofstream(path, std::ios::binary) << version1(c);
  const Checkpoint r = anvil::read_checkpoint(path);
  EXPECT_EQ(r.cycle, c.cycle);
  EXPECT_EQ(std::memcmp(&r.dt_prev, &c.dt_prev, sizeof c.dt_prev), 0);
  EXPECT_TRUE(same_bits(r.node_data, c.node_data));
  EXPECT_TRUE(same_bits(r.element_data, c.element_data));
  EXPECT_EQ(r.element_eroded, std::vector<std::int64_t>{0});
  EXPECT_EQ(r.outputs.pvd, c.outputs.pvd);
  EXPECT_EQ(r.model_particles, 0);
  EXPECT_TRUE(r.particle_gid.empty());
  EXPECT_TRUE(r.outputs.particle_pvd.empty());
  EXPECT_TRUE(r.point_gid.empty());
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

TEST(Checkpoint, UnknownVersionIsRefused) {
  const std::string path = temp_path("version9.anvil");
  std::string s = version1(sample());
  s[7] = '9';
  std::ofstream(path, std::ios::binary) << s;
  try {
    anvil::read_checkpoint(path);
    FAIL() << "a checkpoint of an unknown version was accepted";
  } catch (const anvil::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("version 9"), std::string::npos) << e.what();
  }
}

} // namespace
