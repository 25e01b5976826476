// anvil's Rcb against Zoltan's RCB on the same points: time, balance, and the fraction of
// points that change rank, for a partition from scratch and for a repartition after a
// small motion. Run under mpirun; prints one JSON object per line and case:
//
//   mpirun -np 4 build/bench/bench_rcb_vs_zoltan [--points N] [--reps R] [--zoltan-tol T]
//
// Cases: `uniform` (unit cube), `clustered` (five Gaussian clusters of different sizes on a
// thin uniform background), `can` (the node cloud of a thin cylindrical shell, radius 0.03 m,
// height 0.1 m, two node layers through a 1 mm wall, axially crushed by 4% with folds
// growing from the crushed end); `CASE_repartition`: the same after each partitioner's own
// points were moved to their owners and then moved slightly (0.2% more crush and fold growth
// for the can; a smooth drift of 0.1% of the extent plus a 0.02% jitter for the others).
//
// Initially rank r holds the points with gid = r mod P (scattered). Times are the minimum
// over reps of the slowest rank's wall time for the partition call only (Rcb::partition
// giving an owner per point; Zoltan_LB_Partition giving export lists); moving the data is
// the same Migration for both and not timed. Imbalance is max count / mean count;
// migrated fraction is the fraction of all points whose owner differs from their holder.
// Zoltan runs with IMBALANCE_TOL (default 1.0: its best balance), CHECK_GEOM 0 (no
// self-check), KEEP_CUTS 1, RCB_REUSE 1 and RCB_LOCK_DIRECTIONS 1 (its incremental mode).
//
// Zoltan's interface takes an MPI communicator: this file passes MPI_COMM_WORLD (from
// zoltan.h's own include of mpi.h) to Zoltan only; everything of anvil goes through Comm.
#include <zoltan.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "anvil/parallel/comm.hpp"
#include "anvil/parallel/migration.hpp"
#include "anvil/parallel/rcb.hpp"

namespace {

using namespace anvil;

std::uint64_t mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}
double unit(std::int64_t gid, int stream) {
  return static_cast<double>(mix(static_cast<std::uint64_t>(gid) * 16 + stream) >> 11) * 0x1p-53;
}
// Standard normal from two uniforms (Box-Muller).
double normal(std::int64_t gid, int stream) {
  const double u = std::max(unit(gid, stream), 1e-300), v = unit(gid, stream + 1);
  return std::sqrt(-2 * std::log(u)) * std::cos(2 * M_PI * v);
}

// A point set defined by gid: position of point g at stage 0 (initial) or 1 (moved).
struct Case {
  std::string name;
  std::int64_t points = 0;
  std::function<Vec3(std::int64_t, int)> position;
};

Case uniform_case(std::int64_t n) {
  return {"uniform", n, [](std::int64_t g, int stage) {
            Vec3 p{unit(g, 0), unit(g, 1), unit(g, 2)};
            if (stage > 0) {
              p += Vec3{std::sin(2 * M_PI * p.y), std::sin(2 * M_PI * p.z),
                        std::sin(2 * M_PI * p.x)} *
                   1e-3;
              p += Vec3{unit(g, 3) - 0.5, unit(g, 4) - 0.5, unit(g, 5) - 0.5} * 4e-4;
            }
            return p;
          }};
}

Case clustered_case(std::int64_t n) {
  return {"clustered", n, [](std::int64_t g, int stage) {
            static constexpr double c[5][4] = {{0.2, 0.3, 0.4, 0.05},
                                               {0.7, 0.6, 0.5, 0.10},
                                               {0.4, 0.8, 0.2, 0.02},
                                               {0.8, 0.2, 0.8, 0.07},
                                               {0.3, 0.4, 0.9, 0.03}};
            static constexpr double share[5] = {0.30, 0.25, 0.15, 0.12, 0.08}; // rest: background
            const double u = unit(g, 0);
            double acc = 0;
            Vec3 p{unit(g, 1), unit(g, 2), unit(g, 3)};
            for (int k = 0; k < 5; ++k) {
              acc += share[k];
              if (u < acc) {
                p = Vec3{c[k][0] + c[k][3] * normal(g, 4), c[k][1] + c[k][3] * normal(g, 6),
                         c[k][2] + c[k][3] * normal(g, 8)};
                if (stage > 0) p += Vec3{1e-3 * (k - 2), 5e-4 * (2 - k), 1e-3};
                break;
              }
            }
            if (stage > 0)
              p += Vec3{unit(g, 10) - 0.5, unit(g, 11) - 0.5, unit(g, 12) - 0.5} * 4e-4;
            return p;
          }};
}

