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
  double spacing = 0; // mean spacing actually used, m (cube root of volume)
};

// Box: n_i = max(1, round(L_i / s)) cells per direction, spacing L_i / n_i, so the
// particles fill the box exactly. Sphere: cells of edge s centred on the sphere's
// centre's lattice (c + (k + 1/2) s), kept when inside. Cylinder: n = round(length / s)
// layers of spacing length / n along the axis, cross-section as the sphere's.
Lattice generate_lattice(const LatticeSpec& spec);

} // namespace anvil::sph
