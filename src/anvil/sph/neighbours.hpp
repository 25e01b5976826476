// Cell-list neighbour search for SPH, knowing nothing of MPI. Two particles are
// neighbours when r < h_i + h_j (the support 2 h_ij of the kernel at the mean smoothing
// length). Cells are cubes of edge cell / 2 (`cell` >= the largest h_i + h_j) on a
// lattice anchored at the origin, cell index floor(2 x / cell): the same cells on every
// rank.
//
// Order (the determinism rule, DESIGN.md section 3). A particle's neighbours are listed
// by the 125 cells around its own in a fixed order (z, then y, then x offsets, -2..2)
// and, inside a cell, in ascending global id. The order is therefore a function of the global
// positions, ids and cell size only, not of which rank holds which particle or of the
// order of the arrays: every rank that holds a particle and all of its neighbours (own
// or ghost copies with the same bits) sums its neighbour terms in the same order.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace anvil::sph {

// Neighbour lists in compressed rows: particle i's neighbours are
// index[start[i] .. start[i+1]), indices into the arrays given to the search (index may
// be longer than the list: it keeps its size between calls).
struct NeighbourList {
  std::vector<std::int64_t> start;
  std::vector<int> index; // storage: only the first count() entries are the list
  std::size_t count = 0;
  std::size_t pairs() const { return count; }
};

// Scratch kept between calls (no allocation in steady state).
struct NeighbourWorkspace {
  std::vector<std::int64_t> key;        // cell of each particle (dense index or packed)
  std::vector<int> cell_start;          // dense grid: first entry per cell (+1 at the end)
  std::vector<int> order;               // particles sorted by cell, then gid
  std::vector<double> xs, ys, zs, hs;   // their positions and h in that order
  std::vector<std::int64_t> sorted_key; // sparse fallback: keys in that order
};

// Finds the neighbours of particles [0, n_query) among all n = x.size() particles (the
// query particles included; a particle is not its own neighbour). x, y, z, h, gid have
// n entries; cell >= max over pairs of h_i + h_j and identical on every rank.
void find_neighbours(std::span<const double> x, std::span<const double> y,
                     std::span<const double> z, std::span<const double> h,
                     std::span<const std::int64_t> gid, std::size_t n_query, double cell,
                     NeighbourWorkspace& work, NeighbourList& out);

} // namespace anvil::sph
