// Helpers shared by the tests: relative comparison in the style of LAMMPS's unit tests,
// and running a deck given as text.
#pragma once

#include <array>
#include <cmath>
#include <string>

#include "anvil/io/config.hpp"
#include "anvil/solver/simulation.hpp"

namespace anvil::test {

// |a - b| / min(|a|, |b|), or |a - b| when either is below `floor` in magnitude.
double relative_error(double a, double b, double floor = 1e-300);

// Parses deck text (as if from file `name`) into configuration.
Config deck(const std::string& yaml, const std::string& name = "test.yaml");

// The nodes' total momentum (x, y, z) and, last, the sum of their |m v| (a scale for
// tolerances), over every rank's owned nodes. Collective.
std::array<double, 4> node_momentum(const Simulation& sim);
// The particles' total momentum (x, y, z) and, last, their total mass, over every rank's
// own particles (0 without particles). Collective.
std::array<double, 4> particle_momentum(const Simulation& sim);

// The two hexahedra stacked along z of the keyword tests (12 nodes, part 1, elements 1
// and 2) and a node set 7 of the bottom face, as LS-DYNA *NODE, *ELEMENT_SOLID and
// *SET_NODE_LIST cards.
extern const char* const two_bricks_keyword_mesh;

// The steel column of the 1-D wave tests (prescribed motions, loads): column_length = 0.1 m
// along z, `width` square, `cells` elements along z, its sides held laterally (uniaxial
// strain), run to `end`; `more` adds conditions (its ends' loading) and sections.
// Steel: density 7850 kg/m^3, E 200 GPa, nu 0.3.
inline constexpr double column_length = 0.1;
std::string column_deck(double width, int cells, double end, const std::string& more);

// Source and binary locations (set by CMake).
inline const char* source_dir() {
  return ANVIL_SOURCE_DIR;
}
inline const char* anvil_binary() {
  return ANVIL_BINARY;
}

} // namespace anvil::test
