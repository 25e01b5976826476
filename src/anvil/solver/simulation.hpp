// Simulation: owns the model on this rank and advances it one cycle at a time through
// the paper's six phases (DESIGN.md section 1). It holds all state (no globals): nodes,
// element blocks, time, and the decompositions with their exchanges.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "anvil/contact/contact_phase.hpp"
#include "anvil/contact/rigid_wall.hpp"
#include "anvil/core/timer.hpp"
#include "anvil/fe/hex_block.hpp"
#include "anvil/fe/rigid_body.hpp"
#include "anvil/io/config.hpp"
#include "anvil/mesh/mesh.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/parallel/fe_decomposition.hpp"
#include "anvil/sph/sph_phase.hpp"

namespace anvil {

struct Checkpoint;

// Nodal state on this rank, structure of arrays over local nodes (shared nodes appear on
// every rank that touches them, with identical values).
struct NodeState {
  std::array<std::vector<double>, 3> x;  // position at t(n), m
  std::array<std::vector<double>, 3> x0; // reference position, m
  std::array<std::vector<double>, 3> v;  // velocity at t(n - 1/2) (t(n + 1/2) after a step)
  std::array<std::vector<double>, 3> f;  // internal force at t(n), N
  std::vector<double> mass;              // lumped mass, kg
  std::size_t size() const { return mass.size(); }
};

// Time and cycle counters of the central-difference scheme.
struct Clock {
  double time = 0;               // t(n)
  std::int64_t cycle = 0;        // n
  double dt = 0;                 // dt(n + 1/2) of the last step taken
  double dt_prev = 0;            // dt(n - 1/2), the interval the stress update integrates over
  double dt_initial = 0;         // the first step's dt
  std::int64_t dt_particle = -1; // particle controlling dt, or -1 when an element does
};

// The work of external impulses (constraints, gravity, loads) over a step: an impulse J
// that takes a velocity component from v(n - 1/2) to v(n + 1/2) does J v(n) in all, of
// which J (v(n - 1/2) + 3 v(n + 1/2)) / 8 after t(n) (docs/cycle.md "Energies").
struct ImpulseWork {
  double whole = 0, later = 0;
  void add(double impulse, double v_old, double v_new) {
    whole += impulse * 0.5 * (v_old + v_new);
    later += impulse * 0.125 * (v_old + 3 * v_new);
  }
  ImpulseWork& operator+=(const ImpulseWork& o) {
    whole += o.whole;
    later += o.later;
    return *this;
  }
};

// Global energies and probe values at one time (a history row).
struct Sample {
  double time = 0;
  std::int64_t cycle = 0;
  double dt = 0;
  double kinetic = 0, internal = 0, hourglass = 0, contact = 0, external_work = 0;
  double total() const { return kinetic + internal + hourglass + contact; }
  std::vector<double> probes; // per probe: ux, uy, uz, vx, vy, vz
  // per element probe: its element's stress sxx, syy, szz, sxy, syz, szx (Pa; a thick
  // shell's through-thickness mean) and equivalent plastic strain (0 without plasticity)
  std::vector<double> element_probes;
  // with `output.part_energies`: per part, then per particle set, its kinetic, internal and
  // hourglass energy (J; the totals' terms split by where they are)
  std::vector<double> part_energies;
  std::vector<double> wall_force; // per rigid wall: normal force, N
  std::vector<double> reaction;   // per boundary condition: fx, fy, fz on its nodes, N
  // per condition that holds rotations (BoundaryCondition::holds_spin), in deck order: the
  // moment it applies to its rigid body about the body's centre of mass (mx, my, mz, N m)
  std::vector<double> reaction_moment;
  // per rigid body (its part, in deck order): the displacement of its centre of mass at
  // the time (ux, uy, uz, m) and its velocity and spin over the step from it (vx, vy, vz,
  // m/s; wx, wy, wz, rad/s: v(n + 1/2), the step's rotation), LS-DYNA's RBDOUT
  std::vector<double> rigid_bodies;
};

class Simulation {
public:
  // Builds the model from the deck on `comm` (collective). Throws InputError on a bad
  // model (sets that select nothing, unreadable mesh).
  Simulation(const Config& config, const Comm& comm);
  // The simulation keeps a reference to its communicator: a temporary would dangle.
  Simulation(const Config& config, const Comm&& comm) = delete;
  ~Simulation();

  // One cycle: fe_forces, sph_forces, predict, contact_detect, contact_correct, update.
  // Throws PhysicsError (on every rank) for an inverted element or non-finite state.
  void step();
  bool finished() const;

