// libFuzzer target: the YAML deck reader (parse_deck) on arbitrary text, then, for decks
// whose generated meshes are small, the model's mesh (generators) and every node
// selection. Every input must be accepted or end in InputError; anything else is a
// finding. Mesh files are resolved against a directory that does not exist.
#include <cstddef>
#include <cstdint>
#include <string>

#include "anvil/core/error.hpp"
#include "anvil/io/deck.hpp"
#include "anvil/solver/model.hpp"

namespace {

// Elements of the generated parts, as in the deck reader's own limit check; a file mesh
// counts as too large (nothing is read from disk).
double elements(const anvil::Config& c) {
  double total = 0;
  for (const auto& p : c.parts) {
    const auto& m = p.mesh;
    switch (m.kind) {
    case anvil::MeshConfig::Kind::box:
      total += 1.0 * m.box.divisions[0] * m.box.divisions[1] * m.box.divisions[2];
      break;
    case anvil::MeshConfig::Kind::cylinder: {
      const double h = m.cylinder.divisions[0] / 2 > 1 ? m.cylinder.divisions[0] / 2 : 1;
      total += (4 * h * h + 8 * h * (m.cylinder.divisions[0] - h)) * m.cylinder.divisions[1];
      break;
    }
    case anvil::MeshConfig::Kind::can:
      total += 1.0 * m.can.divisions[0] * m.can.divisions[1] * m.can.divisions[2];
      break;
    default:
      return 1e300;
    }
  }
  return total;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const anvil::Config c =
        anvil::parse_deck(std::string(reinterpret_cast<const char*>(data), size), "fuzz.yaml",
                          "/nonexistent-anvil-fuzz");
    if (elements(c) > 20000) return 0;
    const anvil::Mesh m = anvil::build_mesh(c);
    for (const auto& [name, sel] : c.node_sets) anvil::resolve_selection(m, c, sel);
    for (const auto& bc : c.boundary_conditions) anvil::resolve_selection(m, c, bc.nodes);
    for (const auto& ic : c.initial_conditions) anvil::resolve_selection(m, c, ic.nodes);
  } catch (const anvil::InputError&) {
  }
  return 0;
}
