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
  std::size_t size;
};

// What the walls did to the owned nodes over the step.
struct WallResult {
  double work = 0;    // the impulses times the mean of the step's start and end velocities (J)
  double kinetic = 0; // change of 1/2 m |v(n)|^2, v(n) the mean of v(n-1/2) and v(n+1/2) (J)
};

// Corrects the velocities; adds to impulse[w] the normal impulse wall w gave to owned
// nodes (N s: the velocity change the wall applied, constrained components excluded,
// along its normal).
WallResult apply_rigid_walls(const std::vector<RigidWallConfig>& walls, double dt, WallNodes nodes,
                             std::vector<double>& impulse);

} // namespace anvil
