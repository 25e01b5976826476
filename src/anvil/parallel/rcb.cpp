// RCB: how the cuts are found.
//
// The paper's scheme moves data at every level: after a cut, each rank sends its points
// on the far side to a partner in the other half, and each half recurses on its own
// sub-communicator. We compute the same cuts without moving any point until the end:
// every point stays on the rank that holds it, tagged (by its position in a work array)
// with the tree node it currently belongs to, and all nodes of one level search for their
// medians at once, with one slot per node in each reduction over the whole communicator.
// A cut depends only on the global set of points in its node and on its target, not on
// where those points are held, so the cuts are identical. Points then move once (by a
// Migration plan built from destinations()), not log2(P) times, and an incremental
// repartition moves only the points whose owner changed.
//
// The median search of a node (one "iteration" = one round of reductions):
//  - Target. The ranks [a, b) split at m; the lower side should carry the cumulative
//    weight C(m) = m W / P of all ranks below m (W the total): floor(m N / P) points with
//    unit weights. The node's target is C(m) minus the weight of all nodes left of it, so
//    errors do not accumulate down the tree: every rank boundary is placed independently,
//    each rank gets floor or ceil of N/P points, or within one point weight of W/P.
//  - Order. Points are ordered by (coordinate along the cut direction, global id). The
//    split takes the prefix of that order whose weight is closest to the target (ties to
//    the shorter prefix). The search looks for the "crossing point", the first point whose
//    inclusion takes the prefix weight above the target, then keeps or drops it.
//  - Probes. A round counts the node's undetermined points U against up to 15 sorted probe
//    values (16 bins): weight, count, minimum and maximum per bin, summed or maxed over all
//    ranks. The bin holding the crossing point becomes the new U, bins below it are lower,
//    bins above are upper; the exact extremes of the new U bound the next probes. From
//    scratch the first probes divide the node's bounding box evenly (the midpoint, the
//    paper's first guess, is one of them); incrementally they spread geometrically around
//    the previous cut. Later probes interpolate the crossing's position in U and bracket it
//    by its statistical spread; when a round fails to shrink U four-fold, the next divides
//    U's extent evenly instead, so pathological distributions still converge.
//  - Ties. When U collapses to points that share one coordinate, the same search runs on
//    their global ids, so the split is exact and the same on every run.
//  - Work per round is over U only: after the first round U is compacted into a separate
//    array, so a level costs about two passes over the points plus small rounds.
#include "anvil/parallel/rcb.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace anvil {

namespace {

constexpr int kMaxProbes = 15;
constexpr int kMaxBins = kMaxProbes + 1;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::int64_t kMaxGid = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kMinGid = std::numeric_limits<std::int64_t>::min();

// A local point in the work array. Points of a node are contiguous.
template <bool Weighted>
struct Item;
template <>
struct Item<false> {
  double x[3];
  std::int64_t idx; // index in the caller's arrays
};
template <>
struct Item<true> {
  double x[3];
  double w;
  std::int64_t idx;
};

// An undetermined point of a node's search: its key along the cut, its weight, and the
// caller index (replaced by the global id when the search turns to ties).
struct Cand {
  double c;
  double w;
  std::int64_t id;
};

// Grow-only storage without value-initialisation: the work arrays are always written
// before they are read, and zero-filling them would cost a pass over memory per call.
template <class T>
class Buffer {
public:
  void grow(std::size_t n) {
    if (n > capacity_) {
      data_.reset(new T[n]); // default-initialised: trivial T stays unwritten
      capacity_ = n;
    }
  }
  T* data() { return data_.get(); }
  T& operator[](std::size_t i) { return data_[i]; }

private:
  std::unique_ptr<T[]> data_;
  std::size_t capacity_ = 0;
};

enum class Phase { First, Coord, Gid, Done };

// One tree node during the level that cuts it. Search fields are identical on all ranks
// (they derive from reduced values only); begin/end/nu are local.
struct Node {
  int a = 0, b = 0, m = 0; // ranks [a, b), split at m
  int dim = 0;
  std::int64_t begin = 0, end = 0; // local range in the work arrays
  std::int64_t nu = 0;             // local undetermined points (in cand[begin, begin + nu))
  double offset = 0;               // global weight of the nodes left of this one
  double lo[3] = {kInf, kInf, kInf}, hi[3] = {-kInf, -kInf, -kInf}; // points' bounding box
  Box3 geom;                               // node's box clipped to the domain (for empty nodes)
  double guess = 0, spacing = 0;           // previous cut and point spacing (incremental)
  std::int64_t guess_gid = RcbCut::kNoTie; // previous tie-breaking gid (incremental)
  bool incremental = false;