// Nodes of the can: 2 layers x nt around x nz along, about n in all.
Case can_case(std::int64_t n) {
  const double R = 0.03, H = 0.1, wall = 1e-3;
  const auto nz = static_cast<std::int64_t>(std::llround(std::sqrt(n / 2.0 * H / (2 * M_PI * R))));
  const std::int64_t nt = std::max<std::int64_t>(3, (n / 2) / std::max<std::int64_t>(nz, 1));
  return {"can", 2 * nt * nz, [=](std::int64_t g, int stage) {
            const std::int64_t layer = g % 2, it = (g / 2) % nt, iz = g / (2 * nt);
            const double th = 2 * M_PI * it / nt, z0 = H * iz / (nz - 1);
            const double r0 = R - wall / 2 + wall * layer;
            const double crush = 0.04 + 0.002 * stage;     // axial shortening
            const double amp = 1.5e-3 * (1 + 0.1 * stage); // fold amplitude
            // Folds (wavelength 12 mm) strongest at the crushed top end, with a diamond
            // (5-lobe) modulation; the crushed length is taken up by the folds.
            const double env = std::exp(-(H - z0) / 0.03);
            const double r =
                r0 + amp * env * std::sin(2 * M_PI * z0 / 0.012) * (1 + 0.3 * std::cos(5 * th));
            const double z = z0 * (1 - crush) - 0.5 * amp * env * std::cos(2 * M_PI * z0 / 0.012);
            return Vec3{r * std::cos(th), r * std::sin(th), z};
          }};
}

// This rank's points (SoA) with their gids.
struct Local {
  std::vector<double> x, y, z;
  std::vector<std::int64_t> gid;
  RcbPoints view() const { return {x, y, z, gid, {}}; }
  std::size_t size() const { return gid.size(); }
  void place(const Case& c, int stage) {
    for (std::size_t i = 0; i < gid.size(); ++i) {
      const Vec3 p = c.position(gid[i], stage);
      x[i] = p.x;
      y[i] = p.y;
      z[i] = p.z;
    }
  }
  // Moves the points to dest (their new owners).
  void migrate(const Comm& comm, std::span<const int> dest) {
    Migration plan;
    plan.build(comm, dest);
    std::vector<double> t;
    plan.forward(x, t);
    x.swap(t);
    plan.forward(y, t);
    y.swap(t);
    plan.forward(z, t);
    z.swap(t);
    std::vector<std::int64_t> g;
    plan.forward(gid, g);
    gid.swap(g);
  }
};

Local initial(const Case& c, const Comm& comm) {
  Local l;
  for (std::int64_t g = comm.rank(); g < c.points; g += comm.size()) l.gid.push_back(g);
  l.x.resize(l.size());
  l.y.resize(l.size());
  l.z.resize(l.size());
  l.place(c, 0);
  return l;
}

// ---- Zoltan --------------------------------------------------------------------------
int z_num_obj(void* data, int* ierr) {
  *ierr = ZOLTAN_OK;
  return static_cast<int>(static_cast<Local*>(data)->size());
}
void z_obj_list(void* data, int, int, ZOLTAN_ID_PTR gids, ZOLTAN_ID_PTR lids, int, float*,
                int* ierr) {
  const Local& l = *static_cast<Local*>(data);
  for (std::size_t i = 0; i < l.size(); ++i) {
    gids[i] = static_cast<ZOLTAN_ID_TYPE>(l.gid[i]);
    lids[i] = static_cast<ZOLTAN_ID_TYPE>(i);
  }
  *ierr = ZOLTAN_OK;
}
int z_num_geom(void*, int* ierr) {
  *ierr = ZOLTAN_OK;
  return 3;
}
void z_geom_multi(void* data, int, int, int n, ZOLTAN_ID_PTR, ZOLTAN_ID_PTR lids, int, double* xyz,
                  int* ierr) {
  const Local& l = *static_cast<Local*>(data);
  for (int k = 0; k < n; ++k) {
    const std::size_t i = lids[k];
    xyz[3 * k] = l.x[i];
    xyz[3 * k + 1] = l.y[i];
    xyz[3 * k + 2] = l.z[i];
  }
  *ierr = ZOLTAN_OK;
}

