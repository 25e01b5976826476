// The static FE decomposition (the paper's first): elements owned by the rank METIS gave
// them, every node of an owned element held locally, shared nodes held by every rank
// that touches them and owned (for diagnostics and output) by the lowest such rank.
//
// Assembly is gather-based and exact: each element writes its 8 corner forces into
// slots; a node's force is the sum of the slots of all corners that touch it, over all
// ranks, in ascending (global element id, corner). Corners owned elsewhere arrive in
// remote slots through one exchange per cycle (CornerExchange). Every copy of a shared
// node therefore adds the same numbers in the same order and holds the same bits, and
// the result does not depend on the number of ranks (DESIGN.md section 3).
#pragma once

#include <array>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <vector>

#include "anvil/mesh/mesh.hpp"
#include "anvil/parallel/comm.hpp"

namespace anvil {

struct FeDecomposition {
  int rank = 0, ranks = 1;

  std::vector<std::int64_t> node_gid;   // global id of each local node, ascending
  std::vector<std::uint8_t> node_owned; // 1 where this rank owns the node (lowest toucher)
  // The ranks that hold each local node, as a group of the table below (the same on every
  // rank): group g's ranks, ascending, are holder_ranks[holder_start[g], holder_start[g +
  // 1]); group r < ranks is rank r alone. Contact forces go to every holder of a node.
  std::vector<int> node_holders;
  std::vector<int> holder_start, holder_ranks;

  struct Block {
    std::vector<std::int64_t> gid;        // owned elements of this mesh block, ascending
    std::vector<std::array<int, 8>> conn; // their corners as local node indices
    std::size_t corner_base = 0;          // slot of corner (e, a): slot(e, a)
    int stride = 0;                       // padded element count (simd::padded_size)
    // Corners are element-major: an element's eight corners are adjacent (64 bytes per
    // component), so the kernel writes, and the gather reads, few memory streams.
    std::size_t slot(std::size_t e, int a) const { return corner_base + 8 * e + a; }
    // Per vector of simd::width elements: 1 if one of them touches an exchanged node (its
    // corner slots are read after the exchange), else 0 (HexBlock::corner_rows).
    std::vector<std::uint8_t> exchanged_vectors;
  };
  std::vector<Block> blocks; // one per mesh block, possibly empty

  std::size_t local_slots = 0;           // corner slots of owned elements (padding included)
  std::size_t remote_slots = 0;          // corner slots received from other ranks, after local ones
  std::vector<int> gather_ptr;           // per local node: range in gather_slot (CSR)
  std::vector<std::int64_t> gather_slot; // slots in ascending (element gid, corner)
  std::vector<int> exchanged_nodes;      // local nodes with remote slots (shared with other
                                         // ranks), ascending: their sums need the exchange

  struct Neighbor {
    int rank = 0;
    std::vector<std::int64_t> send_slots; // our corner slots it needs, in agreed order
    std::size_t recv_base = 0;            // first remote slot it fills
    std::size_t recv_count = 0;
    std::vector<int> shared; // local nodes both ranks hold, ascending gid
  };
  std::vector<Neighbor> neighbors; // ascending rank

  std::size_t total_slots() const { return local_slots + remote_slots; }
  std::int64_t num_elements() const;
  std::int64_t num_owned_nodes() const;
};

// Builds this rank's part from the global mesh and the element owners (all ranks hold
// both; no communication).
FeDecomposition decompose_fe(const Mesh& mesh, const std::vector<int>& owner, int rank, int ranks);

// The per-cycle exchange of corner values between ranks that share nodes.
class CornerExchange {
public:
  // `components`: the most arrays one exchange carries (3 forces; 6 with the pressure
  // loads' corner forces).
  CornerExchange(const FeDecomposition& d, const Comm& comm, int components = 3);
  // Fills the remote slots of `components` arrays of total_slots() values each. The
  // arrays come as a braced list (an initializer_list lives on the stack: the cycle
  // allocates nothing for it).
  void exchange(std::initializer_list<double*> arrays);
  // The same in two halves, so that the caller can do other work (a collective, say)
  // while the messages travel: start() sends this rank's slots and posts the receives;
  // finish() waits and fills the remote slots. Both take the same arrays, which must not
  // change in between.
  void start(std::initializer_list<double*> arrays);
  void finish(std::initializer_list<double*> arrays);

private:
  const FeDecomposition& d_;
  const Comm& comm_;
  std::vector<double> send_, recv_;
  Requests requests_; // reused: the exchange allocates nothing
  std::size_t components_;
};

// Sums the corner slots of every local node (the gather): out[i][n] = sum over the
// node's slots in order of corner[i][slot]. Pure arithmetic, no communication. One or
// three components (mass, force) per call, as braced lists of equal length; the three
// components are summed in one pass over the slot list (each still in slot order).
void gather_corners(const FeDecomposition& d, std::initializer_list<const double*> corner,
                    std::initializer_list<double*> out);

// The same for the listed local nodes only (the others' out entries are left alone): with
// the nodal assembly in the kernel (HexWorkspace::begin_nodal_forces), the gather of
// d.exchanged_nodes after the exchange completes the nodal forces.
void gather_corners(const FeDecomposition& d, std::initializer_list<const double*> corner,
                    std::initializer_list<double*> out, std::span<const int> nodes);

} // namespace anvil