  Phase phase = Phase::First;
  double W = 0, N = 0, T = 0;       // node weight and count, lower target
  double WL = 0, NL = 0;            // determined lower weight and count
  double WU = 0, NU = 0;            // undetermined weight and count
  double A = 0, B = 0;              // coordinate extremes of U (coordinate phases)
  std::int64_t GA = 0, GB = 0;      // gid extremes of U (gid phases)
  double lmax = -kInf;              // largest coordinate of determined lower points
  double umin = kInf;               // smallest coordinate of determined upper points
  double tie = 0;                   // coordinate shared by U (gid phases)
  std::int64_t gumin = kMaxGid;     // smallest gid of upper points at `tie`
  bool tie_lower = false;           // some points at `tie` are lower
  bool tie_upper = false;           // some points at `tie` are upper
  bool bisect = false;              // next probes divide U's extent evenly
  bool have_gids = false;           // cand ids hold gids (caller indices before)
  int np = 0;                       // number of probes
  double pc[kMaxProbes] = {};       // coordinate probes (padded with +inf)
  std::int64_t pg[kMaxProbes] = {}; // gid probes
  double cut = 0;
  std::int64_t cut_gid = RcbCut::kNoTie;
  bool take_u = false; // U ends on the lower side
};

// Per-bin tallies of one node in one round, local then global.
struct Tally {
  double w[kMaxBins], n[kMaxBins], mn[kMaxBins], mx[kMaxBins];
  std::int64_t gmn[kMaxBins], gmx[kMaxBins];
  void clear() {
    for (int j = 0; j < kMaxBins; ++j) {
      w[j] = n[j] = 0;
      mn[j] = kInf;
      mx[j] = -kInf;
      gmn[j] = kMaxGid;
      gmx[j] = kMinGid;
    }
  }
};

// A plane between the largest lower coordinate l and the smallest upper one u, so that
// l < cut <= u: halfway when both exist (nicer boxes, and a stable first guess later).
double cut_between(double l, double u) {
  if (l == -kInf) return u;
  if (u == kInf) return std::nextafter(l, kInf);
  double m = 0.5 * l + 0.5 * u;
  if (!(m > l) || m > u) m = u;
  return m;
}

// Sorts, clamps into (A, B], removes duplicates and pads coordinate probes; returns their
// number. At least one probe remains when A < B, so every round shrinks U.
int finish_probes(double* p, int n, double A, double B) {
  const double lo = std::nextafter(A, kInf);
  for (int j = 0; j < n; ++j) p[j] = std::clamp(p[j], lo, B);
  std::sort(p, p + n);
  n = static_cast<int>(std::unique(p, p + n) - p);
  for (int j = n; j < kMaxProbes; ++j) p[j] = kInf;
  return n;
}

// Probes dividing [A, B] evenly: 15, or count - 1 when U holds fewer points (count).
int uniform_probes(double* p, double A, double B, double count) {
  const int n = static_cast<int>(std::min<double>(kMaxProbes, std::max(1.0, count - 1)));
  for (int j = 0; j < n; ++j) p[j] = A + (B - A) * (j + 1) / (n + 1);
  return finish_probes(p, n, A, B);
}

// Probes bracketing the interpolated position of the crossing point: U holds NU points of
// weight WU between A and B, and the crossing is after weight t of them. For points
// spread evenly the position's fraction has standard deviation sqrt(f (1 - f) / NU);
// the probes cover +-16 of those with the finest spacing near the estimate.
int interpolated_probes(double* p, double A, double B, double t, double WU, double NU) {
  static constexpr double s[kMaxProbes] = {-16,  -8,  -4, -2, -1, -0.5, -0.25, 0,
                                           0.25, 0.5, 1,  2,  4,  8,    16};
  const double f = std::clamp((t + 0.5 * WU / NU) / WU, 0.0, 1.0);
  const double sigma = std::max(std::sqrt(f * (1 - f) / NU), 1.0 / NU);
  const double e = A + f * (B - A), d = sigma * (B - A);
  for (int j = 0; j < kMaxProbes; ++j) p[j] = e + s[j] * d;
  return finish_probes(p, kMaxProbes, A, B);
}

// Incremental first probes: the previous cut and geometric steps of the previous point
// spacing on both sides, so a small drift is bracketed in one round and a large one in
// two (the outer bins are then searched by interpolation).
int around_probes(double* p, double c0, double h, double A, double B) {
  static constexpr double s[kMaxProbes] = {-4096, -1024, -256, -64, -16, -4,   -1,  0,
                                           1,     4,     16,   64,  256, 1024, 4096};
  for (int j = 0; j < kMaxProbes; ++j) p[j] = c0 + s[j] * h;
  return finish_probes(p, kMaxProbes, A, B);
}

// Gid probes in (GA, GB]: evenly spaced, or bracketing the interpolated crossing.
int gid_probes(std::int64_t* p, std::int64_t GA, std::int64_t GB, double t, double WU, double NU,
               bool bisect) {
  const long double span = static_cast<long double>(GB) - static_cast<long double>(GA);
  int n = 0;
  if (bisect || NU <= kMaxBins) {
    const int k = static_cast<int>(std::min<double>(kMaxProbes, std::max(1.0, NU - 1)));
    for (int j = 0; j < k; ++j) p[n++] = GA + static_cast<std::int64_t>(span * (j + 1) / (k + 1));
  } else {
    static constexpr long double s[kMaxProbes] = {-16,  -8,  -4, -2, -1, -0.5, -0.25, 0,
                                                  0.25, 0.5, 1,  2,  4,  8,    16};
    const long double f = std::clamp<long double>((t + 0.5 * WU / NU) / WU, 0.0L, 1.0L);
    const long double sigma = std::max<long double>(std::sqrt(f * (1 - f) / NU), 1.0L / NU);
    for (int j = 0; j < kMaxProbes; ++j) {
      const long double v = static_cast<long double>(GA) + span * (f + s[j] * sigma);
      p[n++] = v <= static_cast<long double>(GA)   ? GA
               : v >= static_cast<long double>(GB) ? GB
                                                   : static_cast<std::int64_t>(v);
    }
  }
  for (int j = 0; j < n; ++j) p[j] = std::clamp(p[j], GA + 1, GB);
  std::sort(p, p + n);
  return static_cast<int>(std::unique(p, p + n) - p);
}

// Incremental first gid probes: the previous tie gid and geometric steps around it.
int around_gid_probes(std::int64_t* p, std::int64_t g0) {
  static constexpr std::int64_t s[kMaxProbes] = {-4096, -1024, -256, -64, -16, -4,   -1,  0,
                                                 1,     4,     16,   64,  256, 1024, 4096};
  int n = 0;
  for (int j = 0; j < kMaxProbes; ++j) {
    const long double v = static_cast<long double>(g0) + s[j];
    if (v > static_cast<long double>(kMinGid) && v <= static_cast<long double>(kMaxGid))
      p[n++] = g0 + s[j];
  }
  return n;
}

// Bins of U's coordinates against padded probes, with tallies (t cleared on entry).
// bins[i] = number of probes <= key, branch-free. key_w(i) gives (key, weight); with
// unit weights the weight tally is the count.
template <bool Weighted, class KeyW>
void tally_coords(std::int64_t n, const double* node_probes, KeyW key_w, std::uint8_t* bins,
                  Tally& t) {
  // A local copy of the probes (padded to 16 with +inf): the compiler may then keep them
  // in registers and compare 4 at a time, as the tallies cannot alias them.
  alignas(32) double probes[kMaxBins];
  for (int j = 0; j < kMaxProbes; ++j) probes[j] = node_probes[j];
  probes[kMaxProbes] = kInf;
  // Two interleaved sets of tallies: consecutive points often fall in the same bin, and
  // with one set every update would wait for the store of the previous one.
  double w[2][kMaxBins] = {}, c[2][kMaxBins] = {}, mn[2][kMaxBins], mx[2][kMaxBins];
  for (int h = 0; h < 2; ++h)
    for (int j = 0; j < kMaxBins; ++j) {
      mn[h][j] = kInf;
      mx[h][j] = -kInf;
    }
  auto one = [&](std::int64_t i, int h) {
    const auto [k, wi] = key_w(i);
    int b = 0;
    for (int j = 0; j < kMaxBins; ++j) b += k >= probes[j];
    bins[i] = static_cast<std::uint8_t>(b);
    if constexpr (Weighted) w[h][b] += wi;
    c[h][b] += 1;
    mn[h][b] = std::min(mn[h][b], k);
    mx[h][b] = std::max(mx[h][b], k);
  };
  std::int64_t i = 0;
  for (; i + 1 < n; i += 2) {
    one(i, 0);
    one(i + 1, 1);
  }
  if (i < n) one(i, 0);
  for (int j = 0; j < kMaxBins; ++j) {
    t.n[j] = c[0][j] + c[1][j];
    t.w[j] = Weighted ? w[0][j] + w[1][j] : t.n[j];
    t.mn[j] = std::min(mn[0][j], mn[1][j]);
    t.mx[j] = std::max(mx[0][j], mx[1][j]);
  }
}

// Bins of U's gids against np sorted probes, with tallies (t cleared on entry): the tie
// search, rare enough to stay simple.
void tally_gids(std::int64_t n, const std::int64_t* probes, int np, const Cand* u,
                std::uint8_t* bins, Tally& t) {
  for (std::int64_t i = 0; i < n; ++i) {
    const std::int64_t g = u[i].id;
    int b = 0;
    for (int j = 0; j < np; ++j) b += g >= probes[j];
    bins[i] = static_cast<std::uint8_t>(b);
    t.w[b] += u[i].w;
    t.n[b] += 1;
    t.gmn[b] = std::min(t.gmn[b], g);
    t.gmx[b] = std::max(t.gmx[b], g);
  }
}

// Keeps the candidates in bin `keep`, in order; returns their number.
std::int64_t compact(Cand* u, const std::uint8_t* bins, std::int64_t n, int keep) {
  std::int64_t k = 0;
  for (std::int64_t i = 0; i < n; ++i) {
    u[k] = u[i];
    k += bins[i] == keep;
  }
  return k;
}

// The bin holding the crossing point: the first whose inclusion takes the determined
// lower weight above T (the last non-empty bin if rounding of weighted sums hides it).
int crossing_bin(const Node& s, const Tally& g, int bins) {
  double cum = s.WL;
  int last = 0;
  for (int j = 0; j < bins; ++j) {
    if (g.n[j] > 0) last = j;
    if (g.n[j] > 0 && cum + g.w[j] > s.T) return j;
    cum += g.w[j];
  }
  return last;
}

// Whether the single point (or group of equal keys) U joins the lower side: the prefix
// weight closest to the target, ties to the shorter prefix.
bool include_u(const Node& s) {
  return (s.WL + s.WU - s.T) < (s.T - s.WL);
}

} // namespace