struct Zoltan {
  Zoltan_Struct* zz = nullptr;
  Zoltan(Local& l, const std::string& tol) {
    zz = Zoltan_Create(MPI_COMM_WORLD);
    Zoltan_Set_Param(zz, "DEBUG_LEVEL", "0");
    Zoltan_Set_Param(zz, "LB_METHOD", "RCB");
    Zoltan_Set_Param(zz, "NUM_GID_ENTRIES", "1");
    Zoltan_Set_Param(zz, "NUM_LID_ENTRIES", "1");
    Zoltan_Set_Param(zz, "OBJ_WEIGHT_DIM", "0");
    Zoltan_Set_Param(zz, "RETURN_LISTS", "EXPORT");
    Zoltan_Set_Param(zz, "IMBALANCE_TOL", tol.c_str());
    Zoltan_Set_Param(zz, "CHECK_GEOM", "0");
    Zoltan_Set_Param(zz, "KEEP_CUTS", "1");
    Zoltan_Set_Param(zz, "RCB_REUSE", "1");
    Zoltan_Set_Param(zz, "RCB_LOCK_DIRECTIONS", "1");
    Zoltan_Set_Param(zz, "RCB_OUTPUT_LEVEL", "0");
    Zoltan_Set_Num_Obj_Fn(zz, z_num_obj, &l);
    Zoltan_Set_Obj_List_Fn(zz, z_obj_list, &l);
    Zoltan_Set_Num_Geom_Fn(zz, z_num_geom, &l);
    Zoltan_Set_Geom_Multi_Fn(zz, z_geom_multi, &l);
  }
  ~Zoltan() { Zoltan_Destroy(&zz); }
  Zoltan(const Zoltan&) = delete;
  Zoltan& operator=(const Zoltan&) = delete;

  // Partitions; returns the owner of each local point.
  std::vector<int> partition(std::size_t n, int me) {
    int changes, ngid, nlid, nimp, nexp;
    ZOLTAN_ID_PTR igid, ilid, egid, elid;
    int *iproc, *ipart, *eproc, *epart;
    if (Zoltan_LB_Partition(zz, &changes, &ngid, &nlid, &nimp, &igid, &ilid, &iproc, &ipart, &nexp,
                            &egid, &elid, &eproc, &epart) != ZOLTAN_OK) {
      std::fprintf(stderr, "Zoltan_LB_Partition failed\n");
      std::exit(1);
    }
    std::vector<int> dest(n, me);
    for (int k = 0; k < nexp; ++k) dest[elid[k]] = eproc[k];
    Zoltan_LB_Free_Part(&igid, &ilid, &iproc, &ipart);
    Zoltan_LB_Free_Part(&egid, &elid, &eproc, &epart);
    return dest;
  }
};

// ---- measurement ------------------------------------------------------------------------
struct Result {
  double seconds = 1e300, imbalance = 0, migrated = 0;
  int iterations = 0;
};

// Imbalance and migrated fraction of an assignment.
void assess(const Comm& comm, std::span<const int> dest, std::int64_t total, Result& r) {
  std::vector<std::int64_t> count(static_cast<std::size_t>(comm.size()) + 1, 0);
  for (int d : dest) {
    ++count[static_cast<std::size_t>(d)];
    count.back() += d != comm.rank();
  }
  comm.sum(std::span<std::int64_t>(count));
  const std::int64_t mx = *std::max_element(count.begin(), count.end() - 1);
  r.imbalance = static_cast<double>(mx) / (static_cast<double>(total) / comm.size());
  r.migrated = static_cast<double>(count.back()) / static_cast<double>(total);
}

template <class F>
double timed(const Comm& comm, F&& f) {
  comm.barrier();
  const auto t0 = std::chrono::steady_clock::now();
  f();
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return comm.max(s);
}

