// compare_checkpoints A B: exit 0 when two checkpoints hold the same state bit for bit
// (time, cycle, every node's position, velocity and contact history, every element's
// state and its thick-shell points', every particle's state and contact history); diagnostics that
// are sums over ranks may differ in the last bits and are not compared. Otherwise prints the first
// difference of each section that differs (exit 1).
#include <cstdio>
#include <cstring>

#include "anvil/core/error.hpp"
#include "anvil/io/checkpoint.hpp"

namespace {

// True when x and y hold the same bits; otherwise prints the first differing entry
// (as record and value within a record of `width` entries).
template <class T>
bool same(const char* what, const std::vector<T>& x, const std::vector<T>& y, int width) {
  if (x.size() != y.size()) {
    std::printf("%s: %zu vs %zu entries\n", what, x.size(), y.size());
    return false;
  }
  for (std::size_t i = 0; i < x.size(); ++i)
    if (std::memcmp(&x[i], &y[i], sizeof(T)) != 0) {
      std::printf("%s: record %zu, value %zu: %.17g vs %.17g\n", what, i / width, i % width,
                  static_cast<double>(x[i]), static_cast<double>(y[i]));
      return false;
    }
  return true;
}

} // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: compare_checkpoints A B\n");
    return 2;
  }
  try {
    using anvil::Checkpoint;
    const Checkpoint a = anvil::read_checkpoint(argv[1]), b = anvil::read_checkpoint(argv[2]);
    bool ok = a.cycle == b.cycle && std::memcmp(&a.time, &b.time, sizeof a.time) == 0;
    // Every section is compared (no short cut), so that all differences are reported.
    ok &= same("node ids", a.node_gid, b.node_gid, 1);
    ok &= same("nodes", a.node_data, b.node_data, Checkpoint::node_values);
    ok &= same("node contact faces", a.node_face, b.node_face, 1);
    ok &= same("element ids", a.element_gid, b.element_gid, 1);
    ok &= same("elements", a.element_data, b.element_data, Checkpoint::element_values);
    ok &= same("eroded elements", a.element_eroded, b.element_eroded, 1);
    ok &= same("particle ids", a.particle_gid, b.particle_gid, 1);
    ok &= same("particles", a.particle_data, b.particle_data, Checkpoint::particle_values);
    ok &= same("particle contact faces", a.particle_face, b.particle_face, 1);
    ok &= same("thick-shell element ids", a.point_gid, b.point_gid, 1);
    ok &= same("thick-shell points", a.point_data, b.point_data, Checkpoint::point_values);
    ok &= same("thick-shell point counts", a.point_count, b.point_count, 1);
    std::printf(
        "%s: cycle %lld vs %lld, t %.17g vs %.17g, %zu nodes, %zu elements, %zu particles\n",
        ok ? "identical" : "DIFFERENT", static_cast<long long>(a.cycle),
        static_cast<long long>(b.cycle), a.time, b.time, a.node_gid.size(), a.element_gid.size(),
        a.particle_gid.size());
    return ok ? 0 : 1;
  } catch (const anvil::InputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
}