struct Rcb::Work {
  Buffer<Item<false>> unit[2];     // work arrays (ping-pong between levels), unit weights
  Buffer<Item<true>> heavy[2];     // the same with weights
  Buffer<Cand> cand;               // undetermined points, at each node's item range
  Buffer<std::uint8_t> bins;       // bin of each item or candidate in the current round
  std::vector<Node> nodes, next;   // nodes of the current and the next level
  std::vector<Tally> tally;        // one per node of the level
  std::vector<double> sums, maxes; // reduction buffers
  std::vector<std::int64_t> gmaxes;
};

Rcb::Rcb(const Comm& comm, const Vec3& direction_scale)
    : comm_(&comm), direction_scale_(direction_scale), rank_(comm.rank()), ranks_(comm.size()),
      cuts_(static_cast<std::size_t>(comm.size())), count_(static_cast<std::size_t>(comm.size())),
      weight_(static_cast<std::size_t>(comm.size())), work_(std::make_unique<Work>()) {
  for (int d = 0; d < 3; ++d)
    if (!(direction_scale[d] > 0 && std::isfinite(direction_scale[d])))
      throw std::invalid_argument("Rcb: the direction scale factors must be positive");
}
Rcb::~Rcb() = default;
Rcb::Rcb(Rcb&&) noexcept = default;
Rcb& Rcb::operator=(Rcb&&) noexcept = default;

