#include "test_support.hpp"

#include <algorithm>
#include <cmath>
#include <span>

#include <fmt/format.h>

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

std::array<double, 4> particle_momentum(const Simulation& sim) {
  std::array<double, 4> p{0, 0, 0, 0};
  if (const auto* sph = sim.sph()) {
    const auto& pt = sph->particles();
    for (std::size_t i = 0; i < pt.size(); ++i) {
      for (int k = 0; k < 3; ++k) p[k] += pt.mass[i] * pt.v[k][i];
      p[3] += pt.mass[i];
    }
  }
  sim.comm().sum(std::span<double>(p));
  return p;
}

const char* const two_bricks_keyword_mesh = R"(*NODE
       1             0.0             0.0             0.0
       2             1.0             0.0             0.0
       3             1.0             1.0             0.0
       4             0.0             1.0             0.0
       5             0.0             0.0             1.0
       6             1.0             0.0             1.0
       7             1.0             1.0             1.0
       8             0.0             1.0             1.0
       9             0.0             0.0             2.0
      10             1.0             0.0             2.0
      11             1.0             1.0             2.0
      12             0.0             1.0             2.0
*ELEMENT_SOLID
       1       1       1       2       3       4       5       6       7       8
       2       1       5       6       7       8       9      10      11      12
*SET_NODE_LIST
         7
         1         2         3         4
)";

std::string column_deck(double width, int cells, double end, const std::string& more) {
  return fmt::format(R"(
termination: {{time: {}}}
materials:
  steel: {{model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}}
parts:
  column:
    mesh: {{generate: box, min: [0, 0, 0], max: [{}, {}, {}], divisions: [1, 1, {}]}}
    material: steel
boundary_conditions:
  - {{set: column.xmin, fix: [x]}}
  - {{set: column.xmax, fix: [x]}}
  - {{set: column.ymin, fix: [y]}}
  - {{set: column.ymax, fix: [y]}}
)",
                     end, width, width, column_length, cells) +
         more;
}

} // namespace anvil::test
