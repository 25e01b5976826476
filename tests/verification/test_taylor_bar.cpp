// The copper Taylor bar (Wilkins and Guinan 1973 setup, the benchmark of Simo 1992 and of
// the codes compared by Kamoulakos 1990): L = 32.4 mm, R = 3.2 mm, 227 m/s onto a rigid
// frictionless wall (impact face fixed axially, free radially), E = 117 GPa, nu = 0.35,
// rho = 8930 kg/m^3, yield 400 MPa, linear hardening modulus 100 MPa, 80 us; butterfly
// mesh 8 elements across the radius, 40 along (examples/taylor_bar.yaml).
// References and tolerances:
//   footprint (mushroom) radius 7.12 mm (Simo 1992): within 3%;
//   final length: the published values span 21.42-21.66 mm (Kamoulakos 1990's
//   compilation; Camacho and Ortiz 1997): within that span widened by 1%;
//   energy balance error below 1%.
#include <gtest/gtest.h>

#include <cmath>

#include "anvil/io/deck.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

TEST(TaylorBar, FootprintAndFinalLengthMatchPublishedValues) {
  const Config config = read_deck(std::string(test::source_dir()) + "/examples/taylor_bar.yaml");
  const Comm world = Comm::world();
  Simulation sim(config, world);
  while (!sim.finished()) sim.step();
  const Sample s = sim.sample();

  const auto& nd = sim.nodes();
  double radius = 0, top = -1e300;
  for (std::size_t n = 0; n < nd.size(); ++n) {
    if (nd.x0[2][n] == 0.0) radius = std::max(radius, std::hypot(nd.x[0][n], nd.x[1][n]));
    top = std::max(top, nd.x[2][n]);
  }
  radius = world.max(radius) * 1e3;
  const double length = world.max(top) * 1e3;
  const double balance = sim.balance_error(s);
  if (world.rank() == 0)
    std::printf("taylor bar: footprint radius %.4f mm (7.12: %+.2f%%), final length %.4f mm, "
                "energy balance error %.2e, cycles %lld\n",
                radius, 100 * (radius - 7.12) / 7.12, length, balance,
                static_cast<long long>(sim.clock().cycle));
  EXPECT_LT(std::abs(radius - 7.12) / 7.12, 0.03);
  EXPECT_GT(length, 21.42 * 0.99);
  EXPECT_LT(length, 21.66 * 1.01);
  EXPECT_LT(balance, 0.01);
  // Nearly all the kinetic energy has gone into plastic work.
  EXPECT_LT(s.kinetic, 0.01 * (s.internal + s.hourglass));
}

} // namespace
