// Particle phase microbenchmark: one SPH cycle step 2 (decomposition upkeep, ghosts,
// cell-list neighbour search, both passes with the material update) on one rank, for a
// cube of particles at rest plus a shearing, compressing velocity field, ~50 neighbours
// per particle in 3-D (h = 1.145 spacing: (4/3) pi (2h)^3 / s^3 - 1 = 50). Reported as
// ns per particle per step (counter `ns_per_particle`), also the mean neighbour count.
// The particles do not move between the steps, so the candidate (Verlet) lists are built
// once, in the fixture: the figure is that of a step that reuses them (docs/sph.md gives
// the cost of a build and how often a moving model rebuilds).
// Goal (docs/sph.md): at most 400 ns on one core.
#include <benchmark/benchmark.h>

#include <memory>

#include <fmt/format.h>

#include "anvil/io/deck.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/sph/sph_phase.hpp"

namespace {

using namespace anvil;

struct Fixture {
  Config config;
  std::unique_ptr<Material> material;
  std::unique_ptr<sph::SphPhase> phase;
  PhaseTimers timers;

  Fixture(const Comm& comm, int n, const std::string& model, double epsilon) {
    const double s = 1e-3;
    config = parse_deck(fmt::format(R"(
termination: {{cycles: 1}}
materials:
  m: {{model: {}, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3{}}}
particles:
  cube: {{generate: {{shape: box, min: [0, 0, 0], max: [{}, {}, {}], spacing: {}}},
          material: m, smoothing_ratio: 1.145, artificial_stress: {{epsilon: {}}}}}
)",
                                    model, model == "elastic" ? "" : ", yield_stress: 250.0e6",
                                    n * s, n * s, n * s, s, epsilon),
                        "bench.yaml", ".");
    const auto& mc = config.materials[0];
    material = make_material(mc.model, mc.params, mc.tables, "", {});
    phase = std::make_unique<sph::SphPhase>(
        config, [&](int) { return material.get(); }, comm);
    auto& pt = phase->particles();
    for (std::size_t i = 0; i < pt.size(); ++i) {
      const double x = pt.x[0][i], y = pt.x[1][i], z = pt.x[2][i];
      pt.v[0][i] = -50.0 * x + 20.0 * y;
      pt.v[1][i] = 10.0 * z;
      pt.v[2][i] = -80.0 * z + 5.0 * x * y;
    }
    phase->forces(0.0, timers); // first cycle: buffers grow
  }
};

void run(benchmark::State& state, const std::string& model, double epsilon) {
  const Comm self = Comm::self();
  Fixture f(self, static_cast<int>(state.range(0)), model, epsilon);
  for (auto _ : state) {
    f.phase->forces(1e-9, f.timers);
    benchmark::ClobberMemory();
  }
  const double n = static_cast<double>(f.phase->particles().size());
  state.counters["particles"] = n;
  // Each pair once (one rank: no ghosts), two neighbour entries.
  state.counters["neighbours"] = 2.0 * static_cast<double>(f.phase->stats().pairs) / n;
  // Seconds per (1e-9 particle) per iteration = ns per particle per step (CPU time).
  state.counters["ns_per_particle"] = benchmark::Counter(
      n * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_SphPhase_Elastic(benchmark::State& s) {
  run(s, "elastic", 0.0);
}
void BM_SphPhase_Elastic_ArtificialStress(benchmark::State& s) {
  run(s, "elastic", 0.3);
}
void BM_SphPhase_J2(benchmark::State& s) {
  run(s, "j2_plasticity", 0.0);
}

BENCHMARK(BM_SphPhase_Elastic)->Arg(20)->Arg(32)->Arg(48)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SphPhase_Elastic_ArtificialStress)->Arg(32)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SphPhase_J2)->Arg(20)->Arg(32)->Unit(benchmark::kMillisecond);

} // namespace

int main(int argc, char** argv) {
  anvil::MpiSession mpi(&argc, &argv);
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