void Rcb::partition(const RcbPoints& points) {
  // Weighted or not is a collective choice: a rank without points passes no weights
  // either, and must still follow the weighted targets of the others.
  if (comm_->max(static_cast<std::int64_t>(!points.weight.empty())) == 0)
    run<false>(points, false);
  else
    run<true>(points, false);
}

void Rcb::repartition(const RcbPoints& points) {
  const bool inc = have_cuts_;
  if (comm_->max(static_cast<std::int64_t>(!points.weight.empty())) == 0)
    run<false>(points, inc);
  else
    run<true>(points, inc);
}

template <bool Weighted>
void Rcb::run(const RcbPoints& in, bool incremental) {
  const Comm& comm = *comm_;
  const int P = ranks_;
  Work& wk = *work_;
  const std::size_t n = in.x.size();
  auto& items = [&]() -> auto& {
    if constexpr (Weighted)
      return wk.heavy;
    else
      return wk.unit;
  }
  ();

  // Copy into the work array, with the root's bounding box and an input check (made
  // collective through the box reduction so that every rank throws together).
  items[0].grow(n);
  items[1].grow(n);
  wk.cand.grow(n);
  wk.bins.grow(n);
  dest_.assign(n, rank_);
  bool bad = in.y.size() != n || in.z.size() != n || in.gid.size() != n ||
             (Weighted && in.weight.size() != n && !(n == 0 && in.weight.empty()));
  Node root;
  root.a = 0;
  root.b = P;
  root.begin = 0;
  root.end = static_cast<std::int64_t>(n);
  if (!bad) {
    double lo[3] = {kInf, kInf, kInf}, hi[3] = {-kInf, -kInf, -kInf};
    bool finite = true;
    for (std::size_t i = 0; i < n; ++i) {
      auto& it = items[0][i];
      it.x[0] = in.x[i];
      it.x[1] = in.y[i];
      it.x[2] = in.z[i];
      it.idx = static_cast<std::int64_t>(i);
      if constexpr (Weighted) {
        it.w = in.weight[i];
        finite &= std::isfinite(it.w) && it.w >= 0;
      }
      for (int d = 0; d < 3; ++d) {
        lo[d] = std::min(lo[d], it.x[d]);
        hi[d] = std::max(hi[d], it.x[d]);
        finite &= it.x[d] - it.x[d] == 0; // false for NaN and infinities (min/max skip NaN)
      }
    }
    for (int d = 0; d < 3; ++d) {
      finite &= n == 0 || (std::isfinite(lo[d]) && std::isfinite(hi[d]));
      root.lo[d] = lo[d];
      root.hi[d] = hi[d];
    }
    bad = !finite;
  }

  const bool inc = incremental && have_cuts_ && static_cast<int>(cuts_.size()) == P;
  have_cuts_ = false; // until this partition completes (an exception leaves no stale cuts)
  if (!inc) cuts_.assign(static_cast<std::size_t>(std::max(P, 1)), RcbCut{});
  count_.assign(static_cast<std::size_t>(P), 0);
  weight_.assign(static_cast<std::size_t>(P), 0.0);
  stats_.iterations.clear(); // keeps its capacity: a steady-state call allocates nothing
  stats_.total_iterations = 0;
  stats_.incremental = inc;

  double Wtot = 0, Ntot = 0;
  int cur = 0; // which work array holds the current level
  wk.nodes.clear();
  wk.nodes.push_back(root);
  std::int64_t bad_flag = bad ? 1 : 0;

  for (int level = 0; !wk.nodes.empty(); ++level) {
    auto& nodes = wk.nodes;
    const std::size_t nn = nodes.size();

    // Global bounding boxes of the level's nodes (min as max of the negative).
    wk.maxes.resize(nn * 6 + 1);
    for (std::size_t k = 0; k < nn; ++k)
      for (int d = 0; d < 3; ++d) {
        wk.maxes[k * 6 + d] = -nodes[k].lo[d];
        wk.maxes[k * 6 + 3 + d] = nodes[k].hi[d];
      }
    wk.maxes[nn * 6] = static_cast<double>(bad_flag);
    comm.max(std::span<double>(wk.maxes));
    if (wk.maxes[nn * 6] > 0)
      throw std::invalid_argument("Rcb: points need x, y, z and gid (and weight, if any) of "
                                  "equal length, finite coordinates and finite weights >= 0");
    for (std::size_t k = 0; k < nn; ++k)
      for (int d = 0; d < 3; ++d) {
        nodes[k].lo[d] = -wk.maxes[k * 6 + d];
        nodes[k].hi[d] = wk.maxes[k * 6 + 3 + d];
      }
    if (level == 0) {
      Node& r = nodes[0];
      const bool empty = !(r.lo[0] <= r.hi[0]);
      for (int d = 0; d < 3; ++d) {
        domain_.lo[d] = empty ? 0.0 : r.lo[d];
        domain_.hi[d] = empty ? 0.0 : r.hi[d];
      }
      r.geom = domain_;
    }

    // Leaves (one rank) need no cut; they were assigned when created. P == 1 ends here.
    if (level == 0 && P == 1) break;

    // Directions and first probes.
    for (Node& s : nodes) {
      s.m = split(s.a, s.b);
      RcbCut& c = cuts_[static_cast<std::size_t>(s.m)];
      const bool empty = !(s.lo[0] <= s.hi[0]);
      if (inc) {
        s.dim = c.dim;
        s.incremental = true;
        s.guess = c.value;
        s.guess_gid = c.gid;
        s.spacing = c.spacing;
      } else {
        // The longest extent of the points' box keeps subdomains closest to cubes (the
        // paper's rule), measured in the stretched coordinates; an empty node uses its
        // geometric box instead.
        const Box3 ext =
            empty ? s.geom : Box3{{s.lo[0], s.lo[1], s.lo[2]}, {s.hi[0], s.hi[1], s.hi[2]}};
        auto extent = [&](int d) { return (ext.hi[d] - ext.lo[d]) * direction_scale_[d]; };
        s.dim = 0;
        for (int d = 1; d < 3; ++d)
          if (extent(d) > extent(s.dim)) s.dim = d;
      }
      s.phase = Phase::First;
      const double A = s.lo[s.dim], B = s.hi[s.dim];
      if (empty || !(A < B)) {
        s.np = 0;
        for (double& p : s.pc) p = kInf;
      } else if (s.incremental && s.spacing > 0 && std::isfinite(s.guess)) {
        s.np = around_probes(s.pc, s.guess, s.spacing, A, B);
      } else {
        s.np = uniform_probes(s.pc, A, B, kMaxBins);
      }
    }

    // Median search: all nodes of the level advance together, one reduction per round.
    wk.tally.resize(nn);
    int rounds = 0;
    for (;;) {
      std::size_t active = 0;
      bool gid_round = false;
      for (const Node& s : nodes)
        if (s.phase != Phase::Done) {
          ++active;
          gid_round |= s.phase == Phase::Gid;
        }
      if (active == 0) break;
      ++rounds;

      // Local tallies.
      for (std::size_t k = 0; k < nn; ++k) {
        Node& s = nodes[k];
        Tally& t = wk.tally[k];
        if (s.phase == Phase::Done) continue;
        t.clear();
        std::uint8_t* bins = wk.bins.data() + s.begin;
        Cand* u = wk.cand.data() + s.begin;
        if (s.phase == Phase::First) {
          const auto* it = items[cur].data() + s.begin;
          const int d = s.dim;
          tally_coords<Weighted>(
              s.end - s.begin, s.pc,
              [&](std::int64_t i) {
                if constexpr (Weighted)
                  return std::pair<double, double>(it[i].x[d], it[i].w);
                else
                  return std::pair<double, double>(it[i].x[d], 1.0);
              },
              bins, t);
        } else if (s.phase == Phase::Coord) {
          tally_coords<Weighted>(
              s.nu, s.pc, [&](std::int64_t i) { return std::pair<double, double>(u[i].c, u[i].w); },
              bins, t);
        } else {
          if (!s.have_gids) // first round on ties: look the gids up once
            for (std::int64_t i = 0; i < s.nu; ++i)
              u[i].id = in.gid[static_cast<std::size_t>(u[i].id)];
          s.have_gids = true;
          tally_gids(s.nu, s.pg, s.np, u, bins, t);
        }
      }

      // Global tallies: sums (weight, count), maxes (-min, max), gid maxes (~min, max).
      wk.sums.resize(active * 2 * kMaxBins);
      wk.maxes.resize(active * 2 * kMaxBins);
      wk.gmaxes.resize(gid_round ? active * 2 * kMaxBins : 0);
      std::size_t slot = 0;
      for (std::size_t k = 0; k < nn; ++k) {
        if (nodes[k].phase == Phase::Done) continue;
        const Tally& t = wk.tally[k];
        double* su = wk.sums.data() + slot * 2 * kMaxBins;
        double* mx = wk.maxes.data() + slot * 2 * kMaxBins;
        for (int j = 0; j < kMaxBins; ++j) {
          su[j] = t.w[j];
          su[kMaxBins + j] = t.n[j];
          mx[j] = -t.mn[j];
          mx[kMaxBins + j] = t.mx[j];
        }
        if (gid_round) {
          std::int64_t* gm = wk.gmaxes.data() + slot * 2 * kMaxBins;
          for (int j = 0; j < kMaxBins; ++j) {
            gm[j] = ~t.gmn[j];
            gm[kMaxBins + j] = t.gmx[j];
          }
        }
        ++slot;
      }
      comm.sum(std::span<double>(wk.sums));
      comm.max(std::span<double>(wk.maxes));
      if (gid_round) comm.max(std::span<std::int64_t>(wk.gmaxes));

      // Decisions (identical on every rank) and local compaction of U.
      slot = 0;
      for (std::size_t k = 0; k < nn; ++k) {
        Node& s = nodes[k];
        if (s.phase == Phase::Done) continue;
        Tally& g = wk.tally[k];
        const double* su = wk.sums.data() + slot * 2 * kMaxBins;
        const double* mx = wk.maxes.data() + slot * 2 * kMaxBins;
        for (int j = 0; j < kMaxBins; ++j) {
          g.w[j] = su[j];
          g.n[j] = su[kMaxBins + j];
          g.mn[j] = -mx[j];
          g.mx[j] = mx[kMaxBins + j];
        }
        if (gid_round) {
          const std::int64_t* gm = wk.gmaxes.data() + slot * 2 * kMaxBins;
          for (int j = 0; j < kMaxBins; ++j) {
            g.gmn[j] = ~gm[j];
            g.gmx[j] = gm[kMaxBins + j];
          }
        }
        ++slot;
        const int nbins = s.np + 1;
        std::uint8_t* bins = wk.bins.data() + s.begin;
        Cand* u = wk.cand.data() + s.begin;

        if (s.phase == Phase::First) {
          for (int j = 0; j < nbins; ++j) {
            s.W += g.w[j];
            s.N += g.n[j];
          }
          if (level == 0) {
            Wtot = s.W;
            Ntot = s.N;
          }
          // Target of the lower side: the cumulative share of ranks [0, m) minus what the
          // nodes to the left already hold.
          double C;
          if constexpr (Weighted) {
            C = Wtot * s.m / P;
          } else {
            const auto NT = static_cast<std::int64_t>(Ntot);
            C = static_cast<double>((NT / P) * s.m + (NT % P) * s.m / P);
          }
          s.T = std::clamp(C - s.offset, 0.0, s.W);
          s.spacing = s.N > 0 ? (s.hi[s.dim] - s.lo[s.dim]) / s.N : 0.0;
          if (s.N == 0) {
            // No points: halve the node's geometric box, so empty ranks still get boxes.
            s.cut = 0.5 * (s.geom.lo[s.dim] + s.geom.hi[s.dim]);
            s.phase = Phase::Done;
            continue;
          }
          if (s.T >= s.W) { // everything lower (weighted case with heavy points)
            s.WL = s.W;
            s.NL = s.N;
            s.lmax = s.hi[s.dim];
            s.cut = cut_between(s.lmax, kInf);
            s.phase = Phase::Done;
            continue;
          }
        }

        {
          const int j = crossing_bin(s, g, nbins);
          const bool gid = s.phase == Phase::Gid;
          for (int i = 0; i < j; ++i) {
            s.WL += g.w[i];
            s.NL += g.n[i];
            if (g.n[i] > 0) {
              if (gid)
                s.tie_lower = true;
              else
                s.lmax = std::max(s.lmax, g.mx[i]);
            }
          }
          for (int i = j + 1; i < nbins; ++i)
            if (g.n[i] > 0) {
              if (gid) {
                s.tie_upper = true;
                s.gumin = std::min(s.gumin, g.gmn[i]);
              } else {
                s.umin = std::min(s.umin, g.mn[i]);
              }
            }
          const double NUold = s.phase == Phase::First ? s.N : s.NU;
          s.WU = g.w[j];
          s.NU = g.n[j];
          s.bisect = s.NU * 4 > NUold;
          // Keep U's candidates.
          if (s.phase == Phase::First) {
            const auto* it = items[cur].data() + s.begin;
            const int d = s.dim;
            std::int64_t q = 0;
            for (std::int64_t i = 0; i < s.end - s.begin; ++i) {
              if (bins[i] != j) continue;
              double w = 1.0;
              if constexpr (Weighted) w = it[i].w;
              u[q++] = Cand{it[i].x[d], w, it[i].idx};
            }
            s.nu = q;
          } else {
            s.nu = compact(u, bins, s.nu, j);
          }
          if (gid) {
            s.GA = g.gmn[j];
            s.GB = g.gmx[j];
          } else {
            s.A = g.mn[j];
            s.B = g.mx[j];
            s.phase = Phase::Coord;
          }
        }

        // Resolve, or choose the next probes.
        if (s.phase == Phase::Coord) {
          if (s.NU == 1) {
            s.take_u = include_u(s);
            if (s.take_u) {
              s.WL += s.WU;
              s.NL += s.NU;
              s.lmax = s.A;
            } else {
              s.umin = s.A;
            }
            s.cut = cut_between(s.lmax, s.umin);
            s.phase = Phase::Done;
          } else if (s.A == s.B) {
            // Many points on one plane: split them by global id. The first gid round has
            // no extremes to work from: one bin, or probes around the previous tie gid.
            s.tie = s.A;
            s.phase = Phase::Gid;
            s.np = 0;
            if (s.incremental && s.guess_gid != RcbCut::kNoTie)
              s.np = around_gid_probes(s.pg, s.guess_gid);
          } else {
            s.spacing = (s.B - s.A) / s.NU;
            s.np = (s.bisect || s.NU <= kMaxBins)
                       ? uniform_probes(s.pc, s.A, s.B, s.NU)
                       : interpolated_probes(s.pc, s.A, s.B, s.T - s.WL, s.WU, s.NU);
          }
        } else if (s.phase == Phase::Gid) {
          if (s.NU == 1 || s.GA == s.GB) {
            s.take_u = include_u(s);
            if (s.take_u) {
              s.WL += s.WU;
              s.NL += s.NU;
              s.tie_lower = true;
            } else {
              s.tie_upper = true;
              s.gumin = std::min(s.gumin, s.GA);
            }
            if (!s.tie_lower)
              s.cut = cut_between(s.lmax, s.tie);
            else if (!s.tie_upper)
              s.cut = cut_between(s.tie, s.umin);
            else {
              s.cut = s.tie;
              s.cut_gid = s.gumin;
            }
            s.phase = Phase::Done;
          } else {
            s.np = gid_probes(s.pg, s.GA, s.GB, s.T - s.WL, s.WU, s.NU, s.bisect);
          }
        }
      }
    }
    stats_.iterations.push_back(rounds);
    stats_.total_iterations += rounds;

    // Split every node's points into its children (out of place), record the cuts and
    // create the next level; points of leaves get their owner.
    auto& src = items[cur];
    auto& dst = items[1 - cur];
    wk.next.clear();
    for (Node& s : nodes) {
      RcbCut& c = cuts_[static_cast<std::size_t>(s.m)];
      c.dim = s.dim;
      c.value = s.cut;
      c.gid = s.cut_gid;
      c.level = level;
      if (s.spacing > 0) c.spacing = s.spacing;
      const int d = s.dim;
      const double v = s.cut;
      const std::int64_t cg = s.cut_gid;
      // Branch-free: both slots are written, one cursor advances. The owner written here
      // is final for a leaf child and overwritten at a deeper level otherwise (cheaper
      // than another pass over the leaves).
      std::int64_t lo = s.begin, hi = s.end - 1;
      int* dest = dest_.data();
      for (std::int64_t i = s.begin; i < s.end; ++i) {
        const auto& it = src[static_cast<std::size_t>(i)];
        const double x = it.x[d];
        bool low = x < v;
        if (x == v) [[unlikely]]
          low = in.gid[static_cast<std::size_t>(it.idx)] < cg;
        dst[static_cast<std::size_t>(lo)] = it;
        dst[static_cast<std::size_t>(hi)] = it;
        lo += low;
        hi -= !low;
        dest[it.idx] = low ? s.a : s.m;
      }
      for (int side = 0; side < 2; ++side) {
        Node ch;
        ch.a = side == 0 ? s.a : s.m;
        ch.b = side == 0 ? s.m : s.b;
        ch.begin = side == 0 ? s.begin : lo;
        ch.end = side == 0 ? lo : s.end;
        ch.offset = side == 0 ? s.offset : s.offset + s.WL;
        ch.geom = s.geom;
        if (side == 0)
          ch.geom.hi[d] = std::clamp(v, ch.geom.lo[d], ch.geom.hi[d]);
        else
          ch.geom.lo[d] = std::clamp(v, ch.geom.lo[d], ch.geom.hi[d]);
        if (ch.b - ch.a == 1) {
          count_[static_cast<std::size_t>(ch.a)] =
              static_cast<std::int64_t>(side == 0 ? s.NL : s.N - s.NL);
          weight_[static_cast<std::size_t>(ch.a)] = side == 0 ? s.WL : s.W - s.WL;
          continue;
        }
        for (std::int64_t i = ch.begin; i < ch.end; ++i) {
          const auto& it = dst[static_cast<std::size_t>(i)];
          for (int e = 0; e < 3; ++e) {
            ch.lo[e] = std::min(ch.lo[e], it.x[e]);
            ch.hi[e] = std::max(ch.hi[e], it.x[e]);
          }
        }
        wk.next.push_back(ch);
      }
    }
    std::swap(wk.nodes, wk.next);
    cur = 1 - cur;
  }

  if (P == 1) {
    count_[0] = static_cast<std::int64_t>(comm.sum(static_cast<std::int64_t>(n)));
    double w = 0;
    if constexpr (Weighted)
      for (double x : in.weight) w += x;
    else
      w = static_cast<double>(n);
    weight_[0] = w;
    Wtot = w;
    Ntot = static_cast<double>(count_[0]);
  }

  std::int64_t moved = 0;
  for (int r : dest_) moved += r != rank_;
  stats_.points_moved = comm.sum(moved);
  stats_.points = static_cast<std::int64_t>(Ntot);
  double wmax = 0;
  for (double w : weight_) wmax = std::max(wmax, w);
  stats_.imbalance = Wtot > 0 ? wmax / (Wtot / P) : 1.0;
  have_cuts_ = P > 1;
}

