// Mass scaling (time_step.mass_scaling, LS-DYNA's *CONTROL_TIMESTEP DT2MS < 0 with
// MS1ST = 1): elements whose stable step, at rest in their initial shape, is below
// step / scale get the mass that raises it to that, as from a density f = (target /
// step)^2 times their material's (LS-DYNA's manual: "mass is added only to those elements
// whose time step would otherwise be less than |DT2MS|").
//
// References and tolerances:
// - A column scaled by f = 4 everywhere carries the 1-D wave of a material 4 times denser
//   (Kolsky 1963, ch. 1): speed c / 2, so the front reaches mid-length at z / (c / 2), and
//   the axial stress behind it is -(4 rho)(c / 2) v0: both within 1%, as test_wave_1d.
//   It is the run of the denser material itself: positions within 1e-9 of the largest
//   displacement (the two differ in the rounding of f and of the wave speed only).
// - Two blocks, one of thin elements: only the thin elements gain mass; the added mass is
//   N m ((target / dt)^2 - 1) of the thin elements' unscaled step dt (all alike), the
//   initial step is the asked one, and the nodes carry the added mass (the initial kinetic
//   energy of the moving thin block is (m + added) v^2 / 2): all within 1e-12.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include <fmt/format.h>

#include "anvil/io/checkpoint.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

constexpr double rho = 7850, E = 200e9, nu = 0.3, v0 = 1.0, L = 0.1;

std::string column(double density, double end) {
  return fmt::format(R"(
termination: {{time: {}}}
materials:
  steel: {{model: elastic, density: {}, youngs_modulus: 200.0e9, poissons_ratio: 0.3}}
parts:
  column:
    mesh: {{generate: box, min: [0, 0, 0], max: [0.0005, 0.0005, 0.1], divisions: [1, 1, 200]}}
    material: steel
boundary_conditions:
  - {{set: column.xmin, fix: [x]}}
  - {{set: column.xmax, fix: [x]}}
  - {{set: column.ymin, fix: [y]}}
  - {{set: column.ymax, fix: [y]}}
  - {{set: column.zmin, velocity: [0, 0, 1.0], components: [z]}}
probes:
  - {{name: mid, at: [0, 0, 0.05]}}
)",
                     end, density);
}

TEST(MassScaling, ScaledColumnCarriesTheWaveOfADenserOne) {
  const Comm world = Comm::world();
  const double M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
  const double c = std::sqrt(M / rho) / 2; // the wave speed of density 4 rho
  const double t_end = 1.2 * L / c;
  Config scaled = test::deck(column(rho, t_end));
  {
    // The elements' step at rest (the pushed end's first element compresses at once,
    // which bulk viscosity shortens; mass scaling looks at the elements at rest).
    Config rest = scaled;
    rest.boundary_conditions.pop_back();
    Simulation plain(rest, world);
    scaled.mass_scaling_step = 2 * scaled.time_step_scale * plain.stable_time_step(); // f = 4
  }
  const Config dense = test::deck(column(4 * rho, t_end));
  Simulation a(scaled, world), b(dense, world);
  EXPECT_EQ(a.mass_scaled_elements(), 200);
  EXPECT_LT(test::relative_error(a.part_added_masses()[0], 3 * a.part_masses()[0]), 1e-12);
  std::vector<double> t, vz;
  double stress = 0;
  while (!a.finished()) {
    a.step();
    b.step();
    const Sample s = a.sample();
    t.push_back(s.time);
    vz.push_back(s.probes[5]);
  }
  ASSERT_EQ(a.clock().cycle, b.clock().cycle);
  // Arrival at mid-length: the velocity crossing v0 / 2.
  double t_half = -1;
  for (std::size_t k = 1; k < t.size(); ++k)
    if (vz[k - 1] < 0.5 * v0 && vz[k] >= 0.5 * v0) {
      t_half = t[k - 1] + (0.5 * v0 - vz[k - 1]) / (vz[k] - vz[k - 1]) * (t[k] - t[k - 1]);
      break;
    }
  ASSERT_GT(t_half, 0) << "the wave never reached the probe";
  // Mean axial stress of the loaded quarter (behind the front at the end).
  double sum = 0, count = 0, dx = 0, umax = 0;
  const auto& nd_a = a.nodes();
  const auto& nd_b = b.nodes();
  for (const auto& blk : a.blocks())
    for (int e = 0; e < blk.size(); ++e) {
      double z = 0;
      for (int k = 0; k < 8; ++k) z += nd_a.x[2][blk.conn[k][e]] / 8;
      if (z < 0.25 * L) {
        sum += blk.stress[2][e];
        count += 1;
      }
    }
  for (std::size_t n = 0; n < nd_a.size(); ++n) {
    dx = std::max(dx, std::abs(nd_a.x[2][n] - nd_b.x[2][n]));
    umax = std::max(umax, std::abs(nd_b.x[2][n] - nd_b.x0[2][n]));
  }
  sum = world.sum(sum);
  count = world.sum(count);
  dx = world.max(dx);
  umax = world.max(umax);
  stress = sum / count;
  const double t_ref = 0.5 * L / c, s_ref = -(4 * rho) * c * v0;
  if (world.rank() == 0)
    std::printf("f = 4 column: arrival %.4e s (1-D theory %.4e, rel %.2e); stress %.4e Pa "
                "(theory %.4e, rel %.2e); against density 4 rho: %.2e of the displacement\n",
                t_half, t_ref, test::relative_error(t_half, t_ref), stress, s_ref,
                test::relative_error(stress, s_ref), dx / umax);
  EXPECT_LT(test::relative_error(t_half, t_ref), 0.01);
  EXPECT_LT(test::relative_error(stress, s_ref), 0.01);
  EXPECT_LT(dx, 1e-9 * umax);
}