  // Global energies and probes at the time of the last step's forces (collective).
  // Also valid before the first step (initial state).
  Sample sample() const;
  // Energy balance error |E - E(0) - W| / max(|E|, |W|, |E(0)|, scale) for a sample;
  // `scale`: the largest |E| or |W| of the run so far (Outputs keeps it), so that a run
  // whose energies all return to about 0 (a driven body brought to rest) does not read
  // its round-off as a 100% error (QA round 31).
  double balance_error(const Sample& s, double scale = 0) const;
  // E(0): the kinetic energy the initial conditions gave (before constraints).
  double initial_energy() const { return initial_energy_; }
  // Smallest element stable time step at the current state (collective; runs the
  // element kernel without advancing anything); `element`, if given, receives the global id
  // of the element that sets it (the smallest of those that do), -1 without elements.
  double stable_time_step(std::int64_t* element = nullptr);
  // Continues from a checkpoint of the same model (any rank count). InputError when it
  // does not match. Collective.
  void restore(const Checkpoint& checkpoint);
  // Asks the run to stop after the current cycle (a signal handler's flag, or a test).
  // The request reaches every rank through the cycle's reduction; stop_requested() then
  // says so on all of them.
  void request_stop() { stop_local_ = true; }
  bool stop_requested() const { return stop_; }
  // This rank's share of the global diagnostics (for checkpoints).
  double external_work_local() const { return external_work_; }
  double contact_energy_local() const { return contact_energy_; }
  std::int64_t eroded_local() const { return eroded_; }

  // Builds the dynamic decompositions for the current state without advancing (the
  // contact RCB of nodes and faces at rest): for `anvil decompose`. Collective.
  void decompose_now();

