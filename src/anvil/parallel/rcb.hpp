// Recursive coordinate bisection (RCB, Berger and Bokhari 1987; the paper's dynamic
// decomposition for SPH particles and contact). A standalone unit: it knows points,
// optional weights, a unique 64-bit global id per point and a communicator, nothing
// about nodes, particles or faces. Its output is an owner rank for every local point,
// the cut tree, one box per rank and the statistics of the search; Migration (in
// migration.hpp) moves data to those owners: plan.build(comm, rcb.destinations()).
//
// The tree. The ranks [a, b) of a node are split at m = a + (b - a) / 2: ranks [a, m)
// take the lower side of the cut, [m, b) the upper side. Each m in [1, P) splits exactly
// one node, so the tree is stored as one cut per m (cuts()[m]; cuts()[0] is unused),
// as LAMMPS's rcb.h does.
//
// A point (c, g) (coordinate c along the cut's dim, global id g) lies on the lower side
// of a cut (value, gid) iff c < value, or c == value and g < gid. With gid = kNoTie the
// cut is a plain plane: boxes are half-open, [lo, hi) in every direction. A tie-breaking
// gid appears only when many points share the coordinate at which the split must fall;
// owner(p) without a gid then places points lying exactly on that plane on the upper
// side, owner(p, gid) always reproduces the partition.
//
// Cost: every level passes over the local points three to four times (count against the
// first probes, split, child boxes) and runs a few rounds of reductions of 64 doubles per
// tree node; no point moves. Memory: about 90 bytes per local point,
// kept between calls so that a steady-state repartition allocates nothing.
//
// Boxes tile all of space: the outer faces of the boxes at the boundary are at -inf and
// +inf (so every point, also one that moved out of the domain, has an owner). domain()
// is the bounding box of the points at the last partition; clip to it for pictures.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "anvil/core/vec3.hpp"
#include "anvil/parallel/comm.hpp"

namespace anvil {

// Points of this rank in structure-of-arrays form. All spans have the same length, except
// weight, which is either empty (unit weights) or of that length too; if any rank passes
// weights, every rank holding points must. Units are the caller's (the partition is
// scale-free); coordinates must be finite, weights finite and >= 0.
struct RcbPoints {
  std::span<const double> x, y, z;   // coordinates
  std::span<const std::int64_t> gid; // global id, unique over all ranks (breaks ties)
  std::span<const double> weight;    // empty: every point weighs 1
};

struct RcbCut {
  static constexpr std::int64_t kNoTie = std::numeric_limits<std::int64_t>::min();
  int dim = 0;               // 0, 1, 2: the direction cut
  double value = 0;          // plane position along dim
  std::int64_t gid = kNoTie; // tie-breaking id for points with coordinate == value
  int level = 0;             // depth of the node in the tree (root 0)
  double spacing = 0;        // typical coordinate gap of points near the cut (first guesses)
};

struct RcbStats {
  std::vector<int> iterations;   // median-search rounds (one reduction each) per level
  int total_iterations = 0;      // sum of iterations
  std::int64_t points = 0;       // points partitioned, all ranks
  std::int64_t points_moved = 0; // points whose owner differs from the rank that holds them
  double imbalance = 1;          // max over ranks of weight / mean weight (1 when empty)
  bool incremental = false;      // the last partition reused the previous cuts
};

class Rcb {
public:
  // comm must outlive this object; every member function taking points is collective.
  // Before the first partition, every cut is the plane x = 0 (queries are valid).
  // direction_scale stretches the coordinates when a node chooses the direction to cut
  // (the longest of its box's extents times these factors; all positive): a factor below
  // 1 makes cuts across that direction rarer (LS-DYNA's decomposition transformation SX,
  // SY, SZ). The cuts' places are those of the unstretched points.
  explicit Rcb(const Comm& comm, const Vec3& direction_scale = {1, 1, 1});
  ~Rcb();
  Rcb(Rcb&&) noexcept;
  Rcb& operator=(Rcb&&) noexcept;

  // Partitions from scratch: at every node, the direction is the longest extent of the
  // bounding box of the node's points (times direction_scale), and the first probes of the cut
  // divide that box evenly (its midpoint, the paper's first guess, among them). With unit weights
  // every rank ends with floor(N/P) or ceil(N/P) points; with weights every rank's weight is within
  // the largest single weight of W/P. The result depends only on the global set of (point, gid,
  // weight) and P, not on which rank holds what.
  void partition(const RcbPoints& points);

  // Repartitions reusing the previous cuts as first guesses and their directions (so a
  // small motion moves few points and needs few iterations). The cuts are the same exact
  // splits as partition() would find along those directions. Falls back to partition()
  // when there are no previous cuts.
  void repartition(const RcbPoints& points);

  // ---- results of the last partition ------------------------------------------------
  std::span<const int> destinations() const { return dest_; } // owner of each local point
  std::span<const RcbCut> cuts() const { return cuts_; }      // cuts()[m], m in [1, P)
  const RcbStats& stats() const { return stats_; }
  const Box3& domain() const { return domain_; } // bounding box of all points
  int ranks() const { return ranks_; }
  std::int64_t count(int rank) const { return count_[static_cast<std::size_t>(rank)]; }
  double weight(int rank) const { return weight_[static_cast<std::size_t>(rank)]; }

  // Owner of a point: the rank whose box contains it (points exactly on a tie-broken
  // plane go to the upper side). Serial, O(log P).
  int owner(const Vec3& p) const;
  // Owner of a point with its global id: exactly the partition's answer.
  int owner(const Vec3& p, std::int64_t gid) const;
  // Ranks whose boxes intersect the closed box b, ascending, into out (cleared first).
  // A box touching a tie-broken plane reports both sides. For ghosting.
  void overlapping(const Box3& b, std::vector<int>& out) const;
  // Box of a rank, half-open [lo, hi), outer faces at +-infinity.
  Box3 box(int rank) const;

  // The split rank of the node holding ranks [a, b) (b - a >= 2).
  static int split(int a, int b) { return a + (b - a) / 2; }

private:
  // The partition (see rcb.cpp for the scheme): fills every result member. incremental
  // reuses cuts_' directions and values as first guesses. Throws std::invalid_argument on
  // every rank if any rank's input is invalid.
  template <bool Weighted>
  void run(const RcbPoints& points, bool incremental);

  const Comm* comm_;
  Vec3 direction_scale_;
  int rank_ = 0, ranks_ = 1;
  std::vector<int> dest_;           // owner rank of each local input point
  std::vector<RcbCut> cuts_;        // cut tree, see above (size P; [0] unused)
  std::vector<std::int64_t> count_; // points per rank after the partition
  std::vector<double> weight_;      // weight per rank after the partition
  Box3 domain_;                     // bounding box of all points
  RcbStats stats_;                  // search and balance statistics
  bool have_cuts_ = false;          // cuts_ hold a previous partition (for repartition)

  struct Work; // buffers reused between calls (no allocation in steady state)
  std::unique_ptr<Work> work_;
};

} // namespace anvil
