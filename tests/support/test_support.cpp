#include "test_support.hpp"

#include <algorithm>

#include "anvil/io/deck.hpp"

namespace anvil::test {

double relative_error(double a, double b, double floor) {
  const double d = std::abs(a - b);
  const double m = std::min(std::abs(a), std::abs(b));
  return m < floor ? d : d / m;
}

Config deck(const std::string& yaml, const std::string& name) {
  return parse_deck(yaml, name, ".");
}

} // namespace anvil::test
