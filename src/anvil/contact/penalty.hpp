// Penalty enforcement (the paper's step 5): each node-face pair found by the search
// pushes the node out along the face normal with F = k |gap| and the face nodes back with
// -N_a F (N_a the face's shape functions at the foot), so momentum is conserved to
// round-off between deformable bodies; optional Coulomb friction opposes the relative
// tangential velocity, limited by mu |F| and by the force that would stop the sliding in
// one step. The stiffness is the face's (contact_phase.cpp: penalty_scale K A^2 / V), but
// never more than stable_stiffness_fraction m / dt^2, m the pair's mass (the node against
// the face's nodes at the foot): a light node (a gas particle) on a stiff face would
// otherwise ring unstably, k dt^2 / m past central difference's limit of 4.
// MPI-free: forces leave as items addressed to every FE rank that holds the node.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "anvil/contact/search.hpp"

namespace anvil {

// One contribution to a node's contact force. Each FE rank that holds the node receives
// the items of a node and sums them in ascending `slave` (then as given): every copy gets
// the same bits, independent of the decomposition (DESIGN.md section 3).
struct ContactForceItem {
  std::int64_t target; // node receiving the force (global id)
  std::int64_t slave;  // the pair's node, the key of the summation order
  std::int64_t face;   // the pair's face on the slave's own item, -1 on the face nodes'
  double allowance;    // the pair's allowance on the slave's own item
  double f[3];         // N
};

// The cap on a pair's stiffness, in m / dt^2 (the spring alone: omega dt = 0.71).
inline constexpr double stable_stiffness_fraction = 0.5;

struct PenaltyOptions {
  double friction = 0; // Coulomb coefficient
  double dt = 0;       // the step (for the stiffness cap and the sticking limit)
};

// The holder groups of the items' `holders` fields: group g's ranks are
// ranks[start[g], start[g + 1]) (FeDecomposition::holder_start, holder_ranks).
struct HolderGroups {
  std::span<const int> start, ranks;
};

// Appends, per node touched by each pair, one item for each FE rank that holds the node
// to `items`, and that rank to `dest`.
void penalty_forces(const std::vector<ContactNodeItem>& nodes,
                    const std::vector<ContactFaceItem>& faces,
                    const std::vector<ContactPair>& pairs, const PenaltyOptions& options,
                    const HolderGroups& holders, std::vector<ContactForceItem>& items,
                    std::vector<int>& dest);

} // namespace anvil
