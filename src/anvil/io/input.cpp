#include "anvil/io/input.hpp"

#include "anvil/io/deck.hpp"
#include "anvil/io/keyword.hpp"

namespace anvil {

Config read_input(const std::string& path) {
  return is_keyword_file(path) ? read_keyword_deck(path) : read_deck(path);
}

} // namespace anvil
