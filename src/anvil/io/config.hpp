// The deck as typed, validated configuration. The deck reader (deck.hpp) is the only
// code that sees YAML; everything else takes these structs. Every struct remembers where
// in the deck it came from so that later checks (a set that selects no node, a mesh file
// that fails to read) still name the file, line and key.
#pragma once

#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "anvil/core/error.hpp"
#include "anvil/core/time_curve.hpp"
#include "anvil/core/vec3.hpp"
#include "anvil/fe/hex_block.hpp"
#include "anvil/material/material.hpp"
#include "anvil/mesh/generators.hpp"

namespace anvil {

struct MaterialConfig {
  std::string name;
  std::string model;      // registry name (material.hpp)
  ParamValues params;     // every parameter of the model, defaults filled in
  TableValues tables;     // its tabulated parameters that the deck gives
  std::string eos_model;  // equation of state replacing the pressure (empty: none)
  ParamValues eos_params; // its parameters, defaults filled in
  SourceLocation where;
};

struct MeshConfig {
  // embedded: the mesh came with the deck (an LS-DYNA keyword deck holds its nodes and
  // elements); parts that share one embedded mesh share its nodes.
  enum class Kind { box, cylinder, can, file, embedded };
  Kind kind = Kind::box;
  BoxSpec box;
  CylinderSpec cylinder;
  CanSpec can;
  std::string file;                     // resolved relative to the deck's directory
  std::shared_ptr<const Mesh> embedded; // Kind::embedded: the deck's mesh, shared by parts
  std::size_t embedded_block = 0;       // Kind::embedded: this part's block in it
  SourceLocation where;
};

struct PartConfig {
  std::string name;
  MeshConfig mesh;
  std::string material;
  HourglassControl hourglass;
  BulkViscosity bulk_viscosity;
  Erosion erosion;
  ThickShell thick_shell;
  // A rigid body (LS-DYNA's *MAT_RIGID): its nodes move together, its elements carry no
  // stress; the material gives its mass (density) and its contact stiffness (E, nu).
  bool rigid = false;
  // A rigid part merged into another's body (LS-DYNA's *CONSTRAINED_RIGID_BODIES: PIDS
  // into PIDL): the part whose body it joins; empty: a body of its own (or none). The
  // body is named after its lead, the part at the end of the chain.
  std::string merge_with;
  SourceLocation merge_where;
  SourceLocation where;
};

// The lead part of each part's rigid body (following merge_with), or -1 for a part that is
// not rigid. Assumes a validated config (the names exist, no cycles).
std::vector<int> rigid_body_leads(const std::vector<PartConfig>& parts);
// Throws InputError (at merge_with) where a part merges into no part, a part that is not
// rigid, or a chain that comes back to itself.
void check_rigid_merges(const std::vector<PartConfig>& parts);

// SPH particles (DESIGN.md section 4, `particles:`): a lattice filling a shape at a
// spacing, and the options of the particle formulation (docs/sph.md).
struct LatticeSpec {
  enum class Shape { box, sphere, cylinder };
  Shape shape = Shape::box;
  Vec3 min, max;           // box
  Vec3 center;             // sphere
  Vec3 origin;             // cylinder: centre of its base
  double radius = 0;       // sphere, cylinder
  double inner_radius = 0; // cylinder: hollow inside this radius (a ring or tube)
  double length = 0;       // cylinder
  int axis = 2;            // cylinder
  double spacing = 0;      // lattice spacing, m
};

// Particles given one by one (LS-DYNA's *ELEMENT_SPH) instead of a lattice, in 3-D.
struct ParticleList {
  std::vector<Vec3> x;
  std::vector<double> mass;     // kg; 0 where the volume is given instead
  std::vector<double> volume;   // m^3 where the mass is 0: the mass is density * volume
  std::vector<std::int64_t> id; // the deck's ids (node ids), for messages
  // Named node sets (a keyword deck's) that hold particles of this set: name -> indices
  // into x, ascending. Conditions on such a set act on these particles too.
  std::map<std::string, std::vector<std::int64_t>> sets;
};

struct ParticleSetConfig {
  enum class Kernel { cubic_spline, wendland_c2 };
  std::string name;
  LatticeSpec lattice;
  std::shared_ptr<const ParticleList> list; // instead of the lattice when given
  std::string material;
  // h0 = smoothing_ratio * spacing: the lattice's (cell volume)^(1/dimensions); a list's,
  // the largest distance from a particle to its nearest neighbour (LS-DYNA's rule).
  double smoothing_ratio = 1.3;
  double smoothing_length = 0;    // h0 itself, m, when > 0 (LS-DYNA's SPHINI)
  SourceLocation smoothing_where; // the deck's key of the smoothing length (empty: `where`)
  // Bounds of h / h0 as the density changes (LS-DYNA's *SECTION_SPH HMIN and HMAX, with
  // their defaults): h = h0 (rho0 / rho)^(1/d) clamped to [h_min, h_max] h0.
  double h_min = 0.2, h_max = 2.0;
  Kernel kernel = Kernel::cubic_spline;
  double viscosity_linear = 1.0;    // Monaghan-Gingold alpha
  double viscosity_quadratic = 2.0; // Monaghan-Gingold beta
  double artificial_stress = 0.3;   // Monaghan's epsilon (Gray et al. 2001); 0 turns it off
  double artificial_stress_exponent = 4;
  bool corrected_gradient = false; // Randles-Libersky normalised velocity gradient
  bool summation_density = false;  // rho = sum m W (gases, shocks) instead of continuity
  SourceLocation where;
};

// Options of the SPH decomposition (top-level `sph:`, optional).
struct SphConfig {
  double rebalance_threshold = 1.2; // re-cut the particle RCB when max/mean count exceeds it
  // Dimensions of the particle model: 3, or 2 (plane strain in x-y, masses per unit
  // thickness) or 1 (uniaxial strain along x, masses per unit area) for verification
  // problems that are planar or one-dimensional; below 3 the deck may hold no FE part.
  int dimensions = 3;
};

// A set of nodes (and particles): a named set (deck `node_sets`, or a generated
// `PART.SET`), or an inline selection by part (a part or a particle set) and/or box.
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
  // `center: mass_center`: about the centre of mass of the nodes it sets (their lumped
  // masses; for a rigid part, the body's), found when the model is built.
  bool about_mass_center = false;
  SourceLocation where;
};