// A block of thin elements (10 x 10 x 10 of 1 x 1 x 0.2 mm, moving at 10 m/s) beside a
// block of 1 mm cubes at rest.
const char* two_blocks = R"(
termination: {cycles: 20}
time_step: {scale: 0.9, mass_scaling: {step: 4.0e-8}}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  thin:
    mesh: {generate: box, min: [0, 0, 0], max: [0.01, 0.01, 0.002], divisions: [10, 10, 10]}
    material: steel
  cubes:
    mesh: {generate: box, min: [0, 0, 0.003], max: [0.01, 0.01, 0.013], divisions: [10, 10, 10]}
    material: steel
initial_conditions:
  - {part: thin, velocity: [0, 0, 10.0]}
)";

TEST(MassScaling, OnlyElementsBelowTheStepGainMass) {
  const Comm world = Comm::world();
  Config config = test::deck(two_blocks);
  const double step = config.mass_scaling_step;
  config.mass_scaling_step = 0;
  double dt_thin = 0; // the thin elements' step (they set the model's)
  {
    Simulation plain(config, world);
    dt_thin = plain.stable_time_step();
  }
  config.mass_scaling_step = step;
  Simulation sim(config, world);
  const double target = step / config.time_step_scale;
  ASSERT_LT(dt_thin, target);
  const double m_thin = sim.part_masses()[0];
  const double added_ref = m_thin * ((target / dt_thin) * (target / dt_thin) - 1);
  EXPECT_EQ(sim.mass_scaled_elements(), 1000);
  EXPECT_EQ(sim.part_added_masses()[1], 0.0);
  EXPECT_LT(test::relative_error(sim.part_added_masses()[0], added_ref), 1e-12);
  const double dt = sim.stable_time_step();
  EXPECT_LT(test::relative_error(dt, target), 1e-12);
  // The nodes carry the added mass: their sum, and the thin block's kinetic energy.
  double nodal = 0;
  for (std::size_t n = 0; n < sim.nodes().size(); ++n)
    if (sim.fe().node_owned[n]) nodal += sim.nodes().mass[n];
  nodal = world.sum(nodal);
  const double total = sim.part_masses()[0] + sim.part_masses()[1] + sim.part_added_masses()[0];
  EXPECT_LT(test::relative_error(nodal, total), 1e-12);
  const double ke_ref = 0.5 * (m_thin + sim.part_added_masses()[0]) * 10.0 * 10.0;
  EXPECT_LT(test::relative_error(sim.sample().kinetic, ke_ref), 1e-12);
  // Past 5% of a part's mass: a warning names the part.
  bool warned = false;
  for (const auto& w : sim.warnings())
    warned = warned || (w.find("part thin") != std::string::npos &&
                        w.find("mass scaling adds") != std::string::npos);
  EXPECT_TRUE(warned);
  while (!sim.finished()) sim.step();
  EXPECT_LT(test::relative_error(sim.clock().time, 20 * step), 1e-12);
  const double balance = sim.balance_error(sim.sample()); // (collective)
  if (world.rank() == 0)
    std::printf("thin elements' step %.6e s raised to %.6e s: %lld elements, added mass %.6e kg "
                "(reference %.6e), balance error after 20 cycles %.2e\n",
                dt_thin, dt, static_cast<long long>(sim.mass_scaled_elements()),
                sim.part_added_masses()[0], added_ref, balance);
}

// A restart keeps the masses of the run that wrote the checkpoint: a deck without its mass
// scaling, or with another step, is an input error (QA round 30: it ran on with other
// masses and the old velocities, the energy balance off by 16%); the same deck restores.
// A step so large that the masses overflow is an input error too (was a non-finite force
// at t = 0, exit 3).
TEST(MassScaling, RestartKeepsTheMassesAndOverflowIsAnInputError) {
  const Comm world = Comm::world();
  const Config config = test::deck(two_blocks);
  Simulation sim(config, world);
  for (int i = 0; i < 5; ++i) sim.step();
  // (capture() gathers on rank 0; every rank reads the file back.)
  const std::string path = fmt::format("/tmp/anvil_test_mass_scaling_np{}.anvil", world.size());
  const Checkpoint captured = capture(sim, OutputState{});
  if (world.rank() == 0) write_checkpoint(path, captured);
  world.barrier();
  const Checkpoint c = read_checkpoint(path);
  world.barrier();
  if (world.rank() == 0) std::remove(path.c_str());
  {
    Simulation same(config, world);
    EXPECT_NO_THROW(same.restore(c));
    EXPECT_EQ(same.clock().cycle, 5);
  }
  for (const double step : {0.0, 5.0e-8}) {
    Config other = config;
    other.mass_scaling_step = step;
    Simulation sim2(other, world);
    try {
      sim2.restore(c);
      ADD_FAILURE() << "no error for a restart with the step " << step;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("the masses would change under the run"),
                std::string::npos)
          << e.what();
    }
  }
  std::string huge = two_blocks;
  huge.replace(huge.find("step: 4.0e-8"), 12, "step: 1.0e300");
  try {
    Simulation sim3(test::deck(huge, "deck.yaml"), world);
    ADD_FAILURE() << "no error for a step of 1e300 s";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("deck.yaml:3: time_step.mass_scaling.step"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("beyond any number"), std::string::npos) << e.what();
  }
}

} // namespace
