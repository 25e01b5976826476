// Helpers shared by the tests: relative comparison in the style of LAMMPS's unit tests,
// and running a deck given as text.
#pragma once

#include <cmath>
#include <string>

#include "anvil/io/config.hpp"

namespace anvil::test {

// |a - b| / min(|a|, |b|), or |a - b| when either is below `floor` in magnitude.
double relative_error(double a, double b, double floor = 1e-300);

// Parses deck text (as if from file `name`) into configuration.
Config deck(const std::string& yaml, const std::string& name = "test.yaml");

// Source and binary locations (set by CMake).
inline const char* source_dir() {
  return ANVIL_SOURCE_DIR;
}
inline const char* anvil_binary() {
  return ANVIL_BINARY;
}

} // namespace anvil::test
