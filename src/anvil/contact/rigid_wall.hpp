// Planar rigid walls (LS-DYNA's *RIGIDWALL_PLANAR): a kinematic constraint applied to the
// predicted motion. A node whose predicted position x(n) + dt v lies behind a wall gets
// the normal velocity that puts it exactly on the wall at t(n+1); Coulomb friction then
// reduces its tangential velocity by at most mu times the normal velocity change. The
// wall can push but never pull, so bodies leave it freely. MPI-free; every copy of a
// shared node computes the same correction.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "anvil/io/config.hpp"

namespace anvil {

struct WallNodes {
  const double* x[3];       // positions at t(n)
  double* v[3];             // in: predicted v(n+1/2); out: corrected
  const double* v_start[3]; // v(n-1/2), for the work of the wall impulses
  const double* mass;
  const std::uint8_t* constrained; // bit i: component i is constrained and left alone
  const std::uint8_t* owned;       // diagnostics count owned nodes only
  const std::int64_t* gid;         // global ids, keys of the force's summation order
  std::int64_t gid_offset;         // added to gid (particles come after the nodes)
  std::size_t size;
};

// The normal impulse (N s) one wall gave one owned node over the step: the velocity
// change the wall applied, constrained components excluded, along its normal.
struct WallHit {
  std::int64_t key; // gid + gid_offset
  std::int32_t wall;
  double impulse;
};

// What the walls did to the owned nodes over the step.
struct WallResult {
  double work = 0;    // the impulses times the mean of the step's start and end velocities (J)
  double kinetic = 0; // change of 1/2 m |v(n)|^2, v(n) the mean of v(n-1/2) and v(n+1/2) (J)
};

// The wall normal n without the constrained components (bit i of `fixed`): the directions
// a wall can move a node in. A wall nearly square to all of them (|n_f|^2 <= 1e-6; a
// fully fixed node) leaves the node alone.
Vec3 free_part(const Vec3& n, unsigned fixed);
bool wall_can_move(const Vec3& n, unsigned fixed);

// Corrects the velocities; appends to `hits` each owned node a wall acted on. A wall's
// force is the sum of its hits in ascending key over every rank (wall_forces), the same
// bits on any number of ranks.
WallResult apply_rigid_walls(const std::vector<RigidWallConfig>& walls, double dt, WallNodes nodes,
                             std::vector<WallHit>& hits);

// Sums the hits of every wall in ascending key: force[w] = sum of wall w's impulses / dt.
// `hits` is every rank's list (in any order); it is sorted in place.
void wall_forces(std::vector<WallHit>& hits, double dt, std::vector<double>& force);

} // namespace anvil
