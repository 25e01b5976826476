// Structured hexahedral meshes for the common shapes of impact problems. Each returns a
// one-block Mesh with named node sets for its faces (names without the part prefix).
#pragma once

#include <array>

#include "anvil/mesh/mesh.hpp"

namespace anvil {

// Axis-aligned box from `min` to `max` with `divisions` cells per direction, each cell a
// hexahedron, or (`shape`) two wedges cut by the plane through its edges along z at
// (min x, min y) and (max x, max y), or six tetrahedra around its diagonal from
// (min x, min y, min z) (Kuhn's subdivision: neighbours share whole faces).
// Node sets: xmin, xmax, ymin, ymax, zmin, zmax.
struct BoxSpec {
  Vec3 min, max;
  std::array<int, 3> divisions{1, 1, 1};
  Shape shape = Shape::hexahedron;
};
Mesh generate_box(const BoxSpec& spec);

// Solid circular cylinder with a butterfly (O-grid) section: a central block of
// 2c x 2c elements, c = max(1, divisions[0] / 2), and divisions[0] - c layers of the outer
// ring, so that divisions[0] elements span the radius; divisions[1] elements along the
// axis. The base centre is at `origin`; `axis` 0, 1, 2 for x, y, z.
// Node sets: bottom, top, outer.
struct CylinderSpec {
  double radius = 0, length = 0;
  int axis = 2;
  Vec3 origin;
  std::array<int, 2> divisions{2, 1};
};
Mesh generate_cylinder(const CylinderSpec& spec);

// Thin-walled open tube ("can" wall): mean radius, wall thickness, height along `axis`
// from `origin`; divisions = {around, along the axis, through the wall}.
// Node sets: bottom, top, inner, outer.
struct CanSpec {
  double radius = 0, height = 0, thickness = 0;
  int axis = 2;
  Vec3 origin;
  std::array<int, 3> divisions{8, 1, 1};
};
Mesh generate_can(const CanSpec& spec);

} // namespace anvil