  const Config& config() const { return config_; }
  const Comm& comm() const { return comm_; }
  const Clock& clock() const { return clock_; }
  const NodeState& nodes() const { return nodes_; }
  const std::vector<HexBlock>& blocks() const { return blocks_; }
  const FeDecomposition& fe() const { return fe_; }
  const PhaseTimers& timers() const { return timers_; }
  const ContactPhase* contact() const { return contact_.get(); }
  // Mutable access for tests that drive the contact phase on the current state.
  ContactPhase* contact() { return contact_.get(); }
  // The SPH decomposition and its particles (null without particles).
  const sph::SphPhase* sph() const { return sph_.get(); }
  // Mutable access for tests that set initial fields no deck key expresses (a mode
  // shape); call before the first step.
  sph::SphPhase* sph() { return sph_.get(); }
  std::int64_t global_nodes() const { return global_nodes_; }
  std::int64_t global_elements() const { return global_elements_; }
  // mesh_fingerprint() of the initial global mesh (the same on every rank).
  std::uint64_t mesh_fingerprint() const { return mesh_fingerprint_; }
  // The ids the outputs give local node n and element e of block b: the mesh file's
  // (LS-DYNA NID/EID, Gmsh tag, Exodus id maps) where they do not repeat, else 1..N.
  std::int64_t node_file_id(std::size_t n) const { return node_file_id_[n]; }
  std::int64_t element_file_id(std::size_t b, std::size_t e) const {
    return element_file_id_[b][e];
  }
  // The largest of those ids over all ranks (the Exodus writer stores 64-bit id maps
  // when it exceeds 2^31 - 1).
  std::int64_t max_file_id() const { return max_file_id_; }
  // Of the initial particles (ids, sets, masses, reference positions; 0 without any).
  std::uint64_t particle_fingerprint() const { return particle_fingerprint_; }
  // Each part's mass from its material's density (without mass scaling's), kg.
  const std::vector<double>& part_masses() const { return part_mass_; }
  // Mass scaling (time_step.mass_scaling): the mass it added to each part, kg, and the
  // elements it scaled (over all ranks; zeros without it).
  const std::vector<double>& part_added_masses() const { return part_added_mass_; }
  // Each rigid body's motion over the last step (the same on every rank).
  const std::vector<RigidMotion>& rigid_motions() const { return rigid_motion_; }
  std::int64_t mass_scaled_elements() const { return mass_scaled_elements_; }
  // The element step mass scaling raises the elements to (step / scale), or 0 without it.
  double mass_scaling_target() const {
    return config_.mass_scaling_step > 0 ? config_.mass_scaling_step / config_.time_step_scale
                                         : 0.0;
  }
  // Global element id -> part name (for messages).
  std::string describe_element(std::int64_t gid) const;
  // Per external load, the faces it presses or the nodes it pushes, over all ranks
  // (collective).
  std::vector<std::int64_t> load_targets() const;
  // Per external load, the area of the faces it presses now, m^2 (0 for a force; the sum
  // of each face's |vector area|; collective).
  std::vector<double> pressed_area() const;
  // What the setup found questionable (the same on every rank), for the user.
  const std::vector<std::string>& warnings() const { return warnings_; }

private:
  void fe_forces();
  void sph_forces();
  void predict();
  void detect_contacts();
  void correct();
  void share_eroded(bool exposing = true);
  // Mass scaling at t = 0: raises each element's mass so that its stable step at rest in
  // its initial shape is at least config_.mass_scaling_step / scale (collective).
  void scale_masses();
  Vec3 mass_center(std::span<const std::int64_t> ids) const;
  // The part index of the rigid part a condition holds as a body (`part:` a rigid part,
  // whole), or -1.
  int rigid_body_of(const BoundaryCondition& bc) const;
  std::vector<std::int64_t> body_nodes(const Mesh& mesh, const Selection& sel) const;
  void warn_of_setup(const Mesh& mesh);
  void apply_walls();             // the rigid walls' part of correct()
  void sample_probe_velocities(); // at the end of correct()
  ContactNodes contact_view();
  void update();
  void warn_if_outside_model(const std::vector<std::int64_t>& ids, const SourceLocation& where);
  void apply_initial_conditions(const Mesh& mesh);
  void apply_boundary_conditions(const Mesh& mesh);
  void update_prescribed_motions(double t, double dt);
  void refresh_node_constraints();
  void refresh_particle_constraints();
  // External loads (loads.cpp): resolved at setup; the pressed faces' corner forces at t(n)
  // before the corner exchange, the loads' nodal forces added after it; their work over the
  // step before (predict).
  void setup_loads(const Mesh& mesh);
  void setup_rigid_bodies(const Mesh& mesh);
  void gather_rigid_points(bool with_contact);
  void move_rigid_bodies(bool with_contact);
  void warn_of_thin_rigid_parts(const std::vector<std::size_t>& parts);
  void press_faces();
  void add_loads();
  void add_load_work(double dt_v, ImpulseWork& work) const;
  std::array<double, 3> body_acceleration(double t) const;
  void locate_probes(const Mesh& mesh);
  void locate_element_probes();
  std::vector<double> part_energies() const; // this rank's share of Sample::part_energies
  double owned_kinetic_energy() const;
  // Particles: selection (mask over own particles), conditions, their part of predict,
  // contact and update (sph_coupling.cpp).
  std::vector<std::uint8_t> select_particles(const Selection& sel) const;
  // The mesh nodes of a selection that may also (or only) select particles: an
  // InputError when it selects neither nodes nor particles on any rank. Collective.
  std::vector<std::int64_t> selected_nodes(const Mesh& mesh, const Selection& sel) const;
  void apply_particle_conditions();
  void apply_particle_boundary_conditions();
  double particle_bc_velocity(int k, std::size_t i) const;
  double particle_kinetic_energy() const;
  double particle_internal_energy() const;
  void predict_particles(double dt_avg, double& ke, ImpulseWork& work);
  std::vector<ContactNodeItem>& particle_contact_items(double dt);
  void correct_particles(double& contact_work, double& kinetic, double& reaction);
  void sample_particle_probe_velocities();
  void update_particles(double dt);
  // restore() for the particles; `from` names the checkpoint in messages. Collective.
  void restore_particles(const Checkpoint& c, const std::string& from);
  // Particles of the sets in contact that start inside an element of a part in contact
  // (global count; the setup's warning). Collective.
  std::int64_t particles_inside_contact_parts(const Mesh& mesh) const;
  // The mesh blocks (parts) in contact, ascending.
  std::vector<std::size_t> contact_blocks(const Mesh& mesh) const;
  // Setup warning: owned contact nodes that start inside an element of a part in contact.
  void warn_of_initial_overlap(const Mesh& mesh);

  Config config_;
  const Comm& comm_;
  FeDecomposition fe_;
  std::unique_ptr<CornerExchange> corner_exchange_;
  std::vector<std::unique_ptr<Material>> materials_;
  std::vector<HexBlock> blocks_;
  HexWorkspace workspace_;
  std::array<CornerArray, 3> corner_force_;
  std::array<std::vector<double>, 3> v_prev_; // v(n-1/2) of the current step (energy accounting)
  NodeState nodes_;
  Clock clock_;
  PhaseTimers timers_;

