// Neighbour search for SPH, knowing nothing of MPI, in two stages, over half lists (each
// pair once, in the row of its particle of lower global id):
//
//  - candidates (Verlet lists): every pair within a fixed radius (the support plus a
//    skin) at the positions of the build, by cell lists: cubes of edge radius / 2 on a
//    lattice anchored at the origin, the 5 x 5 x 5 cells around a particle's own. Built
//    only when the particles have moved too far for the lists to hold every pair within
//    the support (the caller decides: sph_phase.cpp).
//  - neighbours, every step: the candidate pairs with r_ij < h_i + h_j (the support 2 h_ij
//    of the kernel at the mean smoothing length) at the current positions, the exact test
//    on the current positions and h.
//
// Order (the determinism rule, DESIGN.md section 3): the rows are in ascending global id
// of their particle, and each row lists the partners of larger global id in ascending
// global id. A particle's neighbours are the particles whose rows list it (lower ids, in
// row order) followed by its own row (higher ids): ascending global id. The lists are
// therefore a function of the current global positions, h and ids alone: not of which
// rank holds which particle, of the order of the arrays, of the skin or of when the
// candidates were built (so a restart, which builds them afresh, continues with the same
// bits).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace anvil::sph {

// Half lists in padded rows, one row per particle in ascending global id: row k belongs to
// particle row[k] and lists index[start[k] .. start[k] + len[k]); rows start at multiples
// of simd::width and are padded to a whole number of vectors with the row's particle
// itself (index is longer than the lists: it keeps its size between calls).
struct NeighbourList {
  std::vector<int> row;            // particle of each row, ascending global id
  std::vector<std::int64_t> start; // row starts, one per row and the end
  std::vector<int> len;            // entries of each row, padding excluded
  std::vector<int> index;          // storage, padded rows
  std::size_t count = 0;           // sum of len: each pair once
  std::size_t pairs() const { return count; }
};

// Scratch kept between calls (no allocation in steady state).
struct NeighbourWorkspace {
  std::vector<std::int64_t> key;        // cell of each particle (dense index or packed)
  std::vector<int> cell_start;          // dense grid: first entry per cell (+1 at the end)
  std::vector<int> order;               // particles sorted by cell, then gid
  std::vector<double> xs, ys, zs;       // their positions in that order
  std::vector<std::int64_t> gs;         // and their global ids
  std::vector<std::int64_t> sorted_key; // sparse fallback: keys in that order
};

// Candidate half lists of the n = x.size() particles, own ones [0, n_own) and ghost copies
// after them: the row of particle i lists every j with gid_j > gid_i and
// |x_i - x_j| < radius of which i or j is own (the pairs that concern an own particle),
// in ascending gid; one row per particle, rows in ascending gid. x, y, z, gid have n
// entries.
void find_candidates(std::span<const double> x, std::span<const double> y,
                     std::span<const double> z, std::span<const std::int64_t> gid,
                     std::size_t n_own, double radius, NeighbourWorkspace& work,
                     NeighbourList& out);

// The neighbours among the candidates: the entries j of each row (particle i) with
// r_ij < h_i + h_j at the current positions, in the candidates' order. xh holds each
// particle's x, y, z, h at xh + stride * k (stride in doubles, 32-byte aligned): the
// records pass 1 reads.
void filter_neighbours(const double* xh, int stride, const NeighbourList& candidates,
                       NeighbourList& out);

} // namespace anvil::sph
