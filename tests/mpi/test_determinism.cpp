// DESIGN.md section 3: a run on P ranks produces bit-for-bit the trajectory of the run on
// one rank. The same deck runs on MPI_COMM_WORLD and, on rank 0, on MPI_COMM_SELF; the
// nodal positions, velocities and element stresses are gathered by global id and
// compared with exact equality (tolerance: zero).
#include <gtest/gtest.h>

#include <cstring>
#include <map>

#include "anvil/io/deck.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/solver/can_crush.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

// An impact with plasticity, the three hourglass forms (a clamped sheet one element thick
// flaps with the assumed-strain form, another as a thick shell), a prescribed velocity, a rotation
// and non-trivial partitions: every code path of the FE cycle.
const char* deck_text = R"(
termination: {cycles: 150}
materials:
  copper: {model: j2_plasticity, density: 8930, youngs_modulus: 117.0e9,
           poissons_ratio: 0.35, yield_stress: 0.4e9, hardening_modulus: 0.1e9}
  steel: {model: johnson_cook, density: 7830, youngs_modulus: 200.0e9, poissons_ratio: 0.29,
          A: 792.0e6, B: 510.0e6, C: 0.014, n: 0.26, m: 1.03, melt_temperature: 1793.0,
          specific_heat: 477.0}
parts:
  bar:
    mesh: {generate: cylinder, radius: 3.2e-3, length: 16.0e-3, axis: z, divisions: [4, 10]}
    material: copper
    hourglass: {model: viscous, coefficient: 0.1}
  plate:
    mesh: {generate: box, min: [-0.01, -0.01, -0.004], max: [0.01, 0.01, -0.001], divisions: [8, 8, 3]}
    material: steel
    hourglass: {model: stiffness, coefficient: 0.05}
  sheet:
    mesh: {generate: box, min: [0.02, -0.01, 0], max: [0.04, 0.01, 0.001], divisions: [8, 8, 1]}
    material: steel
    hourglass: {model: assumed_strain}
  shell:
    mesh: {generate: box, min: [0.05, -0.01, 0], max: [0.07, 0.01, 0.001], divisions: [8, 8, 1]}
    material: steel
    thick_shell: {points: 3}
initial_conditions:
  - {part: bar, velocity: [0, 0, -400.0], angular_velocity: [0, 0, 2000.0], center: [0, 0, 0]}
  - {part: sheet, velocity: [0, 0, 60.0], angular_velocity: [3000.0, 0, 0], center: [0.03, 0, 0]}
  - {part: shell, velocity: [0, 0, 80.0], angular_velocity: [3000.0, 0, 0], center: [0.06, 0, 0]}
boundary_conditions:
  - {set: sheet.xmin, fix: all}
  - {set: shell.xmin, fix: all}
  - {set: bar.bottom, fix: [z]}
  - {set: plate.zmin, velocity: [0, 0, 30.0]}
)";

struct Snapshot {
  std::map<std::int64_t, std::array<double, 6>> nodes;    // x, v by node gid
  std::map<std::int64_t, std::array<double, 8>> elements; // stress, ep, T by element gid
};