  // Constraints: per local node a mask of constrained components (fixed or prescribed)
  // and the prescribed velocity (0 where fixed).
  std::vector<std::uint8_t> constrained_;
  std::array<std::vector<double>, 3> v_bc_;
  std::vector<int> constrained_nodes_; // local nodes some condition holds (active or not)
  // The conditions that hold them, per constrained node j and component i, in deck order:
  // holders_[holder_start_[3 j + i], holder_start_[3 j + i + 1]).
  std::vector<int> holder_start_, holders_;
  // Prescribed motions with a time history: each condition's factor on its value for the
  // current step (1 without a curve; update_prescribed_motions), and the node components
  // whose v_bc_ follows one (the condition that prescribes them last in the deck).
  struct CurvedComponent {
    int node;
    int component;
    int condition;
  };
  std::vector<double> motion_factor_;
  std::vector<std::uint8_t> bc_active_; // per condition: 1 if it holds over the current step
  double gravity_[3] = {0, 0, 0};       // body acceleration of the current step, m/s^2
  std::int64_t stalled_steps_ = 0;      // steps in a row that did not advance the time
  std::vector<CurvedComponent> curved_components_;
  // External loads (deck `loads`). The faces pressed on this rank's elements, ascending
  // (element gid, face, load), with their corners' forces under a unit pressure at t(n)
  // (12 values per face, for the work); the pressure corner forces of the step, per slot
  // (empty without pressures), exchanged with the element forces; the nodes whose sums they
  // enter (on any rank), ascending; the forces on nodes, ascending (node, load); all the
  // loaded nodes, ascending, and their load force of the step.
  struct PressedFace {
    std::int64_t gid;
    int block, element, face, load;
  };
  struct NodalForce {
    int node, load;
  };
  std::vector<PressedFace> pressed_;
  std::array<std::vector<double>, 3> load_corner_;
  std::vector<int> pressure_nodes_;
  std::vector<NodalForce> nodal_forces_;
  std::vector<int> loaded_nodes_;
  std::array<std::vector<double>, 3> f_load_;
  std::vector<double> load_factor_; // per load, its curve's value at t(n) (1 without one)
  // Per local node and component: the condition that constrains it (-1: none), and the
  // force it applies there over the current step, N (predict, correct; summed per
  // condition by sample()). The particles' reactions, per own particle, in p_reaction_.
  std::array<std::vector<int>, 3> bc_source_;
  std::array<std::vector<double>, 3> bc_reaction_;
  struct ReactionTerm { // one constrained component's force, for the ordered sum
    std::int64_t key;   // node gid, or global node count + particle gid
    std::int32_t condition, component;
    std::int32_t part; // 0: the impulse of t = 0 (below), 1: the step's force
    double force;
  };
  // The impulses (N s) that set constrained components at t = 0, on owned nodes and own
  // particles: added to the first row's reactions.
  std::vector<ReactionTerm> initial_impulses_;
  std::vector<double> reactions() const;

  // Contact (null without a contact definition): the contact decomposition and the
  // contact force per local node of the current cycle.
  std::unique_ptr<ContactPhase> contact_;
  std::array<std::vector<double>, 3> contact_force_;
  double contact_energy_ = 0; // penalty energy stored plus friction dissipated, owned nodes

  // Rigid walls: normal impulse given to owned nodes in the last step, per wall.
  std::vector<WallHit> wall_hits_; // of the last step (owned nodes, own particles)
  double dt_avg_ = 0;  // the velocity step of the last cycle (mean of the two intervals)
  double dt_full_ = 0; // the last cycle's step before shortening it to the end time

  // Diagnostics accumulated by this rank over owned entities. The work of the constraints'
  // and the loads' impulses of a step is booked whole in its predict() as impulse . v(n),
  // but an impulse acts from t(n - 1/2) to t(n + 1/2) while the velocity goes from
  // v(n - 1/2) to v(n + 1/2): the part after t(n), impulse . (v(n - 1/2) + 3 v(n + 1/2)) / 8
  // (the velocity taken linear over the interval), is work_later_, which sample() leaves
  // for the next row. With the kinetic energy of v(n) = (v(n - 1/2) + v(n + 1/2)) / 2 the
  // two agree exactly on a node that only these impulses move.
  double external_work_ = 0;
  double work_later_ = 0;
  double initial_energy_ = 0;
  bool have_initial_energy_ = false;

