// An elastic bar strikes a rigid wall (1-D wave theory; e.g. Graff, "Wave Motion in
// Elastic Solids", 1975, section 1.1; Johnson, "Impact Strength of Materials", 1972):
// a column in uniaxial strain (sides fixed laterally), length L, moving at v0 onto a
// planar rigid wall, stays in contact for 2L/c with the wall force rho c v0 A, then leaves
// with velocity v0 reversed, c = sqrt((lambda + 2 mu) / rho).
// Tolerances: contact duration (force below half its plateau) within 2% of 2L/c; mean
// plateau force within 2% of rho c v0 A; rebound velocity of the centre of mass within 2%
// of v0; the struck face at rest during the contact (the probe's velocity at t(n), after
// the wall's correction) to round-off, 1e-9 v0. The artificial bulk viscosity is off (as in the
// energy check): it is a dissipative device for shocks, and with LS-DYNA's default coefficients it
// takes 5% of the energy out of this event (rebound at 0.975 v0, measured).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

TEST(RigidWall, ElasticBarStaysInContactFor2LOverC) {
  const double L = 0.05, a = 0.002, rho = 7850, E = 200e9, nu = 0.3, v0 = 5.0;
  const double c = std::sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / rho);
  const double t_contact = 2 * L / c;
  const std::string deck = R"(
termination: {time: )" + std::to_string(1.5 * t_contact) +
                           R"(}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  bar:
    mesh: {generate: box, min: [0, 0, 0], max: [0.002, 0.002, 0.05], divisions: [1, 1, 100]}
    material: steel
    bulk_viscosity: {linear: 0, quadratic: 0}
initial_conditions:
  - {part: bar, velocity: [0, 0, -5.0]}
boundary_conditions:
  - {set: bar.xmin, fix: [x]}
  - {set: bar.xmax, fix: [x]}
  - {set: bar.ymin, fix: [y]}
  - {set: bar.ymax, fix: [y]}
rigid_walls:
  - {point: [0, 0, 0], normal: [0, 0, 1]}
probes:
  - {name: face, at: [0, 0, 0]}
)";
  const Comm world = Comm::world();
  Simulation sim(test::deck(deck), world);
  std::vector<double> t, force, face_v;
  while (!sim.finished()) {
    sim.step();
    const Sample s = sim.sample();
    t.push_back(s.time);
    force.push_back(s.wall_force[0]);
    face_v.push_back(s.probes[5]);
  }
  const double plateau_expected = rho * c * v0 * a * a;
  double sum = 0;
  int n = 0;
  for (std::size_t k = 0; k < t.size(); ++k)
    if (t[k] > 0.1 * t_contact && t[k] < 0.9 * t_contact) {
      sum += force[k];
      ++n;
    }
  const double plateau = sum / n;
  double face_v_max = 0;
  for (std::size_t k = 0; k < t.size(); ++k)
    if (t[k] > 0.1 * t_contact && t[k] < 0.9 * t_contact)
      face_v_max = std::max(face_v_max, std::abs(face_v[k]));
  EXPECT_LT(face_v_max, 1e-9 * v0) << "the struck face moves while it rests on the wall";
  double t_end = -1;
  for (std::size_t k = 1; k < t.size(); ++k)
    if (t[k] > 0.5 * t_contact && force[k - 1] >= 0.5 * plateau && force[k] < 0.5 * plateau) {
      t_end =
          t[k - 1] + (force[k - 1] - 0.5 * plateau) / (force[k - 1] - force[k]) * (t[k] - t[k - 1]);
      break;
    }
  // Rebound velocity: the centre-of-mass velocity (momentum / mass) after separation.
  double mom[2] = {0, 0};
  for (std::size_t k = 0; k < sim.nodes().size(); ++k)
    if (sim.fe().node_owned[k]) {
      mom[0] += sim.nodes().mass[k] * sim.nodes().v[2][k];
      mom[1] += sim.nodes().mass[k];
    }
  world.sum(std::span<double>(mom, 2));
  const double v_sum = mom[0] / mom[1];
  const int nv = 1;
  if (world.rank() == 0)
    std::printf("rigid wall: plateau %.2f N (%.2f), contact %.4e s (2L/c %.4e, %+.2f%%), rebound "
                "%.4f m/s\n",
                plateau, plateau_expected, t_end, t_contact, 100 * (t_end - t_contact) / t_contact,
                v_sum / nv);
  EXPECT_LT(std::abs(plateau - plateau_expected) / plateau_expected, 0.02);
  ASSERT_GT(t_end, 0);
  EXPECT_LT(std::abs(t_end - t_contact) / t_contact, 0.02);
  EXPECT_LT(std::abs(v_sum / nv - v0) / v0, 0.02);
  // After separation the wall carries nothing.
  EXPECT_EQ(force.back(), 0.0);
}

} // namespace
