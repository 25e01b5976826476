// One-dimensional elastic wave (uniaxial strain; e.g. Kolsky, "Stress Waves in Solids",
// 1963, ch. 1; Graff, "Wave Motion in Elastic Solids", 1975, section 1.1): the end of a
// column with laterally fixed sides is pushed at v0 = 1 m/s. A step wave runs along it at
// c = sqrt((lambda + 2 mu) / rho); behind the front the particle velocity is v0 and the
// axial stress -rho c v0. Checks at the mid-length probe and in the loaded half:
//   arrival time (velocity crossing v0 / 2) within 1% of z / c,
//   mean particle velocity on the plateau within 1% of v0,
//   mean axial stress behind the front within 1% of -rho c v0.
// The same column of wedges and of tetrahedra (the box cut, hexahedra whose nodes repeat)
// meets the same tolerances.
#include <gtest/gtest.h>

#include <cmath>

#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

class Wave1D : public ::testing::TestWithParam<std::string> {};

TEST_P(Wave1D, StepWaveArrivesAtTheAnalyticTimeWithTheAnalyticAmplitude) {
  const std::string elements = GetParam();
  const int per_cell = elements == "wedges" ? 2 : elements == "tetrahedra" ? 6 : 1;
  const double L = 0.1, rho = 7850, E = 200e9, nu = 0.3, v0 = 1.0;
  const double M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
  const double c = std::sqrt(M / rho);
  const double t_end = 1.2 * L / c;
  const std::string deck = R"(
termination: {time: )" + std::to_string(t_end) +
                           R"(}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  column:
    mesh: {generate: box, min: [0, 0, 0], max: [0.0005, 0.0005, 0.1], divisions: [1, 1, 200],
           elements: )" + elements +
                           R"(}
    material: steel
boundary_conditions:
  - {set: column.xmin, fix: [x]}
  - {set: column.xmax, fix: [x]}
  - {set: column.ymin, fix: [y]}
  - {set: column.ymax, fix: [y]}
  - {set: column.zmin, velocity: [0, 0, 1.0], components: [z]}
probes:
  - {name: mid, at: [0, 0, 0.05]}
)";
  const Comm world = Comm::world();
  Simulation sim(test::deck(deck), world);
  std::vector<double> t, vz;
  while (!sim.finished()) {
    sim.step();
    const Sample s = sim.sample();
    t.push_back(s.time);
    vz.push_back(s.probes[5]);
  }
  const double z = 0.05, t_arrival = z / c;
  double t_half = -1;
  for (std::size_t k = 1; k < t.size(); ++k)
    if (vz[k - 1] < 0.5 * v0 && vz[k] >= 0.5 * v0) {
      t_half = t[k - 1] + (0.5 * v0 - vz[k - 1]) / (vz[k] - vz[k - 1]) * (t[k] - t[k - 1]);
      break;
    }
  ASSERT_GT(t_half, 0) << "the wave never reached the probe";
  EXPECT_LT(std::abs(t_half - t_arrival) / t_arrival, 0.01)
      << "arrival " << t_half << " s, analytic " << t_arrival << " s";

  double sum = 0;
  int n = 0;
  for (std::size_t k = 0; k < t.size(); ++k)
    if (t[k] > t_arrival + 0.1 * L / c) {
      sum += vz[k];
      ++n;
    }
  ASSERT_GT(n, 10);
  EXPECT_LT(std::abs(sum / n - v0) / v0, 0.01) << "plateau velocity " << sum / n;

  // Axial stress in the loaded half (the front is at 1.2 L, reflected from the free end
  // it has come back to 0.8 L: the first 0.3 L still carry the incident step).
  double s_sum = 0, count = 0;
  for (const auto& b : sim.blocks())
    for (int e = 0; e < b.size(); ++e)
      if (b.gid[e] < 60 * per_cell) {
        s_sum += b.stress[2][e];
        count += 1;
      }
  s_sum = world.sum(s_sum);
  count = world.sum(count);
  const double expected = -rho * c * v0;
  EXPECT_LT(std::abs(s_sum / count - expected) / std::abs(expected), 0.01)
      << "stress " << s_sum / count << " Pa, analytic " << expected << " Pa";
  if (world.rank() == 0)
    std::printf(
        "wave (%s): c %.1f m/s, arrival %.4e s (analytic %.4e, error %.3f%%), plateau %.5f m/s, "
        "stress %.5e Pa (analytic %.5e, error %.3f%%)\n",
        elements.c_str(), c, t_half, t_arrival, 100 * (t_half - t_arrival) / t_arrival, sum / n,
        s_sum / count, expected, 100 * (s_sum / count - expected) / std::abs(expected));
}

INSTANTIATE_TEST_SUITE_P(Elements, Wave1D, ::testing::Values("hexahedra", "wedges", "tetrahedra"));

} // namespace