int Rcb::owner(const Vec3& p, std::int64_t gid) const {
  int a = 0, b = ranks_;
  while (b - a > 1) {
    const int m = split(a, b);
    const RcbCut& c = cuts_[static_cast<std::size_t>(m)];
    const double x = p[c.dim];
    if (x < c.value || (x == c.value && gid < c.gid))
      b = m;
    else
      a = m;
  }
  return a;
}

int Rcb::owner(const Vec3& p) const {
  return owner(p, kMaxGid);
}

void Rcb::overlapping(const Box3& q, std::vector<int>& out) const {
  out.clear();
  // Depth-first, lower side first, so ranks come out ascending. Depth <= log2(P) + 1.
  struct Range {
    int a, b;
  };
  Range stack[64];
  int top = 0;
  stack[top++] = {0, ranks_};
  while (top > 0) {
    const Range r = stack[--top];
    if (r.b - r.a == 1) {
      out.push_back(r.a);
      continue;
    }
    const int m = split(r.a, r.b);
    const RcbCut& c = cuts_[static_cast<std::size_t>(m)];
    const bool tie = c.gid != RcbCut::kNoTie;
    const bool lower = q.lo[c.dim] < c.value || (tie && q.lo[c.dim] <= c.value);
    const bool upper = q.hi[c.dim] >= c.value;
    if (upper) stack[top++] = {m, r.b};
    if (lower) stack[top++] = {r.a, m};
  }
}

Box3 Rcb::box(int rank) const {
  Box3 box{{-kInf, -kInf, -kInf}, {kInf, kInf, kInf}};
  int a = 0, b = ranks_;
  while (b - a > 1) {
    const int m = split(a, b);
    const RcbCut& c = cuts_[static_cast<std::size_t>(m)];
    if (rank < m) {
      box.hi[c.dim] = std::min(box.hi[c.dim], c.value);
      b = m;
    } else {
      box.lo[c.dim] = std::max(box.lo[c.dim], c.value);
      a = m;
    }
  }
  return box;
}

} // namespace anvil
