// Penalty enforcement (the paper's step 5): each node-face pair found by the search
// pushes the node out along the face normal with F = k |gap| and the face nodes back with
// -N_a F (N_a the face's shape functions at the foot), so momentum is conserved to
// round-off between deformable bodies; optional Coulomb friction opposes the relative
// tangential velocity, limited by mu |F| and by the force that would stop the sliding in
// one step. MPI-free: forces leave as items addressed to the nodes' FE owners.
#pragma once

#include <cstdint>
#include <vector>

#include "anvil/contact/search.hpp"

namespace anvil {

// One contribution to a node's contact force. The receiving FE owner sums the items of a
// node in ascending `slave` (then as given), which makes the sum independent of the
// decomposition (DESIGN.md section 3).
struct ContactForceItem {
  std::int64_t target; // node receiving the force (global id)
  std::int64_t slave;  // the pair's node, the key of the summation order
  std::int64_t face;   // the pair's face on the slave's own item, -1 on the face nodes'
  double allowance;    // the pair's allowance on the slave's own item
  double f[3];         // N
};

struct PenaltyOptions {
  double friction = 0; // Coulomb coefficient
  double dt = 0;       // the step over which the force acts (for the sticking limit)
};

// Appends one item per node touched by each pair to `items`, and its destination (the FE
// owner of the target node) to `dest`.
void penalty_forces(const std::vector<ContactNodeItem>& nodes,
                    const std::vector<ContactFaceItem>& faces,
                    const std::vector<ContactPair>& pairs, const PenaltyOptions& options,
                    std::vector<ContactForceItem>& items, std::vector<int>& dest);

} // namespace anvil