void print(const Comm& comm, const std::string& name, std::int64_t points, const Result& a,
           const Result& z, const nlohmann::json& extra) {
  if (comm.rank() != 0) return;
  nlohmann::json j = {{"case", name},
                      {"points", points},
                      {"ranks", comm.size()},
                      {"anvil_seconds", a.seconds},
                      {"zoltan_seconds", z.seconds},
                      {"anvil_imbalance", a.imbalance},
                      {"zoltan_imbalance", z.imbalance},
                      {"anvil_migrated_fraction", a.migrated},
                      {"zoltan_migrated_fraction", z.migrated},
                      {"anvil_iterations", a.iterations}};
  j.update(extra);
  std::printf("%s\n", j.dump().c_str());
  std::fflush(stdout);
}

void run_case(const Comm& comm, const Case& c, int reps, const std::string& tol) {
  Result a0, z0, a1, z1, a1s;
  for (int rep = 0; rep < reps; ++rep) {
    // anvil: scratch, move to owners, move slightly, incremental (and scratch, for the
    // iteration count) repartition.
    {
      Local l = initial(c, comm);
      Rcb rcb(comm);
      a0.seconds = std::min(a0.seconds, timed(comm, [&] { rcb.partition(l.view()); }));
      assess(comm, rcb.destinations(), c.points, a0);
      a0.iterations = rcb.stats().total_iterations;
      l.migrate(comm, rcb.destinations());
      l.place(c, 1);
      Rcb fresh(comm);
      a1s.seconds = std::min(a1s.seconds, timed(comm, [&] { fresh.partition(l.view()); }));
      assess(comm, fresh.destinations(), c.points, a1s);
      a1s.iterations = fresh.stats().total_iterations;
      a1.seconds = std::min(a1.seconds, timed(comm, [&] { rcb.repartition(l.view()); }));
      assess(comm, rcb.destinations(), c.points, a1);
      a1.iterations = rcb.stats().total_iterations;
    }
    // Zoltan: the same sequence on its own decomposition.
    {
      Local l = initial(c, comm);
      Zoltan z(l, tol);
      std::vector<int> dest;
      z0.seconds =
          std::min(z0.seconds, timed(comm, [&] { dest = z.partition(l.size(), comm.rank()); }));
      assess(comm, dest, c.points, z0);
      l.migrate(comm, dest);
      l.place(c, 1);
      z1.seconds =
          std::min(z1.seconds, timed(comm, [&] { dest = z.partition(l.size(), comm.rank()); }));
      assess(comm, dest, c.points, z1);
    }
  }
  print(comm, c.name, c.points, a0, z0, {{"zoltan_imbalance_tol", tol}});
  print(comm, c.name + "_repartition", c.points, a1, z1,
        {{"zoltan_imbalance_tol", tol},
         {"anvil_scratch_seconds", a1s.seconds},
         {"anvil_scratch_iterations", a1s.iterations},
         {"anvil_scratch_migrated_fraction", a1s.migrated}});
}

} // namespace

int main(int argc, char** argv) {
  MpiSession mpi(&argc, &argv);
  const Comm comm = Comm::world();
  std::int64_t points = 1000000;
  int reps = 3;
  std::string tol = "1.0";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--points" && i + 1 < argc)
      points = std::atoll(argv[++i]);
    else if (a == "--reps" && i + 1 < argc)
      reps = std::atoi(argv[++i]);
    else if (a == "--zoltan-tol" && i + 1 < argc)
      tol = argv[++i];
    else {
      if (comm.rank() == 0)
        std::fprintf(stderr, "usage: %s [--points N] [--reps R] [--zoltan-tol T]\n", argv[0]);
      return 2;
    }
  }
  if (points < 1 || reps < 1) {
    if (comm.rank() == 0) std::fprintf(stderr, "--points and --reps must be positive\n");
    return 2;
  }
  float version = 0;
  if (Zoltan_Initialize(argc, argv, &version) != ZOLTAN_OK) {
    std::fprintf(stderr, "Zoltan_Initialize failed\n");
    return 1;
  }
  for (const Case& c : {uniform_case(points), clustered_case(points), can_case(points)})
    run_case(comm, c, reps, tol);
  return 0;
}
