// Writes the data of the RCB picture (the paper's Figure 1) as JSON: a 2-D point cloud
// (z = 0) partitioned over the ranks of the run, with every point's owner, every cut with
// its level and the segment it draws inside its node's box, and every rank's box, all
// clipped to the points' bounding box. tools/plot_rcb.py draws it.
//
//   mpirun -np 8 build/bench/rcb_dump OUT.json [--points N]
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "anvil/parallel/comm.hpp"
#include "anvil/parallel/migration.hpp"
#include "anvil/parallel/rcb.hpp"
#include "anvil/parallel/rcb_statistics.hpp"

namespace {

using namespace anvil;

std::uint64_t mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}
double unit(std::int64_t g, int s) {
  return static_cast<double>(mix(static_cast<std::uint64_t>(g) * 4 + s) >> 11) * 0x1p-53;
}

// An irregular 2-D body like the paper's: a tilted ellipse with a denser round lobe,
// points drawn by rejection from their union.
Vec3 point(std::int64_t g) {
  for (int k = 0;; ++k) {
    const double x = 3 * unit(g * 64 + k, 0), y = 2 * unit(g * 64 + k, 1);
    const double u = (x - 1.3) * 0.8 + (y - 0.9) * 0.6, v = -(x - 1.3) * 0.6 + (y - 0.9) * 0.8;
    const bool ellipse = u * u / 1.4 + v * v / 0.35 < 1;
    const bool lobe = (x - 2.3) * (x - 2.3) + (y - 1.5) * (y - 1.5) < 0.2;
    if ((ellipse && unit(g * 64 + k, 2) < 0.6) || lobe) return {x, y, 0.0};
  }
}

// Every cut with the segment it draws: the node's box (clipped to the domain) split at
// the cut's value.
void cuts_json(const Rcb& rcb, int a, int b, Box3 box, nlohmann::json& out) {
  if (b - a < 2) return;
  const int m = Rcb::split(a, b);
  const RcbCut& c = rcb.cuts()[static_cast<std::size_t>(m)];
  Box3 seg = box;
  seg.lo[c.dim] = seg.hi[c.dim] = c.value;
  out.push_back({{"split", m},
                 {"level", c.level},
                 {"dim", c.dim},
                 {"value", c.value},
                 {"from", {seg.lo.x, seg.lo.y}},
                 {"to", {seg.hi.x, seg.hi.y}}});
  Box3 lo = box, hi = box;
  lo.hi[c.dim] = c.value;
  hi.lo[c.dim] = c.value;
  cuts_json(rcb, a, m, lo, out);
  cuts_json(rcb, m, b, hi, out);
}

} // namespace

int main(int argc, char** argv) {
  MpiSession mpi(&argc, &argv);
  const Comm comm = Comm::world();
  if (argc < 2) {
    if (comm.rank() == 0) std::fprintf(stderr, "usage: %s OUT.json [--points N]\n", argv[0]);
    return 2;
  }
  const std::string out = argv[1];
  std::int64_t n = 600;
  if (argc == 4 && std::string(argv[2]) == "--points") n = std::atoll(argv[3]);

  // Points scattered over the ranks by gid, as any holder would do.
  std::vector<double> x, y, z;
  std::vector<std::int64_t> gid;
  for (std::int64_t g = comm.rank(); g < n; g += comm.size()) {
    const Vec3 p = point(g);
    x.push_back(p.x);
    y.push_back(p.y);
    z.push_back(p.z);
    gid.push_back(g);
  }
  Rcb rcb(comm);
  rcb.partition({x, y, z, gid, {}});

  // Gather points and owners on rank 0 (a Migration to rank 0).
  std::vector<int> owner(rcb.destinations().begin(), rcb.destinations().end());
  Migration plan;
  plan.build(comm, std::vector<int>(gid.size(), 0));
  std::vector<double> gx, gy;
  std::vector<int> gowner;
  plan.forward(x, gx);
  plan.forward(y, gy);
  plan.forward(owner, gowner);
  if (comm.rank() != 0) return 0;

  nlohmann::json j = rcb_statistics(rcb);
  nlohmann::json pts = nlohmann::json::array();
  for (std::size_t i = 0; i < gx.size(); ++i) pts.push_back({gx[i], gy[i], gowner[i]});
  j["points_xy_owner"] = pts;
  nlohmann::json cuts = nlohmann::json::array();
  cuts_json(rcb, 0, comm.size(), rcb.domain(), cuts);
  j["cut_segments"] = cuts;
  std::ofstream f(out);
  f << j.dump(1) << "\n";
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", out.c_str());
    return 1;
  }
  std::printf("wrote %s: %zu points, %d ranks, %d iterations\n", out.c_str(), gx.size(),
              comm.size(), rcb.stats().total_iterations);
  return 0;
}
