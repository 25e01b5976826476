// The YAML deck reader: parses once, validates everything it can without the mesh, and
// returns typed configuration. Every problem is an InputError naming the file, the line
// and the key: unknown keys, wrong types, missing or impossible values, malformed YAML.
#pragma once

#include <string>

#include "anvil/io/config.hpp"

namespace anvil {

// Reads and validates the deck at `path`; mesh file names are resolved relative to it.
Config read_deck(const std::string& path);

// Parses deck text; `name` stands for the file in messages, `base_dir` resolves mesh files.
Config parse_deck(const std::string& text, const std::string& name,
                  const std::string& base_dir = ".");

} // namespace anvil
