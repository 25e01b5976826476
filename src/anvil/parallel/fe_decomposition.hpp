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
#include <vector>

#include "anvil/mesh/mesh.hpp"
#include "anvil/parallel/comm.hpp"

namespace anvil {

struct FeDecomposition {
  int rank = 0, ranks = 1;

  std::vector<std::int64_t> node_gid;   // global id of each local node, ascending
  std::vector<std::uint8_t> node_owned; // 1 where this rank owns the node
  std::vector<int> node_owner;          // owning rank of each local node (lowest toucher)

  struct Block {
    std::vector<std::int64_t> gid;        // owned elements of this mesh block, ascending
    std::vector<std::array<int, 8>> conn; // their corners as local node indices
    std::size_t corner_base = 0;          // slot of corner (e, a): base + a * stride + e
    int stride = 0;                       // padded element count (simd::padded_size)
  };
  std::vector<Block> blocks; // one per mesh block, possibly empty

  std::size_t local_slots = 0;           // corner slots of owned elements (padding included)
  std::size_t remote_slots = 0;          // corner slots received from other ranks, after local ones
  std::vector<int> gather_ptr;           // per local node: range in gather_slot (CSR)
  std::vector<std::int64_t> gather_slot; // slots in ascending (element gid, corner)

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
  CornerExchange(const FeDecomposition& d, const Comm& comm);
  // Fills the remote slots of `components` arrays of total_slots() values each.
  void exchange(const std::vector<double*>& arrays);

private:
  const FeDecomposition& d_;
  const Comm& comm_;
  std::vector<double> send_, recv_;
};

// Copies nodal values from each shared node's owner to the other ranks that hold it
// (for values computed on owners only, such as contact forces).
class NodeExchange {
public:
  NodeExchange(const FeDecomposition& d, const Comm& comm);
  // `arrays` hold one value per local node; non-owned shared entries are overwritten.
  void from_owners(const std::vector<double*>& arrays);

private:
  const FeDecomposition& d_;
  const Comm& comm_;
  std::vector<double> send_, recv_;
  Requests requests_; // reused, so an exchange allocates nothing
};

// Sums the corner slots of every local node (the gather): out[i][n] = sum over the
// node's slots in order of corner[i][slot]. Pure arithmetic, no communication.
void gather_corners(const FeDecomposition& d, const std::vector<const double*>& corner,
                    const std::vector<double*>& out);

} // namespace anvil
