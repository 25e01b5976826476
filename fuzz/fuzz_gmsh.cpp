// libFuzzer target: the Gmsh MSH reader (parse_gmsh) on arbitrary text. Every input must
// parse or end in InputError; anything else (another exception, a crash, a leak, UB) is a
// finding. A parsed mesh must refer only to nodes it has.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "anvil/core/error.hpp"
#include "anvil/mesh/read_gmsh.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const anvil::Mesh m =
        anvil::parse_gmsh(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.msh");
    for (const auto& b : m.blocks)
      for (const auto& h : b.elements)
        for (auto n : h)
          if (n < 0 || n >= m.num_nodes()) std::abort();
    for (const auto& [name, ids] : m.node_sets)
      for (auto n : ids)
        if (n < 0 || n >= m.num_nodes()) std::abort();
  } catch (const anvil::InputError&) {
  }
  return 0;
}
