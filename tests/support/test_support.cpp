#include "test_support.hpp"

#include <algorithm>
#include <cmath>
#include <span>

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

std::array<double, 4> node_momentum(const Simulation& sim) {
  std::array<double, 4> p{0, 0, 0, 0};
  const auto& nd = sim.nodes();
  for (std::size_t n = 0; n < nd.size(); ++n)
    if (sim.fe().node_owned[n]) {
      for (int i = 0; i < 3; ++i) p[i] += nd.mass[n] * nd.v[i][n];
      p[3] += nd.mass[n] * std::hypot(nd.v[0][n], nd.v[1][n], nd.v[2][n]);
    }
  sim.comm().sum(std::span<double>(p));
  return p;
}

} // namespace anvil::test
