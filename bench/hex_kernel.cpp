// Element kernel microbenchmark: the FE phase of one cycle (element kernel with a
// material, hourglass, stress update, corner forces, nodal gather) on a block of
// hexahedra, reported in ns per element per cycle.
#include <benchmark/benchmark.h>

#include "anvil/fe/hex_block.hpp"
#include "anvil/material/material.hpp"
#include "anvil/mesh/generators.hpp"
#include "anvil/parallel/fe_decomposition.hpp"

namespace {

using namespace anvil;

struct Fixture {
  Mesh mesh;
  FeDecomposition fe;
  std::unique_ptr<Material> material;
  HexBlock block;
  std::array<std::vector<double>, 3> x, v, f;
  std::array<CornerArray, 3> corner;
  HexWorkspace work;

  Fixture(int n, const std::string& model, HourglassControl::Model hg, int thick_shell_points = 0) {
    mesh = generate_box({{0, 0, 0}, {0.1, 0.1, 0.1}, {n, n, n}});
    fe = decompose_fe(mesh, std::vector<int>(static_cast<std::size_t>(mesh.num_elements()), 0), 0,
                      1);
    ParamValues p{{"density", 7850},
                  {"youngs_modulus", 200e9},
                  {"poissons_ratio", 0.3},
                  {"yield_stress", 250e6},
                  {"hardening_modulus", 1e9}};
    material = find_material_model(model)->make(p, {});
    block.material = material.get();
    block.hourglass.model = hg;
    block.thick_shell.points = thick_shell_points;
    const std::size_t nn = fe.node_gid.size();
    for (int i = 0; i < 3; ++i) x[i].resize(nn);
    for (std::size_t k = 0; k < nn; ++k)
      for (int i = 0; i < 3; ++i) x[i][k] = mesh.nodes[fe.node_gid[k]][i];
    const double* xs[3] = {x[0].data(), x[1].data(), x[2].data()};
    block.init(fe.blocks[0].gid, fe.blocks[0].conn, xs, 0);
    block.corner_rows = fe.blocks[0].exchanged_vectors; // as Simulation: none on one rank
    for (int i = 0; i < 3; ++i) {
      v[i].resize(nn);
      f[i].resize(nn);
      corner[i].assign(fe.total_slots(), 0.0);
    }
    for (std::size_t k = 0; k < nn; ++k) {
      const Vec3 p = mesh.nodes[fe.node_gid[k]];
      // A compressive, shearing velocity field that drives every element plastic.
      v[0][k] = -50.0 * p.x + 20.0 * p.y;
      v[1][k] = 10.0 * p.z;
      v[2][k] = -80.0 * p.z + 5.0 * p.x * p.y;
    }
  }

  void cycle(double dt) {
    const NodalView nv{{x[0].data(), x[1].data(), x[2].data()},
                       {v[0].data(), v[1].data(), v[2].data()}};
    const CornerView cv{{corner[0].data(), corner[1].data(), corner[2].data()}};
    HexResult r;
    // As Simulation::fe_forces: the nodal sums in the kernel, the gather for the nodes
    // shared with other ranks (none here).
    work.begin_nodal_forces(static_cast<int>(fe.node_gid.size()));
    hex_forces(block, nv, dt, cv, work, r);
    double* const fs[3] = {f[0].data(), f[1].data(), f[2].data()};
    work.end_nodal_forces(fs);
    gather_corners(fe, {corner[0].data(), corner[1].data(), corner[2].data()},
                   {f[0].data(), f[1].data(), f[2].data()}, fe.exchanged_nodes);
    benchmark::DoNotOptimize(r.dt_stable);
  }
};

void run(benchmark::State& state, const std::string& model, HourglassControl::Model hg,
         int thick_shell_points = 0) {
  Fixture fx(static_cast<int>(state.range(0)), model, hg, thick_shell_points);
  for (auto _ : state) fx.cycle(1e-9);
  const double elements = static_cast<double>(fx.block.size());
  // (elements * 1e-9 per iteration)^-1 over the measured time: ns per element per cycle.
  state.counters["ns_per_element"] = benchmark::Counter(
      elements * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.SetItemsProcessed(static_cast<std::int64_t>(elements) * state.iterations());
}

void BM_FePhase_J2_Viscous(benchmark::State& s) {
  run(s, "j2_plasticity", HourglassControl::Model::viscous);
}
void BM_FePhase_J2_Stiffness(benchmark::State& s) {
  run(s, "j2_plasticity", HourglassControl::Model::stiffness);
}
void BM_FePhase_J2_AssumedStrain(benchmark::State& s) {
  run(s, "j2_plasticity", HourglassControl::Model::assumed_strain);
}
// The thick shell (three points through each element's zeta direction; the can crush's
// wall element). On these cubes zeta is as thin as the other directions: the cost is the
// same as on a wall.
void BM_FePhase_J2_ThickShell3(benchmark::State& s) {
  run(s, "j2_plasticity", HourglassControl::Model::assumed_strain, 3);
}
void BM_FePhase_Elastic_Viscous(benchmark::State& s) {
  run(s, "elastic", HourglassControl::Model::viscous);
}

BENCHMARK(BM_FePhase_J2_Viscous)->Arg(20)->Arg(47)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FePhase_J2_Stiffness)->Arg(47)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FePhase_J2_AssumedStrain)->Arg(47)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FePhase_J2_ThickShell3)->Arg(47)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FePhase_Elastic_Viscous)->Arg(47)->Unit(benchmark::kMillisecond);

} // namespace

BENCHMARK_MAIN();
