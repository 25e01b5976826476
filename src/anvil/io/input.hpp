// The one entry point from a deck file to configuration, whatever its format.
#pragma once

#include <string>

#include "anvil/io/config.hpp"

namespace anvil {

// Reads the deck at `path`: an LS-DYNA keyword deck by its extension (.k, .key, .dyn;
// keyword.hpp), otherwise a YAML deck (deck.hpp). Both give the same validated Config;
// only a keyword deck fills Config::warnings. Throws InputError naming file, line and key.
Config read_input(const std::string& path);

} // namespace anvil