// Collects owned nodes and elements of every rank on rank 0.
Snapshot gather(const Simulation& sim) {
  const Comm& comm = sim.comm();
  std::vector<double> nbuf, ebuf;
  const auto& nd = sim.nodes();
  for (std::size_t n = 0; n < nd.size(); ++n) {
    if (!sim.fe().node_owned[n]) continue;
    nbuf.push_back(static_cast<double>(sim.fe().node_gid[n]));
    for (int i = 0; i < 3; ++i) nbuf.push_back(nd.x[i][n]);
    for (int i = 0; i < 3; ++i) nbuf.push_back(nd.v[i][n]);
  }
  for (const auto& b : sim.blocks())
    for (int e = 0; e < b.size(); ++e) {
      ebuf.push_back(static_cast<double>(b.gid[e]));
      for (int k = 0; k < 6; ++k) ebuf.push_back(b.stress[k][e]);
      ebuf.push_back(b.plastic_strain.empty() ? 0.0 : b.plastic_strain[e]);
      ebuf.push_back(b.temperature.empty() ? 0.0 : b.temperature[e]);
    }
  Snapshot s;
  auto take = [&](const std::vector<double>& buf) {
    for (std::size_t k = 0; k < buf.size(); k += 7) {
      std::array<double, 6> a;
      std::copy(buf.begin() + k + 1, buf.begin() + k + 7, a.begin());
      s.nodes[static_cast<std::int64_t>(buf[k])] = a;
    }
  };
  auto take_e = [&](const std::vector<double>& buf) {
    for (std::size_t k = 0; k < buf.size(); k += 9) {
      std::array<double, 8> a;
      std::copy(buf.begin() + k + 1, buf.begin() + k + 9, a.begin());
      s.elements[static_cast<std::int64_t>(buf[k])] = a;
    }
  };
  if (comm.rank() == 0) {
    take(nbuf);
    take_e(ebuf);
    for (int r = 1; r < comm.size(); ++r) {
      for (auto* buf : {&nbuf, &ebuf}) {
        std::int64_t n = 0;
        comm.recv_bytes(&n, sizeof n, r, 1);
        buf->resize(static_cast<std::size_t>(n));
        comm.recv_bytes(buf->data(), buf->size() * sizeof(double), r, 2);
      }
      take(nbuf);
      take_e(ebuf);
    }
  } else {
    for (auto* buf : {&nbuf, &ebuf}) {
      const std::int64_t n = static_cast<std::int64_t>(buf->size());
      comm.send_bytes(&n, sizeof n, 0, 1);
      comm.send_bytes(buf->data(), buf->size() * sizeof(double), 0, 2);
    }
  }
  return s;
}

bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// Runs `config` on all ranks and, on rank 0, alone; counts the values that differ.
// lazy_cycles (if given): the parallel run's lazy contact cycles.
std::int64_t compare_with_serial(const Config& config, double* max_ep,
                                 std::int64_t* lazy_cycles = nullptr) {
  const Comm world = Comm::world();
  Simulation parallel(config, world);
  while (!parallel.finished()) parallel.step();
  if (lazy_cycles) *lazy_cycles = parallel.contact()->stats().lazy_cycles;
  const Snapshot p = gather(parallel);
  if (world.rank() != 0) return 0;
  const Comm self = Comm::self();
  Simulation serial(config, self);
  while (!serial.finished()) serial.step();
  const Snapshot s = gather(serial);
  EXPECT_EQ(parallel.clock().cycle, serial.clock().cycle);
  EXPECT_TRUE(same_bits(parallel.clock().time, serial.clock().time));
  EXPECT_EQ(p.nodes.size(), s.nodes.size());
  EXPECT_EQ(p.elements.size(), s.elements.size());
  std::int64_t differing = 0;
  for (const auto& [gid, a] : s.nodes)
    for (int k = 0; k < 6; ++k)
      if (!same_bits(a[k], p.nodes.at(gid)[k])) ++differing;
  for (const auto& [gid, a] : s.elements)
    for (int k = 0; k < 8; ++k)
      if (!same_bits(a[k], p.elements.at(gid)[k])) ++differing;
  *max_ep = 0;
  for (const auto& [gid, a] : s.elements) *max_ep = std::max(*max_ep, a[6]);
  return differing;
}

// The scaled can crush (contact on its RCB decomposition, self-contact, a prescribed block)
// for 800 cycles, by when the block has crushed the can's rim for 50 us: the contact
// decomposition must not change a bit either, on its lazy cycles (kept destinations and
// plans, only what the candidate lists read sent) as on its full ones; both occur.
TEST(Determinism, CanCrushSameBitsOnAnyRankCount) {
  CanCrushOptions o;
  o.cycles = 800;
  double max_ep = 0;
  std::int64_t lazy = 0;
  const std::int64_t differing = compare_with_serial(can_crush_config(o), &max_ep, &lazy);
  EXPECT_EQ(differing, 0) << "values differing from the 1-rank run on " << Comm::world().size()
                          << " ranks";
  EXPECT_GT(lazy, 0) << "lazy contact cycles";
  EXPECT_LT(lazy, o.cycles - 1) << "full contact cycles after the first";
  if (Comm::world().rank() == 0) EXPECT_GT(max_ep, 1e-4); // contact has deformed the rim
}

