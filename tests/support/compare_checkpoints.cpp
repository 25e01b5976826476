// compare_checkpoints A B: exit 0 when two checkpoints hold the same state bit for bit
// (time, cycle, every node's position, velocity and contact history, every element's
// state); diagnostics that are sums over ranks may differ in the last bits and are not
// compared. Prints the first difference otherwise (exit 1).
#include <cstdio>
#include <cstring>

#include "anvil/core/error.hpp"
#include "anvil/io/checkpoint.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: compare_checkpoints A B\n");
    return 2;
  }
  try {
    const anvil::Checkpoint a = anvil::read_checkpoint(argv[1]),
                            b = anvil::read_checkpoint(argv[2]);
    auto same = [](const auto& x, const auto& y) {
      return x.size() == y.size() &&
             (x.empty() || std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0);
    };
    const bool ok = a.cycle == b.cycle && std::memcmp(&a.time, &b.time, sizeof a.time) == 0 &&
                    same(a.node_gid, b.node_gid) && same(a.node_data, b.node_data) &&
                    same(a.node_face, b.node_face) && same(a.element_gid, b.element_gid) &&
                    same(a.element_data, b.element_data);
    std::printf("%s: cycle %lld vs %lld, t %.17g vs %.17g, %zu nodes, %zu elements\n",
                ok ? "identical" : "DIFFERENT", static_cast<long long>(a.cycle),
                static_cast<long long>(b.cycle), a.time, b.time, a.node_gid.size(),
                a.element_gid.size());
    return ok ? 0 : 1;
  } catch (const anvil::InputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
}