struct BoundaryCondition {
  Selection nodes;
  std::array<bool, 3> fix{false, false, false}; // fixed components (velocity 0)
  bool prescribed = false;                      // a prescribed motion
  // A prescribed velocity (m/s), or a prescribed displacement from the initial position
  // (m, with a curve): `value` times the curve's value at the time (1 without a curve).
  enum class Motion { velocity, displacement } motion = Motion::velocity;
  Vec3 value;
  std::optional<TimeCurve> curve;
  std::array<bool, 3> components{false, false, false}; // components it prescribes
  // A rigid part's rotations (its `part:` a rigid part: the condition holds the body's
  // centre and spin, LS-DYNA's *MAT_RIGID CON1, CON2 and
  // *BOUNDARY_PRESCRIBED_MOTION_RIGID): fixed ones (spin 0), prescribed ones (`spin`, rad/s,
  // times the curve's value), and whether the deck named any (an error on nodes).
  std::array<bool, 3> fix_spin{false, false, false};
  std::array<bool, 3> spin_components{false, false, false};
  Vec3 spin;
  bool rotations = false;
  // Whether it holds a rotation (fixed or prescribed): its moment goes to history.csv.
  bool holds_spin() const {
    for (std::size_t i = 0; i < 3; ++i)
      if (prescribed ? spin_components[i] : fix_spin[i]) return true;
    return false;
  }
  // The condition holds its components from `birth` to `death` (s; LS-DYNA's BIRTH and
  // DEATH): a step that starts at t(n) with birth <= t(n) < death; outside, they are free.
  double birth = 0, death = std::numeric_limits<double>::infinity();
  bool active(double t) const { return birth <= t && t < death; }
  SourceLocation where;
};

// A body force per unit mass on every node and particle (deck `gravity`, LS-DYNA
// *LOAD_BODY_X/Y/Z): `acceleration` times its curve's value at the time (1 without one).
struct BodyLoad {
  Vec3 acceleration; // m/s^2
  std::optional<TimeCurve> curve;
  SourceLocation where;
};

// An external load on the mesh (deck `loads`; LS-DYNA *LOAD_NODE, *LOAD_SEGMENT): a force
// on each node of a set, or a pressure on faces, times its curve's value at the time (1
// without a curve).
struct Load {
  enum class Kind { force, pressure } kind = Kind::force;
  // force: the nodes. pressure: the faces, a side set of the mesh by name (PART.SET), or the
  // exterior faces whose four nodes a node selection holds.
  Selection target;
  Vec3 force;          // N on each node
  double pressure = 0; // Pa; positive pushes into the body, against the outward normal
  std::optional<TimeCurve> curve;
  // The load acts from `birth` to `death` (s; LS-DYNA's AT of *LOAD_SEGMENT is a birth),
  // and is 0 outside.
  double birth = 0, death = std::numeric_limits<double>::infinity();
  double factor(double t) const {
    return birth <= t && t < death ? (curve ? curve->at(t) : 1.0) : 0.0;
  }
  SourceLocation where;
};