// The same with the sectors decomposition (the FE decomposition an RCB of the element
// centres, every RCB cutting along the can's axis): another partition, the same bits.
TEST(Determinism, CanCrushSectorsSameBitsOnAnyRankCount) {
  CanCrushOptions o;
  o.cycles = 600;
  o.decomposition = CanCrushOptions::Decomposition::sectors;
  const Config config = can_crush_config(o);
  ASSERT_EQ(config.decomposition.fe, DecompositionConfig::Fe::rcb);
  double max_ep = 0;
  const std::int64_t differing = compare_with_serial(config, &max_ep);
  EXPECT_EQ(differing, 0) << "values differing from the 1-rank run on " << Comm::world().size()
                          << " ranks";
  if (Comm::world().rank() == 0) EXPECT_GT(max_ep, 1e-4); // contact has deformed the rim
}

TEST(Determinism, SameBitsOnAnyRankCount) {
  const Config config = test::deck(deck_text);
  const Comm world = Comm::world();
  Simulation parallel(config, world);
  while (!parallel.finished()) parallel.step();
  const Snapshot p = gather(parallel);
  if (world.rank() != 0) return;

  const Comm self = Comm::self();
  Simulation serial(config, self);
  while (!serial.finished()) serial.step();
  const Snapshot s = gather(serial);

  EXPECT_EQ(parallel.clock().cycle, serial.clock().cycle);
  EXPECT_TRUE(same_bits(parallel.clock().time, serial.clock().time));
  ASSERT_EQ(p.nodes.size(), s.nodes.size());
  ASSERT_EQ(p.elements.size(), s.elements.size());
  std::int64_t differing = 0;
  for (const auto& [gid, a] : s.nodes)
    for (int k = 0; k < 6; ++k)
      if (!same_bits(a[k], p.nodes.at(gid)[k])) ++differing;
  for (const auto& [gid, a] : s.elements)
    for (int k = 0; k < 8; ++k)
      if (!same_bits(a[k], p.elements.at(gid)[k])) ++differing;
  EXPECT_EQ(differing, 0) << "values differing from the 1-rank run on " << world.size() << " ranks";
  // The run must have done something: plastic flow and motion.
  double max_ep = 0;
  for (const auto& [gid, a] : s.elements) max_ep = std::max(max_ep, a[6]);
  EXPECT_GT(max_ep, 0.01);
}

// Mass scaling (time_step.mass_scaling) to a step that scales about half the elements of
// the FE deck: each element's factor comes from its own step at rest, the nodes' masses
// are gathered in global element order, so the run keeps its bits.
TEST(Determinism, MassScalingSameBitsOnAnyRankCount) {
  Config config =
      test::deck(std::string("time_step: {mass_scaling: {step: 1.0e-7}}\n") + deck_text);
  double max_ep = 0;
  const std::int64_t differing = compare_with_serial(config, &max_ep);
  EXPECT_EQ(differing, 0) << "values differing from the 1-rank run on " << Comm::world().size()
                          << " ranks";
  if (Comm::world().rank() == 0) EXPECT_GT(max_ep, 0.01);
  const Comm self = Comm::self();
  Simulation sim(config, self);
  EXPECT_GT(sim.mass_scaled_elements(), 0);
  EXPECT_LT(sim.mass_scaled_elements(), sim.global_elements());
}

// Wedges and tetrahedra (hexahedra whose nodes repeat: their own corner masses and step
// factors, triangular contact faces, METIS on 3-node faces): a block of tetrahedra strikes
// a plate of wedges at 150 m/s and dents it, in contact.
TEST(Determinism, WedgesAndTetrahedraSameBitsOnAnyRankCount) {
  const Config config = test::deck(R"(
termination: {cycles: 250}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
  aluminium: {model: j2_plasticity, density: 2700, youngs_modulus: 70.0e9, poissons_ratio: 0.33,
              yield_stress: 1.0e8, hardening_modulus: 1.0e8}
parts:
  block:
    mesh: {generate: box, min: [0.003, 0.002, 0.0061], max: [0.007, 0.006, 0.01], divisions: [3, 3, 3],
           elements: tetrahedra}
    material: steel
  plate:
    mesh: {generate: box, min: [0, 0, 0], max: [0.01, 0.008, 0.006], divisions: [8, 6, 3],
           elements: wedges}
    material: aluminium
initial_conditions:
  - {part: block, velocity: [0, 0, -150.0]}
contact:
  - {type: general}
boundary_conditions:
  - {set: plate.zmin, fix: all}
)");
  double max_ep = 0;
  const std::int64_t differing = compare_with_serial(config, &max_ep);
  EXPECT_EQ(differing, 0) << "values differing from the 1-rank run on " << Comm::world().size()
                          << " ranks";
  if (Comm::world().rank() == 0) EXPECT_GT(max_ep, 1e-3); // the block has dented the plate
}

