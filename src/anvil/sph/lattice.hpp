// Particle lattices (deck `particles: NAME: {generate: ...}`): simple cubic lattices that
// fill a box, a sphere or a cylinder, one particle at the centre of each lattice cell
// whose centre lies inside the shape. Deterministic order (the global particle ids):
// z slowest, then y, then x (for a cylinder: along the axis slowest).
#pragma once

#include <vector>

#include "anvil/core/vec3.hpp"
#include "anvil/io/config.hpp"

namespace anvil::sph {

struct Lattice {
  std::vector<Vec3> points;
  double volume = 0;  // volume per particle, m^3 (the same for every particle of a lattice)
  double spacing = 0; // mean spacing actually used, m (volume^(1/dimensions))
};

// Box: n_i = max(1, round(L_i / s)) cells per direction, spacing L_i / n_i, so the
// particles fill the box exactly. Sphere: cells of edge s centred on the sphere's
// centre's lattice (c + (k + 1/2) s), kept when inside. Cylinder: n = round(length / s)
// layers of spacing length / n along the axis, cross-section as the sphere's (without
// the points inside inner_radius: a ring or a tube).
// In fewer than 3 dimensions (SphConfig::dimensions) the lattice is one layer on the
// model's plane z = 0 (2-D: a box's section, a sphere's: a disc, a cylinder's, which
// must lie along z: a disc or a ring) or its line y = z = 0 (1-D, boxes only), whatever
// the shape's extent there: distances are 3-D, so every set must lie on the same plane
// (line) to interact with the others in plane. Volume is then per unit thickness or area.
Lattice generate_lattice(const LatticeSpec& spec, int dimensions = 3);

// The spacing of particles placed one by one (ParticleList), as LS-DYNA takes it for
// *ELEMENT_SPH: the largest distance from a particle to its nearest neighbour (on a
// lattice, the lattice spacing). 0 for fewer than two points, and 0 with the first pair
// found when two points coincide (`a`, `b`: their indices).
struct CloudSpacing {
  double spacing = 0;
  int a = -1, b = -1;
  double median = 0; // the median distance from a particle to its nearest neighbour
  int farthest = -1; // the particle whose nearest neighbour is farthest (`spacing` away)
};
CloudSpacing cloud_spacing(const std::vector<Vec3>& points);

} // namespace anvil::sph
