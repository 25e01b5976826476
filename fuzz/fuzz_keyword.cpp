// libFuzzer target: the LS-DYNA keyword reader (parse_keyword_deck, parse_keyword_mesh)
// on arbitrary text, then the model's mesh and node selections built from an accepted
// deck. Every input must be accepted or end in InputError; anything else is a finding.
// *INCLUDE resolves against a directory that does not exist.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "anvil/core/error.hpp"
#include "anvil/io/keyword.hpp"
#include "anvil/solver/model.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const char* dir = "/nonexistent-anvil-fuzz";
  try {
    const anvil::Mesh m = anvil::parse_keyword_mesh(text, "fuzz.k", dir);
    for (const auto& b : m.blocks)
      for (const auto& h : b.elements)
        for (auto n : h)
          if (n < 0 || n >= m.num_nodes()) std::abort();
  } catch (const anvil::InputError&) {
  }
  try {
    const anvil::Config c = anvil::parse_keyword_deck(text, "fuzz.k", dir);
    const anvil::Mesh m = anvil::build_mesh(c);
    for (const auto& bc : c.boundary_conditions) anvil::resolve_selection(m, c, bc.nodes);
    for (const auto& ic : c.initial_conditions) anvil::resolve_selection(m, c, ic.nodes);
  } catch (const anvil::InputError&) {
  }
  return 0;
}