// A rigid punch held in x, y and its rotations and driven down in z into a plastic block,
// in contact: every rank moves the held body the same way.
TEST(Determinism, DrivenRigidPunchSameBitsOnAnyRankCount) {
  const Config config = test::deck(R"(
termination: {cycles: 300}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
  aluminium: {model: j2_plasticity, density: 2700, youngs_modulus: 70.0e9, poissons_ratio: 0.33,
              yield_stress: 1.0e8, hardening_modulus: 1.0e8}
parts:
  punch:
    mesh: {generate: box, min: [0.004, 0.002, 0.0101], max: [0.008, 0.008, 0.014], divisions: [2, 3, 2]}
    material: steel
    rigid: true
  block:
    mesh: {generate: box, min: [0, 0, 0], max: [0.012, 0.01, 0.01], divisions: [12, 10, 6]}
    material: aluminium
contact:
  - {type: general}
boundary_conditions:
  - {set: block.zmin, fix: all}
  - {part: punch, fix: all}
  - {part: punch, velocity: [0, 0, -40.0], components: [z]}
)");
  double max_ep = 0;
  const std::int64_t differing = compare_with_serial(config, &max_ep);
  EXPECT_EQ(differing, 0) << "values differing from the 1-rank run on " << Comm::world().size()
                          << " ranks";
  if (Comm::world().rank() == 0) EXPECT_GT(max_ep, 1e-3); // the punch has dented the block
}

// Eroding contact (examples/eroding_penetration.yaml to 12 us): elements erode on every
// rank's part of the target and the faces they covered join the contact surfaces
// (ContactPhase::set_eroded); the same bits as on one rank, exactly.
TEST(Determinism, ErodingContactSameBitsOnAnyRankCount) {
  Config config = read_deck(std::string(test::source_dir()) + "/examples/eroding_penetration.yaml");
  config.end_time = 1.2e-5;
  double max_ep = 0;
  const std::int64_t differing = compare_with_serial(config, &max_ep);
  EXPECT_EQ(differing, 0) << "values differing from the 1-rank run on " << Comm::world().size()
                          << " ranks";
  if (Comm::world().rank() == 0) EXPECT_GT(max_ep, 0.08); // elements eroded
}

// External loads (loads.cpp): a pressure on a clamped plate, which bends and yields; a
// pressure inside a tube (curved faces, their corners on several ranks) and forces on
// the nodes of its rim, all ramped. The pressures' corner forces travel with the element
// forces and are summed in global element order: the same bits as on one rank, exactly.
TEST(Determinism, LoadsSameBitsOnAnyRankCount) {
  const Config config = test::deck(R"(
termination: {cycles: 150}
materials:
  copper: {model: j2_plasticity, density: 8930, youngs_modulus: 117.0e9,
           poissons_ratio: 0.35, yield_stress: 0.4e9, hardening_modulus: 0.1e9}
parts:
  plate:
    mesh: {generate: box, min: [0, 0, 0], max: [0.02, 0.02, 0.002], divisions: [10, 10, 2]}
    material: copper
  tube:
    mesh: {generate: can, radius: 0.01, height: 0.01, thickness: 0.002, divisions: [24, 5, 2],
           origin: [0.05, 0, 0]}
    material: copper
boundary_conditions:
  - {set: plate.xmin, fix: all}
  - {set: tube.bottom, fix: all}
loads:
  - {surface: plate.zmax, pressure: 2.0e7, curve: [[0, 0], [2.0e-6, 1]]}
  - {surface: tube.inner, pressure: 5.0e8, curve: [[0, 0], [4.0e-6, 1]]}
  - {set: tube.top, force: [0, 20.0, -10.0]}
)");
  double max_ep = 0;
  const std::int64_t differing = compare_with_serial(config, &max_ep);
  EXPECT_EQ(differing, 0) << "values differing from the 1-rank run on " << Comm::world().size()
                          << " ranks";
  if (Comm::world().rank() == 0) EXPECT_GT(max_ep, 1e-3); // the loads made plastic flow
}

