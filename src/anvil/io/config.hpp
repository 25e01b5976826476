// The deck as typed, validated configuration. The deck reader (deck.hpp) is the only
// code that sees YAML; everything else takes these structs. Every struct remembers where
// in the deck it came from so that later checks (a set that selects no node, a mesh file
// that fails to read) still name the file, line and key.
#pragma once

#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "anvil/core/error.hpp"
#include "anvil/core/vec3.hpp"
#include "anvil/fe/hex_block.hpp"
#include "anvil/material/material.hpp"
#include "anvil/mesh/generators.hpp"

namespace anvil {

struct MaterialConfig {
  std::string name;
  std::string model;  // registry name (material.hpp)
  ParamValues params; // every parameter of the model, defaults filled in
  SourceLocation where;
};

struct MeshConfig {
  enum class Kind { box, cylinder, can, file };
  Kind kind = Kind::box;
  BoxSpec box;
  CylinderSpec cylinder;
  CanSpec can;
  std::string file; // resolved relative to the deck's directory
  SourceLocation where;
};

struct PartConfig {
  std::string name;
  MeshConfig mesh;
  std::string material;
  HourglassControl hourglass;
  BulkViscosity bulk_viscosity;
  SourceLocation where;
};

// A set of nodes: a named set (deck `node_sets`, or a generated `PART.SET`), or an
// inline selection by part and/or box.
struct Selection {
  std::string name;                // named set, or empty for an inline selection
  std::optional<std::string> part; // restrict to the nodes of a part
  std::optional<Box3> box;         // restrict to a box (boundary included)
  SourceLocation where;
};

struct InitialCondition {
  Selection nodes;
  Vec3 velocity;
  Vec3 angular_velocity; // rad/s about `center`: v += w x (x - center)
  Vec3 center;
  SourceLocation where;
};

struct BoundaryCondition {
  Selection nodes;
  std::array<bool, 3> fix{false, false, false};        // fixed components (velocity 0)
  bool prescribed = false;                             // a prescribed velocity
  Vec3 velocity;                                       // its value, m/s
  std::array<bool, 3> components{false, false, false}; // components it prescribes
  SourceLocation where;
};

struct ProbeConfig {
  std::string name;
  Vec3 at;
  SourceLocation where;
};

struct Config {
  std::string title;
  std::string deck_file;
  double end_time = std::numeric_limits<double>::infinity();
  std::int64_t end_cycles = std::numeric_limits<std::int64_t>::max();
  double time_step_scale = 0.9;
  double fields_every = 0;  // 0: first and last only
  double history_every = 0; // 0: every cycle
  std::vector<MaterialConfig> materials;
  std::vector<PartConfig> parts;
  std::map<std::string, Selection> node_sets;
  std::vector<InitialCondition> initial_conditions;
  std::vector<BoundaryCondition> boundary_conditions;
  std::vector<ProbeConfig> probes;

  const MaterialConfig* material(const std::string& name) const;
};

} // namespace anvil