// General contact (DESIGN.md section 4): node-to-face penalty contact among the exterior
// faces of the listed parts, self-contact included.
struct ContactConfig {
  std::vector<std::string> parts;   // empty: all parts
  double penalty_scale = 0.1;       // k = scale K A^2 / V of the face's element
  double friction = 0;              // Coulomb coefficient
  double depth_fraction = 0.5;      // deepest penetration treated, in element depths V / A
  double rebalance_threshold = 1.2; // recompute the contact RCB when max/mean load exceeds it
  SourceLocation where;
};

// A planar rigid wall: nodes stay on the side the normal points to.
struct RigidWallConfig {
  Vec3 point;
  Vec3 normal; // unit
  double friction = 0;
  SourceLocation where;
};

// A probe: the node or particle nearest a point (`probes`), or the element whose centroid
// at t = 0 is nearest it (`element_probes`, deck key `element_at`).
struct ProbeConfig {
  std::string name;
  Vec3 at;
  SourceLocation where;
  // An element probe of a keyword deck's *DATABASE_HISTORY_SOLID: the element with this
  // id (its mesh's), whatever shares its centroid; -1: the nearest to `at`.
  std::int64_t element_id = -1;
};

// Which field files a run writes (DESIGN.md section 4, `output.format`).
enum class OutputFormat { vtu, exodus, both };

// How the model is divided among the ranks (docs/cycle.md, "The decompositions").
struct DecompositionConfig {
  // The static FE decomposition: METIS k-way on the element dual graph (the paper used
  // Chaco), or a recursive coordinate bisection of the element centres, both weighing
  // each element by its formulation's cost.
  enum class Fe { metis, rcb };
  Fe fe = Fe::metis;
  // Every RCB (the FE one with fe: rcb, the contact and the SPH decompositions) chooses
  // its cut directions in coordinates stretched by these factors (LS-DYNA's SX, SY, SZ
  // of *CONTROL_MPP_DECOMPOSITION_TRANSFORMATION): [1, 1, 0.25] makes cuts across z rare.
  Vec3 scale{1, 1, 1};
};

struct Config {
  std::string title;
  std::string deck_file;
  double end_time = std::numeric_limits<double>::infinity();
  std::int64_t end_cycles = std::numeric_limits<std::int64_t>::max();
  double time_step_scale = 0.9;
  double time_step_minimum_fraction = 0; // stop when dt < this * initial dt (0: never)
  // Mass scaling at t = 0 (0: none): elements whose step would be below this get the mass
  // that raises it to this (LS-DYNA's DT2MS < 0 with MS1ST = 1: TSSFAC |DT2MS|), s.
  double mass_scaling_step = 0;
  SourceLocation mass_scaling_where;        // the deck's key or card field, for messages
  double fields_every = 0;                  // 0: first and last only
  double checkpoint_every = 0;              // 0: checkpoints only when stopped by a signal
  std::int64_t checkpoint_every_cycles = 0; // and/or every that many cycles (0: none)
  double history_every = 0;                 // 0: every cycle
  OutputFormat output_format = OutputFormat::vtu;
  bool part_energies = false; // history.csv columns of each part's energies (LS-DYNA's matsum)
  std::vector<MaterialConfig> materials;
  std::vector<PartConfig> parts;
  std::vector<ParticleSetConfig> particles;
  SphConfig sph;
  std::map<std::string, Selection> node_sets;
  std::vector<InitialCondition> initial_conditions;
  std::vector<BoundaryCondition> boundary_conditions;
  std::vector<ProbeConfig> probes;
  std::vector<ProbeConfig> element_probes; // history columns after the probes'

  std::vector<ContactConfig> contact; // at most one
  std::vector<RigidWallConfig> rigid_walls;
  std::vector<BodyLoad> body_loads; // summed
  std::vector<Load> loads;
  DecompositionConfig decomposition;
  // What the reader accepted but could not take over exactly (an LS-DYNA keyword that
  // anvil ignores, a material option it approximates); the command line prints them.
  std::vector<std::string> warnings;

  const MaterialConfig* material(const std::string& name) const;
  // Index of the particle set of that name, or -1.
  int particle_set(const std::string& name) const;
};

} // namespace anvil