// The rigid walls' forces and the boundary conditions' reactions (history columns, not
// diagnostics): a block dragged with friction on one wall and SPH particles striking
// another, the particles' top held in x, their forces every cycle compared with the 1-rank
// run's, exactly (each wall's impulses and each condition's forces are summed in
// ascending node id, then particle id).
TEST(Determinism, WallForcesAndReactionsSameBitsOnAnyRankCount) {
  const char* deck = R"(
termination: {cycles: 120}
materials:
  steel: {model: elastic, density: 7800, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
  al: {model: j2_plasticity, density: 2700, youngs_modulus: 70.0e9, poissons_ratio: 0.33, yield_stress: 0.1e9}
parts:
  blk:
    mesh: {generate: box, min: [0, 0, 0.0], max: [0.01, 0.01, 0.004], divisions: [6, 6, 3]}
    material: steel
particles:
  ball: {generate: {shape: sphere, center: [0.03, 0, 0.0021], radius: 2.0e-3, spacing: 5.0e-4},
         material: al, smoothing_ratio: 1.3}
boundary_conditions:
  - {set: blk.zmax, velocity: [5.0, 2.0, -0.5]}
  - {set: {part: ball, box: {min: [-1, -1, 0.0035], max: [1, 1, 1]}}, fix: [x]}
initial_conditions:
  - {part: blk, velocity: [5.0, 2.0, 0.0]}
  - {part: ball, velocity: [50.0, 0, -300.0]}
rigid_walls:
  - {point: [0, 0, 0], normal: [0, 0, 1], friction: 0.3}
  - {point: [0.03, 0, 0], normal: [0, 0, 1], friction: 0.2}
probes:
  - {name: base, element_at: [0.004, 0.006, 0.0005]}
  - {name: top, element_at: [0.009, 0.001, 0.0035]}
)";
  const Config config = test::deck(deck);
  // Per cycle: the two walls' forces, then the two conditions' six reaction components;
  // the element probes' values are compared apart (their 14 values a cycle).
  std::vector<double> e;
  auto forces = [&](const Comm& comm) {
    Simulation sim(config, comm);
    std::vector<double> f;
    while (!sim.finished()) {
      sim.step();
      const Sample s = sim.sample();
      f.insert(f.end(), s.wall_force.begin(), s.wall_force.end());
      f.insert(f.end(), s.reaction.begin(), s.reaction.end());
      e.insert(e.end(), s.element_probes.begin(), s.element_probes.end());
    }
    return f;
  };
  const std::vector<double> p = forces(Comm::world());
  const std::vector<double> pe = std::exchange(e, {});
  if (Comm::world().rank() != 0) return;
  const std::vector<double> s = forces(Comm::self());
  ASSERT_EQ(pe.size(), e.size());
  std::int64_t differing_e = 0, stressed = 0;
  for (std::size_t k = 0; k < e.size(); ++k) {
    differing_e += !same_bits(pe[k], e[k]);
    stressed += e[k] != 0;
  }
  EXPECT_EQ(differing_e, 0) << "element probe values differing from the 1-rank run";
  EXPECT_GT(stressed, 1000); // of 120 x 14 values (the plastic strains are 0: elastic)
  ASSERT_EQ(p.size(), s.size());
  std::int64_t differing = 0, acting[8] = {};
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (!same_bits(p[k], s[k])) ++differing;
    if (s[k] != 0) ++acting[k % 8];
  }
  EXPECT_EQ(differing, 0) << "wall forces or reactions differing from the 1-rank run";
  EXPECT_GT(acting[0], 50); // both walls act
  EXPECT_GT(acting[1], 10);
  EXPECT_GT(acting[4], 50); // the block's driver in z
  EXPECT_GT(acting[5], 10); // the particles' holder in x
}

} // namespace
