// `output.part_energies` (LS-DYNA's matsum): each part's and particle set's kinetic,
// internal and hourglass energy. They split the totals by where the energy is, so at every
// row they add up to the totals (a node's kinetic energy split among its elements by the
// lumped mass each gave it): tolerance 1e-12 of the total (the sums in another order).
// The model: a plastic block (viscous hourglass control, so hourglass energy) thrown at
// an elastic one, and a particle ball thrown at the elastic one too, in general contact;
// a body that nothing touches keeps its kinetic energy (1/2 m v^2, to 1e-12) and no
// internal energy (below 1e-15 of its kinetic energy: the round-off strain of a
// translation).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

TEST(PartEnergies, AddUpToTheTotals) {
  const Config config = test::deck(R"(
termination: {cycles: 300}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
  al: {model: j2_plasticity, density: 2700, youngs_modulus: 70.0e9, poissons_ratio: 0.33,
       yield_stress: 0.1e9}
parts:
  target:
    mesh: {generate: box, min: [0, 0, 0], max: [0.02, 0.01, 0.004], divisions: [10, 5, 2]}
    material: steel
  slug:
    mesh: {generate: box, min: [0.002, 0.002, 0.0041], max: [0.008, 0.008, 0.01],
           divisions: [3, 3, 3]}
    material: al
  far:
    mesh: {generate: box, min: [0.1, 0, 0], max: [0.11, 0.01, 0.01], divisions: [2, 2, 2]}
    material: steel
particles:
  ball: {generate: {shape: sphere, center: [0.015, 0.005, 0.0061], radius: 2.0e-3,
         spacing: 5.0e-4}, material: al, smoothing_ratio: 1.3}
initial_conditions:
  - {part: slug, velocity: [0, 0, -200.0]}
  - {part: ball, velocity: [0, 0, -150.0]}
  - {part: far, velocity: [1.0, 0, 0]}
boundary_conditions:
  - {set: target.zmin, fix: [z]}
contact:
  - {type: general, parts: [target, slug, ball]}
output: {part_energies: true}
)");
  const Comm world = Comm::world();
  Simulation sim(config, world);
  double worst = 0;
  int rows = 0;
  Sample s = sim.sample();
  double far_ke = 0;
  for (;;) {
    ASSERT_EQ(s.part_energies.size(), 12u); // three parts and one particle set
    double sum[3] = {0, 0, 0};
    for (std::size_t p = 0; p < 4; ++p)
      for (int k = 0; k < 3; ++k) sum[k] += s.part_energies[3 * p + static_cast<std::size_t>(k)];
    const double total[3] = {s.kinetic, s.internal, s.hourglass};
    const double scale = s.kinetic + s.internal + s.hourglass;
    for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(sum[k] - total[k]) / scale);
    // The far block: 1/2 m v^2 (m = 7850 * 1e-6 kg at 1 m/s), nothing else.
    far_ke = s.part_energies[6];
    EXPECT_LT(s.part_energies[7], 1e-15 * far_ke); // round-off of a translation's strain
    ++rows;
    if (sim.finished()) break;
    sim.step();
    s = sim.sample();
  }
  EXPECT_LT(worst, 1e-12) << "part energies off the totals by " << worst;
  EXPECT_NEAR(far_ke, 0.5 * 7850 * 1e-6 * 1.0, 1e-12 * 0.5 * 7850 * 1e-6);
  // Energy moved between the parts: the slug and the ball lost kinetic energy into
  // internal energy of themselves and the target.
  EXPECT_GT(s.part_energies[1], 0.0);  // target internal
  EXPECT_GT(s.part_energies[4], 0.0);  // slug internal
  EXPECT_GT(s.part_energies[5], 0.0);  // slug hourglass
  EXPECT_GT(s.part_energies[10], 0.0); // ball internal
  if (world.rank() == 0)
    std::printf("part energies: worst |sum - total| %.2e of the energy over %d rows; at the end "
                "(kinetic, internal, hourglass, J): target %.3g %.3g %.3g, slug %.3g %.3g "
                "%.3g, far %.3g %.3g %.3g, ball %.3g %.3g %.3g\n",
                worst, rows, s.part_energies[0], s.part_energies[1], s.part_energies[2],
                s.part_energies[3], s.part_energies[4], s.part_energies[5], s.part_energies[6],
                s.part_energies[7], s.part_energies[8], s.part_energies[9], s.part_energies[10],
                s.part_energies[11]);
}

} // namespace