  // Probes: local node index on the owning rank, -1 elsewhere; or the global id of the
  // probed particle (-1: the probe is on a node).
  std::vector<int> probe_node_;
  std::vector<std::int64_t> probe_particle_;
  // Rigid bodies (parts with `rigid`, solver/rigid.cpp): per body, its nodes' global ids in
  // ascending order (every rank knows them: the global mesh's) and where its points start
  // in rigid_points_; this rank's nodes of rigid bodies (rigid_node_: 1 per such local
  // node); the buffers of the cycle's gather, and each body's motion over the step.
  struct RigidNode {
    int body, slot, local;
    bool owned;
  };
  struct RigidRecord {
    std::int64_t at; // body offset + slot
    RigidPoint p;
  };
  std::vector<std::vector<std::int64_t>> rigid_gids_;
  std::vector<std::size_t> rigid_offset_;
  std::vector<std::size_t> rigid_part_; // the part of each body
  std::vector<RigidNode> rigid_nodes_;
  std::vector<std::uint8_t> rigid_node_;
  std::vector<RigidRecord> rigid_send_, rigid_recv_;
  std::vector<std::int64_t> rigid_bytes_;
  std::vector<RigidPoint> rigid_points_;
  std::vector<RigidMotion> rigid_motion_;
  // The boundary conditions that hold a rigid body (`part:` naming a rigid part): per
  // condition, its body or -1; per body and component (x, y, z, then the rotations about
  // x, y, z), the condition that holds it over the current step, or -1.
  std::vector<int> condition_body_;
  std::vector<Vec3> rigid_centre0_; // each body's centre of mass at t = 0
  std::vector<std::array<int, 6>> rigid_holder_;
  // The rigid walls as the bodies meet them (apply_walls_to_body), per body point whether
  // its node is owned here, and the hits of the step's last motion on the owned points
  // (joined to the nodes' in apply_walls()).
  std::vector<WallPlane> wall_planes_;
  std::vector<std::uint8_t> rigid_point_owned_;
  BodyWallScratch body_wall_scratch_;
  std::vector<WallImpulse> body_wall_impulses_;
  std::vector<WallHit> rigid_wall_hits_;

  // Element probes: (block, element) on the rank that holds the element, (-1, -1) elsewhere.
  std::vector<std::array<int, 2>> element_probe_;

  // SPH (null without particles): the particle decomposition, the velocities v(n-1/2)
  // of its own particles in the current step, the particle sets in contact and the
  // contact items of this cycle.
  std::unique_ptr<sph::SphPhase> sph_;
  std::array<std::vector<double>, 3> pv_prev_;
  std::array<std::vector<double>, 3> p_reaction_;
  std::vector<std::uint8_t> sph_contact_set_;
  std::vector<ContactNodeItem> particle_items_;
  std::vector<int> particle_item_index_;
  std::vector<std::uint8_t> particle_owned_; // all ones (rigid walls' view)

  // What predict() records for the sample at t(n): kinetic energy of owned nodes at the
  // mid-point velocity and the probe values (zero on ranks that do not own the probe).
  double sample_time_ = 0;
  std::int64_t sample_cycle_ = 0;
  double sample_dt_ = 0;
  double kinetic_local_ = 0;
  std::vector<double> probe_local_;

  double dt_stable_ = 0; // from the last fe_forces
  bool stop_local_ = false, stop_ = false;
  std::int64_t eroded_ = 0; // elements this rank has eroded
  // Per block and element: 1 once share_eroded() has told the contact phase it eroded.
  std::vector<std::vector<std::uint8_t>> erosion_shared_;
  // share_eroded()'s buffers (kept: an erosion cycle allocates only past their size)
  std::vector<std::int64_t> erosion_mine_, erosion_fresh_, erosion_bytes_;
  // This rank's smallest element step and its element: the controlling element is found
  // from them (one more reduction) only when a message needs it.
  double dt_stable_local_ = 0;
  std::int64_t stable_gid_local_ = -1;
  std::int64_t global_nodes_ = 0, global_elements_ = 0;
  std::vector<std::string> warnings_;
  std::uint64_t mesh_fingerprint_ = 0;
  std::uint64_t particle_fingerprint_ = 0;
  std::vector<std::int64_t> node_file_id_;                 // per local node
  std::vector<std::vector<std::int64_t>> element_file_id_; // per block and element
  std::int64_t max_file_id_ = 0;                           // of both, over all ranks
  std::vector<std::int64_t> block_offsets_;
  std::vector<double> part_mass_;
  std::vector<double> part_added_mass_;
  std::int64_t mass_scaled_elements_ = 0;
};

} // namespace anvil
