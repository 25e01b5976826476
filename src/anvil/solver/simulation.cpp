#include "anvil/solver/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "anvil/contact/rigid_wall.hpp"
#include "anvil/core/hash.hpp"
#include "anvil/core/nearest.hpp"
#include "anvil/core/simd.hpp"
#include "anvil/io/checkpoint.hpp"
#include "anvil/solver/model.hpp"

namespace anvil {

Simulation::~Simulation() = default;

Simulation::Simulation(const Config& config, const Comm& comm) : config_(config), comm_(comm) {
  // The global mesh is built on every rank (generators and readers are deterministic);
  // every rank gets the same owner of every element (partition_model).
  const Mesh mesh = build_mesh(config_);
  global_elements_ = mesh.num_elements();
  mesh_fingerprint_ = anvil::mesh_fingerprint(mesh);
  block_offsets_ = mesh.block_offsets();
  const std::vector<int> owner = partition_model(mesh, config_, comm_);
  fe_ = decompose_fe(mesh, owner, comm_.rank(), comm_.size());
  // With pressure loads the exchange carries their corner forces too (loads.cpp).
  const bool pressures = std::any_of(config_.loads.begin(), config_.loads.end(),
                                     [](const Load& l) { return l.kind == Load::Kind::pressure; });
  corner_exchange_ = std::make_unique<CornerExchange>(fe_, comm_, pressures ? 6 : 3);
  // Nodes that no element uses (mid-side nodes of imported quadratic elements, stray
  // points) take no part in the run and are not counted.
  global_nodes_ = comm_.sum(fe_.num_owned_nodes());

  // Nodes.
  const std::size_t nn = fe_.node_gid.size();
  for (int i = 0; i < 3; ++i) {
    nodes_.x[i].resize(nn);
    nodes_.v[i].assign(nn, 0.0);
    nodes_.f[i].assign(nn, 0.0);
    v_prev_[i].assign(nn, 0.0);
  }
  for (std::size_t n = 0; n < nn; ++n)
    for (int i = 0; i < 3; ++i) nodes_.x[i][n] = mesh.nodes[fe_.node_gid[n]][i];
  nodes_.x0 = nodes_.x;
  nodes_.mass.assign(nn, 0.0);

  // Materials and element blocks (one per part).
  for (const auto& m : config_.materials)
    materials_.push_back(make_material(m.model, m.params, m.tables, m.eos_model, m.eos_params));
  auto material_of = [&](const std::string& name) -> const Material* {
    for (std::size_t i = 0; i < config_.materials.size(); ++i)
      if (config_.materials[i].name == name) return materials_[i].get();
    return nullptr;
  };
  for (int i = 0; i < 3; ++i) corner_force_[i].assign(fe_.total_slots(), 0.0);
  CornerArray& corner_mass = corner_force_[0]; // reused once for the mass
  const double* xs[3] = {nodes_.x[0].data(), nodes_.x[1].data(), nodes_.x[2].data()};
  for (std::size_t b = 0; b < config_.parts.size(); ++b) {
    const auto& part = config_.parts[b];
    const auto& lb = fe_.blocks[b];
    HexBlock hb;
    hb.name = part.name;
    hb.part = static_cast<int>(b);
    hb.material = material_of(part.material);
    hb.hourglass = part.hourglass;
    hb.bulk_viscosity = part.bulk_viscosity;
    hb.erosion = part.erosion;
    hb.thick_shell = part.thick_shell;
    hb.rigid = part.rigid;
    const int bad = hb.init(lb.gid, lb.conn, xs, lb.corner_base);
    // Every rank must throw, not only the one holding the element.
    const std::int64_t none = std::numeric_limits<std::int64_t>::max();
    const std::int64_t bad_gid = comm_.min(bad >= 0 ? hb.gid[bad] : none);
    if (bad_gid != none) {
      const double v = comm_.min(bad >= 0 && hb.gid[bad] == bad_gid ? hb.volume[bad] : 1e300);
      const std::int64_t id =
          mesh.blocks[b].id(static_cast<std::size_t>(bad_gid - block_offsets_[b]));
      const Shape shape =
          shape_of(mesh.blocks[b].elements[static_cast<std::size_t>(bad_gid - block_offsets_[b])]);
      // "element 12 (a tetrahedron) of part p in mesh file m.msh"
      const std::string which = fmt::format(
          "element {}{} of part {}{}", id,
          shape == Shape::hexahedron ? "" : fmt::format(" (a {})", shape_name(shape)), part.name,
          part.mesh.kind == MeshConfig::Kind::file ? fmt::format(" in mesh file {}", part.mesh.file)
                                                   : "");
      if (!(v > 0))
        throw InputError(part.mesh.where,
                         fmt::format("{} has a non-positive volume ({:.3g} m^3): check the node "
                                     "order",
                                     which, v));
      throw InputError(part.mesh.where,
                       fmt::format("{} is tangled: its volume is positive ({:.3g} m^3) but its "
                                   "Jacobian at the centre is not: check the node order",
                                   which, v));
    }
    hb.corner_rows = lb.exchanged_vectors; // the other nodes are summed in the kernel
    blocks_.push_back(std::move(hb));
  }
  part_mass_.assign(config_.parts.size(), 0.0);
  for (const auto& b : blocks_)
    for (int e = 0; e < b.size(); ++e) part_mass_[b.part] += b.mass[e];
  comm_.sum(std::span<double>(part_mass_));
  scale_masses();
  for (std::size_t b = 0; b < blocks_.size(); ++b)
    for (int e = 0; e < blocks_[b].size(); ++e)
      for (int a = 0; a < 8; ++a)
        corner_mass[fe_.blocks[b].slot(static_cast<std::size_t>(e), a)] =
            blocks_[b].scaled_mass(static_cast<std::size_t>(e)) *
            blocks_[b].corner_share(static_cast<std::size_t>(e), a);
  corner_exchange_->exchange({corner_mass.data()});
  gather_corners(fe_, {corner_mass.data()}, {nodes_.mass.data()});
  std::fill(corner_mass.begin(), corner_mass.end(), 0.0);

  // The mesh files' ids for the outputs, where they do not repeat (a model assembled from
  // several files may repeat them: then 1..N in global order, as for generated meshes).
  {
    const bool node_ids = mesh.node_ids_unique(), element_ids = mesh.element_ids_unique();
    node_file_id_.resize(nn);
    for (std::size_t n = 0; n < nn; ++n)
      node_file_id_[n] =
          node_ids ? mesh.node_id(static_cast<std::size_t>(fe_.node_gid[n])) : fe_.node_gid[n] + 1;
    element_file_id_.resize(blocks_.size());
    for (std::size_t b = 0; b < blocks_.size(); ++b)
      for (int e = 0; e < blocks_[b].size(); ++e) {
        const std::int64_t gid = blocks_[b].gid[static_cast<std::size_t>(e)];
        element_file_id_[b].push_back(
            element_ids ? mesh.blocks[b].id(static_cast<std::size_t>(gid - block_offsets_[b]))
                        : gid + 1);
      }
    // (The same on every rank: the global mesh's.) Said, so that ids a user looks for in
    // the outputs are not silently others (QA round 13).
    // Only where a file gave ids that are dropped: generated parts number their elements
    // from 1 each, which repeat between parts by design.
    const bool file_elements = std::any_of(mesh.blocks.begin(), mesh.blocks.end(),
                                           [](const auto& b) { return !b.ids.empty(); });
    for (const auto& [dropped, what] : {std::pair{!node_ids && !mesh.node_ids.empty(), "node"},
                                        {!element_ids && file_elements, "element"}})
      if (dropped)
        warnings_.push_back(fmt::format(
            "{}: the mesh files' {} ids repeat in the model (the same file in two parts, or a "
            "generated part whose numbers meet a file's): the outputs and messages number the "
            "{}s 1..N in model order instead (docs/meshes.md, \"Ids in the outputs\")",
            config_.deck_file, what, what));
    std::int64_t top = 0;
    for (const auto id : node_file_id_) top = std::max(top, id);
    for (const auto& ids : element_file_id_)
      for (const auto id : ids) top = std::max(top, id);
    max_file_id_ = comm_.max(top);
  }

  if (!config_.contact.empty()) {
    contact_ = std::make_unique<ContactPhase>(config_.contact[0], mesh, fe_, blocks_, comm_,
                                              config_.decomposition.scale);
    for (auto& f : contact_force_) f.assign(nn, 0.0);
  }
  if (!config_.particles.empty()) {
    sph_ = std::make_unique<sph::SphPhase>(
        config_,
        [&](int set) {
          return material_of(config_.particles[static_cast<std::size_t>(set)].material);
        },
        comm_);
    warnings_.insert(warnings_.end(), sph_->notes().begin(), sph_->notes().end());
    // The particles' fingerprint, as the mesh's: of each particle's id, set, mass and
    // reference position, summed over the particles (in two 32-bit halves, so that the
    // sums neither overflow nor depend on which rank holds which particle).
    {
      const sph::Particles& pt = sph_->particles();
      std::int64_t halves[2] = {0, 0};
      for (std::size_t q = 0; q < pt.size(); ++q) {
        Fnv1a h;
        h.bytes(&pt.gid[q], sizeof pt.gid[q]).bytes(&pt.set[q], sizeof pt.set[q]);
        h.bytes(&pt.mass[q], sizeof pt.mass[q]);
        for (int i = 0; i < 3; ++i) h.bytes(&pt.x0[i][q], sizeof(double));
        halves[0] += static_cast<std::int64_t>(h.value() & 0xffffffffu);
        halves[1] += static_cast<std::int64_t>(h.value() >> 32);
      }
      comm_.sum(std::span<std::int64_t>(halves, 2));
      particle_fingerprint_ = Fnv1a().bytes(halves, sizeof halves).value();
    }
    // Particle sets in contact: all of them with `parts: all`, else those listed.
    sph_contact_set_.assign(config_.particles.size(), 0);
    if (contact_)
      for (std::size_t s = 0; s < config_.particles.size(); ++s)
        sph_contact_set_[s] =
            config_.contact[0].parts.empty() ||
            std::find(config_.contact[0].parts.begin(), config_.contact[0].parts.end(),
                      config_.particles[s].name) != config_.contact[0].parts.end();
  }
  // Every deck node set must select something (deck.md), used or not: a set that
  // selects nothing is a mistake whether or not a condition names it yet.
  for (const auto& [name, sel] : config_.node_sets) (void)selected_nodes(mesh, sel);
  apply_initial_conditions(mesh);
  // Constraints stop the constrained velocity components at once (a node on a fixed
  // impact face hits the wall at t = 0): the kinetic energy they remove is work done by
  // the constraint, so that the energy balance starts from the energy the deck gave.
  const double ke_given = comm_.sum(owned_kinetic_energy() + particle_kinetic_energy());
  apply_boundary_conditions(mesh);
  setup_rigid_bodies(mesh);
  setup_loads(mesh);
  locate_probes(mesh);
  locate_element_probes();

  // The initial sample (t = 0): kinetic energy of the initial velocities, probes at rest
  // position with their initial velocity.
  kinetic_local_ = owned_kinetic_energy() + particle_kinetic_energy();
  probe_local_.assign(6 * config_.probes.size(), 0.0);
  for (std::size_t p = 0; p < probe_node_.size(); ++p) {
    if (probe_node_[p] >= 0)
      for (int i = 0; i < 3; ++i) probe_local_[6 * p + 3 + i] = nodes_.v[i][probe_node_[p]];
    const int q = probe_particle_[p] >= 0 ? sph_->find(probe_particle_[p]) : -1;
    if (q >= 0)
      for (int i = 0; i < 3; ++i) probe_local_[6 * p + 3 + i] = sph_->particles().v[i][q];
  }
  // The energy the deck gave: kinetic (before constraints) plus the particles' initial
  // internal energy (a gas's).
  initial_energy_ = ke_given + comm_.sum(particle_internal_energy());
  const double ke_kept = comm_.sum(kinetic_local_);
  if (comm_.rank() == 0) external_work_ = ke_kept - ke_given; // counted once, on rank 0
  warn_of_setup(mesh);
}

// What the setup finds questionable, for the user: nodes and particles that start behind
// a rigid wall (the first step puts them on it, with whatever velocity that takes: a deck
// may mean it, or a wall cuts a corner), probes outside the model (each takes the
// nearest node or particle, wherever that is), and particle contact that cannot act:
// particles meet only element faces, so a contact of particle sets alone touches nothing,
// and particles that start inside an element in contact never came through its faces.
// Collective.
void Simulation::warn_of_setup(const Mesh& mesh) {
  // The model's bounding box, for the tolerances.
  Vec3 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          std::numeric_limits<double>::infinity()};
  Vec3 hi = -1.0 * lo;
  auto extend = [&](double x, double y, double z) {
    const Vec3 q{x, y, z};
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::min(lo[i], q[i]);
      hi[i] = std::max(hi[i], q[i]);
    }
  };
  for (std::size_t n = 0; n < nodes_.size(); ++n)
    extend(nodes_.x[0][n], nodes_.x[1][n], nodes_.x[2][n]);
  const sph::Particles* pt = sph_ ? &sph_->particles() : nullptr;
  if (pt)
    for (std::size_t k = 0; k < pt->size(); ++k) extend(pt->x[0][k], pt->x[1][k], pt->x[2][k]);
  double box[6] = {lo.x, lo.y, lo.z, -hi.x, -hi.y, -hi.z};
  comm_.min(std::span<double>(box, 6));
  lo = {box[0], box[1], box[2]};
  hi = {-box[3], -box[4], -box[5]};
  const double size = std::isfinite(lo.x) ? norm(hi - lo) : 0.0;

  const auto& walls = config_.rigid_walls;
  std::vector<std::int64_t> behind(walls.size(), 0);
  for (std::size_t w = 0; w < walls.size(); ++w) {
    auto gap = [&](double x, double y, double z) {
      return dot(Vec3{x, y, z} - walls[w].point, walls[w].normal);
    };
    const double tol = 1e-9 * size;
    // (Those the wall leaves alone, fixed in every direction it could move them, aside; a
    // rigid body's nodes, constrained to the body, are moved through it.)
    const Vec3 nrm = walls[w].normal;
    for (std::size_t n = 0; n < nodes_.size(); ++n)
      if (fe_.node_owned[n] &&
          (wall_can_move(nrm, constrained_[n]) || (!rigid_node_.empty() && rigid_node_[n] != 0)) &&
          gap(nodes_.x[0][n], nodes_.x[1][n], nodes_.x[2][n]) < -tol)
        ++behind[w];
    if (pt)
      for (std::size_t k = 0; k < pt->size(); ++k)
        if (wall_can_move(nrm, pt->constrained[k]) &&
            gap(pt->x[0][k], pt->x[1][k], pt->x[2][k]) < -tol)
          ++behind[w];
  }
  comm_.sum(std::span<std::int64_t>(behind));
  for (std::size_t w = 0; w < walls.size(); ++w)
    if (behind[w] > 0)
      warnings_.push_back(fmt::format(
          "{}: {} nodes or particles start behind rigid wall {}; the first step moves them "
          "onto it (with the velocity that takes; its impulse is external work)",
          walls[w].where.str(), behind[w], w));
  if (contact_ && sph_ &&
      std::find(sph_contact_set_.begin(), sph_contact_set_.end(), 1) != sph_contact_set_.end()) {
    const auto& listed = config_.contact[0].parts;
    const bool any_part =
        std::any_of(config_.parts.begin(), config_.parts.end(), [&](const PartConfig& p) {
          return listed.empty() || std::find(listed.begin(), listed.end(), p.name) != listed.end();
        });
    if (!any_part)
      warnings_.push_back(fmt::format(
          "{}: contact lists particle sets but no finite-element part: particles touch only "
          "the faces of elements in contact, so they touch nothing (list the parts they hit)",
          config_.contact[0].where.str()));
    else if (const std::int64_t inside = particles_inside_contact_parts(mesh); inside > 0)
      warnings_.push_back(fmt::format(
          "{}: {} particle{} start{} inside elements of parts in contact; contact takes a "
          "particle only when it comes through a face, so it ignores {}",
          config_.contact[0].where.str(), inside, inside == 1 ? "" : "s", inside == 1 ? "s" : "",
          inside == 1 ? "it" : "these"));
  }
  if (contact_) warn_of_initial_overlap(mesh);
  for (const auto* probes : {&config_.probes, &config_.element_probes})
    for (const auto& probe : *probes) {
      const double margin = 0.01 * size;
      bool outside = false;
      for (int i = 0; i < 3; ++i)
        outside |= probe.at[i] < lo[i] - margin || probe.at[i] > hi[i] + margin;
      if (outside)
        warnings_.push_back(fmt::format(
            "{}: probe {} at [{:g}, {:g}, {:g}] lies outside the model (its bounding box); it "
            "follows the nearest {}",
            probe.where.str(), probe.name, probe.at.x, probe.at.y, probe.at.z,
            probes == &config_.probes ? "node or particle" : "element"));
    }
  // A spin given to particles of a solid with the plain SPH gradient: the plain gradient
  // does not reproduce a rigid rotation where a kernel is cut by the free surface, so
  // the spin turns into spurious strain and the body stops turning (QA round 14: a ball
  // at 1e4 rad/s lost 99% of its angular momentum in 0.3 ms; docs/sph.md, Verification).
  if (pt)
    for (const auto& ic : config_.initial_conditions) {
      if (norm(ic.angular_velocity) == 0.0) continue;
      const auto mask = select_particles(ic.nodes);
      std::vector<std::int64_t> spun(config_.particles.size(), 0);
      for (std::size_t k = 0; k < pt->size(); ++k)
        if (mask[k]) ++spun[static_cast<std::size_t>(pt->set[k])];
      comm_.sum(std::span<std::int64_t>(spun));
      for (std::size_t s = 0; s < spun.size(); ++s) {
        const ParticleSetConfig& ps = config_.particles[s];
        const MaterialConfig* mat = config_.material(ps.material);
        if (spun[s] == 0 || ps.corrected_gradient ||
            (mat && (mat->model == "ideal_gas" || mat->model == "fluid")))
          continue;
        warnings_.push_back(fmt::format(
            "{}: particle set '{}' is given an angular velocity with the plain SPH gradient, "
            "which does not reproduce a rigid rotation near a free surface: the spin turns "
            "into spurious strain and the body stops turning; set corrected_gradient: true "
            "(a keyword deck: *CONTROL_SPH FORM 1; docs/sph.md, Verification: spinning ball)",
            ic.where.str(), ps.name));
      }
    }
  // Summation density on a liquid or a solid (QA round 22): a free-surface particle misses
  // neighbours, so its summed density falls short of the material's and a stiff equation
  // of state puts the surface in strong tension. 27 water particles at rest gained 4.4 J
  // from nothing; moving, 5.8e6 J from 1.2 J, with exit status 0. The option is for gases
  // (docs/sph.md).
  for (const auto& ps : config_.particles) {
    const MaterialConfig* mat = config_.material(ps.material);
    if (!ps.summation_density || (mat && mat->model == "ideal_gas")) continue;
    warnings_.push_back(fmt::format(
        "{}: particle set '{}' uses summation_density with material '{}', which is not a gas: "
        "at a free surface the summed density falls short of the material's and its equation "
        "of state pulls the surface together, which can create energy without bound; use the "
        "continuity density (the default) for liquids and solids (docs/sph.md)",
        ps.where.str(), ps.name, ps.material));
  }
  // A condition or a load born at or after the end never acts (QA round 26).
  if (std::isfinite(config_.end_time)) {
    auto unborn = [&](const SourceLocation& where, double birth, const char* what) {
      if (birth >= config_.end_time)
        warnings_.push_back(fmt::format("{}: the {} is born at t = {:g} s, not before the end "
                                        "time {:g} s: it never acts",
                                        where.str(), what, birth, config_.end_time));
    };
    for (const auto& bc : config_.boundary_conditions) unborn(bc.where, bc.birth, "condition");
    for (const auto& load : config_.loads) unborn(load.where, load.birth, "load");
  }
  // A body load or a prescribed motion across the plane (line) of a 2-D (1-D) particle
  // model: held by the plane's constraint, it does nothing (QA round 23c: a z gravity in a
  // plane model, almost always meant along y; round 24: a motion). Such a model has no mesh
  // (it cannot be coupled to one), so every condition is on particles.
  const int dims = config_.sph.dimensions;
  auto across = [&](const SourceLocation& where, const char* what, int i) {
    warnings_.push_back(fmt::format(
        "{}: the {} {} component acts across this {}-D model's {} and moves nothing (the "
        "model's constraint holds it); a {}-D model moves along {}",
        where.str(), what, "xyz"[i], dims, dims == 2 ? "plane" : "line", dims,
        dims == 2 ? "x and y" : "x"));
  };
  if (pt && dims < 3)
    for (int i = dims; i < 3; ++i) {
      for (const auto& load : config_.body_loads)
        if (load.acceleration[i] != 0.0) across(load.where, "body load's", i);
      for (const auto& bc : config_.boundary_conditions)
        if (bc.prescribed && bc.components[static_cast<std::size_t>(i)] && bc.value[i] != 0.0)
          across(bc.where, "prescribed", i);
    }
}

std::vector<std::size_t> Simulation::contact_blocks(const Mesh& mesh) const {
  const auto& listed = config_.contact[0].parts;
  std::vector<std::size_t> blocks;
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b)
    if (listed.empty() ||
        std::find(listed.begin(), listed.end(), mesh.blocks[b].name) != listed.end())
      blocks.push_back(b);
  return blocks;
}

// Contact takes a node only when it comes through a face, so a node that starts inside
// another body is never in contact with it, and the bodies pass through each other there
// (QA round 17: a block starting 0.3 mm into a base went through it, without a word).
// LS-DYNA reports such initial penetrations; anvil names the count and the first (by
// global node id) with the element that holds it. Collective.
void Simulation::warn_of_initial_overlap(const Mesh& mesh) {
  const std::vector<std::size_t> blocks = contact_blocks(mesh);
  // The contact surfaces' nodes (where bodies overlap, some of them lie inside the other
  // body; the interior nodes, most of a solid's, need not be tested: QA round 20, 7 s at
  // 2 M elements), each by its owner.
  std::vector<Vec3> points;
  std::vector<std::int64_t> node;
  std::vector<std::size_t> local;
  for (const int l : contact_->force_nodes()) {
    const auto n = static_cast<std::size_t>(l);
    if (n >= fe_.node_gid.size() || !fe_.node_owned[n]) continue;
    const std::int64_t g = fe_.node_gid[n];
    points.push_back(mesh.nodes[static_cast<std::size_t>(g)]);
    node.push_back(g);
    local.push_back(n);
  }
  const auto holder = elements_holding(mesh, blocks, points, node);
  std::int64_t count = 0, first = std::numeric_limits<std::int64_t>::max(), first_local = -1;
  for (std::size_t i = 0; i < holder.size(); ++i)
    if (holder[i] >= 0) {
      ++count;
      if (node[i] < first) {
        first = node[i];
        first_local = static_cast<std::int64_t>(i);
      }
    }
  count = comm_.sum(count);
  if (count == 0) return;
  const std::int64_t winner = comm_.min(first);
  // The first node's file id and its element, from the rank that owns it.
  std::int64_t about[2] = {-1, -1};
  if (first == winner && first_local >= 0) {
    about[0] = node_file_id(local[static_cast<std::size_t>(first_local)]);
    about[1] = holder[static_cast<std::size_t>(first_local)];
  }
  comm_.max(std::span<std::int64_t>(about, 2));
  warnings_.push_back(fmt::format(
      "{}: {} surface node{} of parts in contact start{} inside elements of parts in contact (node "
      "{} "
      "inside {}); contact takes a node only when it comes through a face, so the bodies pass "
      "through each other there: make the meshes touch or part at t = 0 (docs/contact.md, "
      "initial overlap)",
      config_.contact[0].where.str(), count, count == 1 ? "" : "s", count == 1 ? "s" : "", about[0],
      describe_element(about[1])));
}

double Simulation::owned_kinetic_energy() const {
  double ke = 0;
  for (std::size_t n = 0; n < nodes_.size(); ++n)
    if (fe_.node_owned[n])
      ke += 0.5 * nodes_.mass[n] *
            (nodes_.v[0][n] * nodes_.v[0][n] + nodes_.v[1][n] * nodes_.v[1][n] +
             nodes_.v[2][n] * nodes_.v[2][n]);
  return ke;
}

// A selection of mesh nodes none of which an element uses acts on nothing: anvil's model
// holds only the nodes of its elements (QA round 24: a keyword motion on a stray node was
// accepted and did nothing). A warning, not an error: keyword decks hold constraints on the
// nodes of parts anvil leaves out (shells), and say so already. Collective.
void Simulation::warn_if_outside_model(const std::vector<std::int64_t>& ids,
                                       const SourceLocation& where) {
  std::int64_t held = 0;
  for (std::size_t n = 0; n < fe_.node_gid.size(); ++n)
    if (fe_.node_owned[n] && std::binary_search(ids.begin(), ids.end(), fe_.node_gid[n])) ++held;
  if (comm_.sum(held) == 0 && !ids.empty())
    warnings_.push_back(fmt::format("{}: the selection's {} node{} belong{} to no element: "
                                    "anvil's model holds only the nodes of its elements, so "
                                    "this acts on nothing",
                                    where.str(), ids.size(), ids.size() == 1 ? "" : "s",
                                    ids.size() == 1 ? "s" : ""));
}

// The centre of mass of the nodes with global ids `ids` (sorted), from their lumped masses,
// summed in global id order so that every rank count finds the same bits (collective).
Vec3 Simulation::mass_center(std::span<const std::int64_t> ids) const {
  struct Point {
    std::int64_t gid;
    double m, x[3];
  };
  std::vector<Point> mine;
  for (std::size_t n = 0; n < fe_.node_gid.size(); ++n)
    if (fe_.node_owned[n] && std::binary_search(ids.begin(), ids.end(), fe_.node_gid[n]))
      mine.push_back(
          {fe_.node_gid[n], nodes_.mass[n], {nodes_.x[0][n], nodes_.x[1][n], nodes_.x[2][n]}});
  std::vector<Point> all = comm_.allgatherv(std::span<const Point>(mine));
  std::sort(all.begin(), all.end(), [](const Point& a, const Point& b) { return a.gid < b.gid; });
  double m = 0;
  Vec3 mx{0, 0, 0};
  for (const auto& p : all) {
    m += p.m;
    mx += p.m * Vec3{p.x[0], p.x[1], p.x[2]};
  }
  return m > 0 ? mx * (1 / m) : Vec3{0, 0, 0};
}

void Simulation::apply_initial_conditions(const Mesh& mesh) {
  const std::size_t nn = fe_.node_gid.size();
  for (const auto& ic : config_.initial_conditions) {
    const auto ids = body_nodes(mesh, ic.nodes);
    warn_if_outside_model(ids, ic.nodes.where);
    const Vec3 centre = ic.about_mass_center ? mass_center(ids) : ic.center;
    for (std::size_t n = 0; n < nn; ++n) {
      if (!std::binary_search(ids.begin(), ids.end(), fe_.node_gid[n])) continue;
      const Vec3 r = Vec3{nodes_.x[0][n], nodes_.x[1][n], nodes_.x[2][n]} - centre;
      const Vec3 v = ic.velocity + cross(ic.angular_velocity, r);
      for (int i = 0; i < 3; ++i) nodes_.v[i][n] = v[i];
    }
  }
  apply_particle_conditions(); // the particles' initial and boundary conditions
}

void Simulation::apply_boundary_conditions(const Mesh& mesh) {
  const std::size_t nn = fe_.node_gid.size();
  const auto& bcs = config_.boundary_conditions;
  curved_components_.clear();
  constrained_nodes_.clear();
  update_prescribed_motions(0.0, 0.0); // the factors at t = 0
  constrained_.assign(nn, 0);
  for (int i = 0; i < 3; ++i) v_bc_[i].assign(nn, 0.0);
  for (auto& s : bc_source_) s.assign(nn, -1);
  for (auto& r : bc_reaction_) r.assign(nn, 0.0);
  // The conditions that hold each node component, in deck order (a rigid body's conditions
  // hold the body, setup_rigid_bodies).
  std::vector<std::vector<int>> held(3 * nn);
  for (std::size_t b = 0; b < bcs.size(); ++b) {
    const auto& bc = bcs[b];
    if (rigid_body_of(bc) >= 0) continue;
    if (bc.rotations)
      throw InputError(bc.where,
                       "rotations (rx, ry, rz, angular_velocity, rotation) are a rigid body's: "
                       "give `part:` a rigid part (nodes have no rotations)");
    const auto ids = selected_nodes(mesh, bc.nodes);
    warn_if_outside_model(ids, bc.nodes.where);
    for (std::size_t n = 0; n < nn; ++n) {
      if (!std::binary_search(ids.begin(), ids.end(), fe_.node_gid[n])) continue;
      for (std::size_t i = 0; i < 3; ++i)
        if (bc.prescribed ? bc.components[i] : bc.fix[i])
          held[3 * n + i].push_back(static_cast<int>(b));
    }
  }
  holder_start_.assign(1, 0);
  holders_.clear();
  for (std::size_t n = 0; n < nn; ++n) {
    if (held[3 * n].empty() && held[3 * n + 1].empty() && held[3 * n + 2].empty()) continue;
    constrained_nodes_.push_back(static_cast<int>(n));
    for (std::size_t i = 0; i < 3; ++i) {
      holders_.insert(holders_.end(), held[3 * n + i].begin(), held[3 * n + i].end());
      holder_start_.push_back(static_cast<int>(holders_.size()));
    }
  }
  refresh_node_constraints(); // those of the conditions active at t = 0
  initial_impulses_.clear();
  for (const int n : constrained_nodes_)
    for (int i = 0; i < 3; ++i)
      if (constrained_[n] & (1u << i)) {
        if (fe_.node_owned[n] && v_bc_[i][n] != nodes_.v[i][n])
          initial_impulses_.push_back({fe_.node_gid[n], bc_source_[i][n], i, 0,
                                       nodes_.mass[n] * (v_bc_[i][n] - nodes_.v[i][n])});
        nodes_.v[i][n] = v_bc_[i][n];
      }
  apply_particle_boundary_conditions();
}

// The body acceleration at time t: the deck's loads, each times its curve's value then.
std::array<double, 3> Simulation::body_acceleration(double t) const {
  std::array<double, 3> g{0, 0, 0};
  for (const auto& load : config_.body_loads) {
    const double s = load.curve ? load.curve->at(t) : 1.0;
    for (int i = 0; i < 3; ++i) g[i] += load.acceleration[i] * s;
  }
  return g;
}

// The prescribed motions' factors for the step from t to t + dt: a velocity history at
// the mid-step, where central difference places v(n+1/2); a displacement history as the
// velocity that carries the node from d(t) to d(t + dt) exactly, so that the displacement
// follows the curve without drift (with dt = 0, at setup: the rate just after t).
void Simulation::update_prescribed_motions(double t, double dt) {
  const auto& bcs = config_.boundary_conditions;
  // The conditions that hold their components over this step (birth <= t < death); where
  // that changes, the constrained components do.
  bool changed = bc_active_.size() != bcs.size();
  bc_active_.resize(bcs.size());
  for (std::size_t b = 0; b < bcs.size(); ++b) {
    const std::uint8_t on = bcs[b].active(t) ? 1 : 0;
    changed = changed || on != bc_active_[b];
    bc_active_[b] = on;
  }
  motion_factor_.resize(bcs.size());
  for (std::size_t b = 0; b < bcs.size(); ++b) {
    const auto& c = bcs[b].curve;
    if (!c)
      motion_factor_[b] = 1.0;
    else if (bcs[b].motion == BoundaryCondition::Motion::velocity)
      motion_factor_[b] = c->at(t + 0.5 * dt);
    else
      motion_factor_[b] = dt > 0 ? (c->at(t + dt) - c->at(t)) / dt : c->slope_after(t);
  }
  if (changed) {
    refresh_node_constraints();
    refresh_particle_constraints();
  }
  for (const auto& cc : curved_components_)
    v_bc_[cc.component][cc.node] = config_.boundary_conditions[cc.condition].value[cc.component] *
                                   motion_factor_[cc.condition];
}

// The constrained components of the nodes some condition holds, over the current step:
// each held by the last condition in the deck that holds it and is active (bc_active_), or
// free while none is (a driver that dies hands its nodes to a fix born then). Sets the
// components' source, prescribed value (times its condition's factor) and the list of
// those that follow a time history.
void Simulation::refresh_node_constraints() {
  const auto& bcs = config_.boundary_conditions;
  curved_components_.clear();
  for (std::size_t j = 0; j < constrained_nodes_.size(); ++j) {
    const int n = constrained_nodes_[j];
    std::uint8_t bits = 0;
    for (int i = 0; i < 3; ++i) {
      int b = -1;
      const std::size_t k = 3 * j + static_cast<std::size_t>(i);
      for (int h = holder_start_[k + 1]; h > holder_start_[k] && b < 0; --h)
        if (bc_active_[static_cast<std::size_t>(holders_[h - 1])]) b = holders_[h - 1];
      bc_source_[i][n] = b;
      if (b < 0) continue;
      bits |= static_cast<std::uint8_t>(1u << i);
      const auto& bc = bcs[static_cast<std::size_t>(b)];
      v_bc_[i][n] = bc.prescribed ? bc.value[i] * motion_factor_[static_cast<std::size_t>(b)] : 0.0;
      if (bc.prescribed && bc.curve) curved_components_.push_back({n, i, b});
    }
    constrained_[n] = bits;
  }
}

void Simulation::locate_probes(const Mesh& mesh) {
  (void)mesh;
  const std::size_t np = config_.probes.size();
  probe_node_.assign(np, -1);
  probe_particle_.assign(np, -1);
  if (np == 0) return;
  // Each rank's nearest owned node and nearest particle to every probe (grids of cells),
  // then two reductions for all the probes: the nearest distances, then the lowest id at
  // the nearest distance. The nearest particle competes with the nearest node (a node wins
  // a tie).
  std::vector<int> owned;
  for (std::size_t n = 0; n < fe_.node_gid.size(); ++n)
    if (fe_.node_owned[n]) owned.push_back(static_cast<int>(n));
  const NearestGrid nodes(nodes_.x[0].data(), nodes_.x[1].data(), nodes_.x[2].data(),
                          fe_.node_gid.data(), owned);
  std::vector<NearestGrid::Hit> node_hit(np), particle_hit(np);
  std::vector<double> r2(2 * np);
  {
    std::vector<int> all;
    const auto* pt = sph_ ? &sph_->particles() : nullptr;
    if (pt)
      for (std::size_t i = 0; i < pt->size(); ++i) all.push_back(static_cast<int>(i));
    const NearestGrid particles(pt ? pt->x[0].data() : nullptr, pt ? pt->x[1].data() : nullptr,
                                pt ? pt->x[2].data() : nullptr, pt ? pt->gid.data() : nullptr, all);
    for (std::size_t p = 0; p < np; ++p) {
      node_hit[p] = nodes.nearest(config_.probes[p].at);
      particle_hit[p] = particles.nearest(config_.probes[p].at);
      r2[p] = node_hit[p].r2;
      r2[np + p] = particle_hit[p].r2;
    }
  }
  comm_.min(std::span<double>(r2));
  constexpr std::int64_t none = std::numeric_limits<std::int64_t>::max();
  std::vector<std::int64_t> winner(np);
  for (std::size_t p = 0; p < np; ++p) {
    const bool particle = r2[np + p] < r2[p];
    const NearestGrid::Hit& h = particle ? particle_hit[p] : node_hit[p];
    winner[p] = h.index >= 0 && h.r2 == r2[particle ? np + p : p] ? h.id : none;
  }
  comm_.min(std::span<std::int64_t>(winner));
  for (std::size_t p = 0; p < np; ++p) {
    if (r2[np + p] < r2[p])
      probe_particle_[p] = winner[p];
    else if (node_hit[p].index >= 0 && node_hit[p].id == winner[p])
      probe_node_[p] = node_hit[p].index;
  }
}

// Each element probe's element: the one whose centroid (the mean of its corners at t = 0)
// is nearest the probe's point, the lowest global element id on a tie; found as the node
// probes are (each rank's nearest, then the nearest distance and the lowest id at it over
// all ranks). Collective.
void Simulation::locate_element_probes() {
  const std::size_t np = config_.element_probes.size();
  element_probe_.assign(np, {-1, -1});
  if (np == 0) return;
  std::int64_t local_elements = 0;
  for (const auto& b : blocks_) local_elements += b.size();
  if (comm_.sum(local_elements) == 0)
    throw InputError(config_.element_probes[0].where,
                     fmt::format("element probe {} needs elements, and the model has none",
                                 config_.element_probes[0].name));
  std::array<std::vector<double>, 3> c;
  std::vector<std::int64_t> gid;
  std::vector<std::array<int, 2>> at;
  for (std::size_t bi = 0; bi < blocks_.size(); ++bi) {
    const HexBlock& b = blocks_[bi];
    for (int e = 0; e < b.size(); ++e) {
      for (int i = 0; i < 3; ++i) {
        double sum = 0;
        for (int a = 0; a < 8; ++a) sum += nodes_.x[i][static_cast<std::size_t>(b.conn[a][e])];
        c[i].push_back(sum / 8);
      }
      gid.push_back(b.gid[static_cast<std::size_t>(e)]);
      at.push_back({static_cast<int>(bi), e});
    }
  }
  std::vector<int> all(gid.size());
  for (std::size_t k = 0; k < all.size(); ++k) all[k] = static_cast<int>(k);
  const NearestGrid grid(c[0].data(), c[1].data(), c[2].data(), gid.data(), all);
  std::vector<NearestGrid::Hit> hit(np);
  std::vector<double> r2(np);
  for (std::size_t p = 0; p < np; ++p) {
    const std::int64_t id = config_.element_probes[p].element_id;
    if (id < 0) {
      hit[p] = grid.nearest(config_.element_probes[p].at);
    } else {
      // The element with the file id (at "distance" 0; the lowest gid if ids repeat).
      hit[p] = {std::numeric_limits<double>::infinity(), 0, -1};
      for (std::size_t k = 0; k < at.size(); ++k)
        if (element_file_id_[static_cast<std::size_t>(at[k][0])]
                            [static_cast<std::size_t>(at[k][1])] == id &&
            (hit[p].index < 0 || gid[k] < hit[p].id))
          hit[p] = {0.0, gid[k], static_cast<int>(k)};
    }
    r2[p] = hit[p].r2;
  }
  comm_.min(std::span<double>(r2));
  constexpr std::int64_t none = std::numeric_limits<std::int64_t>::max();
  std::vector<std::int64_t> winner(np);
  for (std::size_t p = 0; p < np; ++p)
    winner[p] = hit[p].index >= 0 && hit[p].r2 == r2[p] ? hit[p].id : none;
  comm_.min(std::span<std::int64_t>(winner));
  for (std::size_t p = 0; p < np; ++p)
    if (hit[p].index >= 0 && hit[p].id == winner[p])
      element_probe_[p] = at[static_cast<std::size_t>(hit[p].index)];
}

// Every rank's eroded elements to the contact surfaces (collective; on the cycles where
// some element eroded, and after a restart: `exposing` false).
void Simulation::share_eroded(bool exposing) {
  if (!contact_) return;
  // The elements eroded here since the last call (each told once), from every rank.
  std::vector<std::int64_t>& mine = erosion_mine_;
  mine.clear();
  erosion_shared_.resize(blocks_.size());
  for (std::size_t b = 0; b < blocks_.size(); ++b) {
    const HexBlock& blk = blocks_[b];
    auto& told = erosion_shared_[b];
    told.resize(static_cast<std::size_t>(blk.size()), 0);
    for (std::size_t e = 0; e < told.size(); ++e)
      if (blk.alive[e] == 0.0 && told[e] == 0) {
        told[e] = 1;
        mine.push_back(blk.gid[e]);
      }
  }
  std::vector<std::int64_t>& fresh = erosion_fresh_;
  comm_.allgatherv(std::span<const std::int64_t>(mine), fresh, erosion_bytes_);
  std::sort(fresh.begin(), fresh.end());
  contact_->set_eroded(fresh, exposing);
}

std::string Simulation::describe_element(std::int64_t gid) const {
  for (std::size_t b = 0; b + 1 < block_offsets_.size(); ++b)
    if (gid >= block_offsets_[b] && gid < block_offsets_[b + 1])
      return fmt::format("element {} (part {}, element {} of the part)", gid + 1,
                         config_.parts[b].name, gid - block_offsets_[b] + 1);
  return fmt::format("element {}", gid + 1);
}

bool Simulation::finished() const {
  return clock_.cycle >= config_.end_cycles || clock_.time >= config_.end_time * (1 - 1e-12);
}

// ---------------------------------------------------------------------------------------
// The cycle.

void Simulation::step() {
  fe_forces();       // 1. FE internal forces (static decomposition)
  sph_forces();      // 2. SPH forces (SPH decomposition)
  predict();         // 3. v(n+1/2) = v(n-1/2) + dt a(n), x* = x(n) + dt v(n+1/2)
  detect_contacts(); // 4. contact search on the predicted motion (contact decomposition)
  correct();         // 5. penalty contact forces and rigid walls correct v(n+1/2)
  update();          // 6. x(n+1) = x(n) + dt v(n+1/2), t(n+1)
}

void Simulation::fe_forces() {
  HexResult r;
  {
    ScopedPhase t(timers_, Phase::fe);
    const NodalView view{{nodes_.x[0].data(), nodes_.x[1].data(), nodes_.x[2].data()},
                         {nodes_.v[0].data(), nodes_.v[1].data(), nodes_.v[2].data()}};
    const CornerView corners{
        {corner_force_[0].data(), corner_force_[1].data(), corner_force_[2].data()}};
    // The kernel sums the corner forces of every node in ascending global element id (the
    // blocks in order); the corner slots it stores are those of the exchanged nodes.
    workspace_.begin_nodal_forces(static_cast<int>(fe_.node_gid.size()));
    for (auto& b : blocks_)
      if (b.size() > 0 && !b.rigid) hex_forces(b, view, clock_.dt_prev, corners, workspace_, r);
    double* const f[3] = {nodes_.f[0].data(), nodes_.f[1].data(), nodes_.f[2].data()};
    workspace_.end_nodal_forces(f);
    eroded_ += r.eroded;
    press_faces(); // the pressure loads' corner forces, exchanged with the elements'
  }
  {
    // The reductions are timed with the exchange, not with the element work: a rank that
    // waits here for a slower one would otherwise hide the imbalance of `fe`.
    ScopedPhase t(timers_, Phase::halo);
    // The corner forces travel while the reduction runs (the exchange is completed before
    // anything below can stop the run, so no message is left outstanding).
    const std::initializer_list<double*> corners = {
        corner_force_[0].data(), corner_force_[1].data(), corner_force_[2].data()};
    const std::initializer_list<double*> with_loads = {
        corner_force_[0].data(), corner_force_[1].data(), corner_force_[2].data(),
        load_corner_[0].data(),  load_corner_[1].data(),  load_corner_[2].data()};
    const bool pressures = !load_corner_[0].empty();
    corner_exchange_->start(pressures ? with_loads : corners);
    // One reduction per cycle carries the stable step and the failure and erosion flags.
    const double none = std::numeric_limits<double>::infinity();
    double red[5] = {r.dt_stable, r.inverted_gid >= 0 ? static_cast<double>(r.inverted_gid) : none,
                     r.nonfinite_gid >= 0 ? static_cast<double>(r.nonfinite_gid) : none,
                     stop_local_ ? 0.0 : 1.0, r.eroded > 0 ? 0.0 : 1.0};
    comm_.min(std::span<double>(red, 5));
    corner_exchange_->finish(pressures ? with_loads : corners);
    stop_ = red[3] == 0.0;             // a stop asked on any rank stops every rank after this cycle
    if (red[4] == 0.0) share_eroded(); // some element eroded somewhere
    if (red[1] != none)
      throw PhysicsError(describe_element(static_cast<std::int64_t>(red[1])), clock_.time,
                         "inverted element (non-positive volume or centre Jacobian)");
    if (red[2] != none || !std::isfinite(red[0]))
      throw PhysicsError(red[2] != none ? describe_element(static_cast<std::int64_t>(red[2]))
                                        : "the model",
                         clock_.time, "non-finite stress or force");
    dt_stable_local_ = r.dt_stable;
    stable_gid_local_ = r.stable_gid;
    dt_stable_ = red[0];
  }
  {
    ScopedPhase t(timers_, Phase::fe);
    // The nodes shared with other ranks: the whole sum again, remote corners included.
    gather_corners(fe_, {corner_force_[0].data(), corner_force_[1].data(), corner_force_[2].data()},
                   {nodes_.f[0].data(), nodes_.f[1].data(), nodes_.f[2].data()},
                   fe_.exchanged_nodes);
    add_loads(); // the external loads of t(n)
  }
}

namespace {

// Central difference for the velocity of one node, or of a vector of nodes: v(n+1/2) from
// old = v(n-1/2), the force f and the body acceleration g, or the prescribed velocity bc
// in the directions where `fixed` holds; returns 1/2 m |v(n)|^2 with v(n) the mean of the
// two half-step velocities. One template for the vector body and the scalar rest: the
// same operations.
template <class V, class Mask>
V advance_velocity(const V (&old)[3], const V (&f)[3], const V (&bc)[3], const Mask (&fixed)[3],
                   const V& m, double dt_avg, const double (&g)[3], V (&nv)[3]) {
  const V inv_m = 1.0 / m;
  V avg2 = 0.0;
  for (int i = 0; i < 3; ++i) {
    // (dt f / m first, as without g: with g = 0 the same bits as before it existed.)
    nv[i] = simd::select(fixed[i], bc[i], old[i] + (dt_avg * f[i] * inv_m + dt_avg * g[i]));
    const V a = 0.5 * (old[i] + nv[i]);
    avg2 += a * a;
  }
  return 0.5 * m * avg2;
}

} // namespace

void Simulation::predict() {
  ScopedPhase t(timers_, Phase::predict);
  double dt = config_.time_step_scale * dt_stable_;
  const bool below =
      clock_.cycle > 0 && dt < config_.time_step_minimum_fraction * clock_.dt_initial;
  // Steps that no longer advance the time (0, not a number, or below the time's last
  // digit) would repeat for ever, whatever minimum_fraction says (QA round 23c: particles
  // under a gravity of 1e308 looped at a step of 0 s). Many are let pass: an element
  // crushed flat controls such steps, shrinking, until erosion takes it (3,010 of them in
  // Cli.ErosionAndTimeStepCollapse).
  stalled_steps_ = clock_.time + dt > clock_.time ? 0 : stalled_steps_ + 1;
  const bool stalled = stalled_steps_ > 10000;
  if (below || stalled) {
    // Every rank takes this branch (dt is global). The controlling element: the smallest
    // gid among the ranks that hold the global minimum (an element's step, unless a
    // particle's was smaller).
    const double none = std::numeric_limits<double>::infinity();
    const bool mine = clock_.dt_particle < 0 && dt_stable_local_ == dt_stable_;
    const double gid = comm_.min(mine ? static_cast<double>(stable_gid_local_) : none);
    const std::int64_t element = gid == none ? -1 : static_cast<std::int64_t>(gid);
    throw PhysicsError(
        clock_.dt_particle >= 0 ? fmt::format("particle {}", clock_.dt_particle + 1)
                                : describe_element(element),
        clock_.time,
        stalled ? fmt::format("the time step collapsed to {:.3e} s, too small to advance the "
                              "time for 10,000 steps (it controls the step)",
                              dt)
                : fmt::format("the time step collapsed to {:.3e} s, below {} of the initial "
                              "{:.3e} s (it controls the step)",
                              dt, config_.time_step_minimum_fraction, clock_.dt_initial));
  }
  dt_full_ = dt;
  if (std::isfinite(config_.end_time) && clock_.time + dt > config_.end_time)
    dt = std::max(config_.end_time - clock_.time, 0.0);
  clock_.dt = dt;
  if (clock_.cycle == 0) clock_.dt_initial = dt;
  // Central difference with a varying step: the velocity advances over the average of
  // the intervals on either side of t(n).
  const double dt_avg = 0.5 * (clock_.dt_prev + dt);
  dt_avg_ = dt_avg;
  const std::size_t nn = nodes_.size();

  // Work of the constraint reactions over this step (before the velocities change),
  // summed in a local whose address is not taken (`impulses`' is, below: the sum went
  // through memory at every term, a quarter of this function's time on the can crush).
  ImpulseWork constraint_work;
  update_prescribed_motions(clock_.time, dt);
  // The body acceleration of this step, at t(n) where its forces are.
  const auto g_now = body_acceleration(clock_.time);
  const double g[3] = {g_now[0], g_now[1], g_now[2]};
  for (int i = 0; i < 3; ++i) gravity_[i] = g[i];
  // The rigid bodies' nodes: prescribed by their bodies' motion (constrained in every
  // component); the reactions' impulses, the rigid bodies' internal forces, sum to zero.
  if (!rigid_gids_.empty()) {
    move_rigid_bodies(false);
    for (const auto& rn : rigid_nodes_) {
      const auto n = static_cast<std::size_t>(rn.local);
      const Vec3 x{nodes_.x[0][n], nodes_.x[1][n], nodes_.x[2][n]};
      const Vec3 v = rigid_motion_[static_cast<std::size_t>(rn.body)].point_velocity(x);
      for (int i = 0; i < 3; ++i) {
        v_bc_[i][n] = v[i];
        if (!rn.owned) continue;
        const double v_old = nodes_.v[i][n];
        const double v_forces = v_old + dt_avg * nodes_.f[i][n] / nodes_.mass[n];
        constraint_work.add(nodes_.mass[n] * (v[i] - v_forces), v_old, v[i]);
      }
    }
  }
  for (int n : constrained_nodes_) {
    for (int i = 0; i < 3; ++i) {
      if (!(constrained_[n] & (1u << i))) continue;
      const double v_old = nodes_.v[i][n];
      // The reaction holds the body force too; its work is the constrained component's
      // whole change of kinetic energy but the forces' (the body force works on free
      // components only, below).
      const double v_forces = v_old + dt_avg * nodes_.f[i][n] / nodes_.mass[n];
      const double v_free = v_old + (dt_avg * nodes_.f[i][n] / nodes_.mass[n] + dt_avg * g[i]);
      const double v_new = v_bc_[i][n];
      bc_reaction_[i][n] = nodes_.mass[n] * (v_new - v_free) / dt_avg;
      if (fe_.node_owned[n]) constraint_work.add(nodes_.mass[n] * (v_new - v_forces), v_old, v_new);
    }
  }
  double ke = 0;
  // Probe displacements at t(n); their velocities once correct() has set v(n+1/2).
  for (std::size_t p = 0; p < probe_node_.size(); ++p)
    if (probe_node_[p] >= 0) {
      const int n = probe_node_[p];
      for (int i = 0; i < 3; ++i) probe_local_[6 * p + i] = nodes_.x[i][n] - nodes_.x0[i][n];
    }
  double* v[3] = {nodes_.v[0].data(), nodes_.v[1].data(), nodes_.v[2].data()};
  double* v_prev[3] = {v_prev_[0].data(), v_prev_[1].data(), v_prev_[2].data()};
  const double* f[3] = {nodes_.f[0].data(), nodes_.f[1].data(), nodes_.f[2].data()};
  const double* m = nodes_.mass.data();
  const std::uint8_t* owned = fe_.node_owned.data();
  const std::uint8_t* fixed = constrained_.data();
  // simd::width nodes at a time (the vector body), then one at a time (the rest): the
  // same operations, so the same bits. The kinetic energy is summed node after node, in a
  // local whose address is not taken (ke's is: a store to v could alias it, and the sum
  // went through memory at every node).
  double ke_nodes = 0;
  constexpr auto W = static_cast<std::size_t>(simd::width);
  std::size_t n = 0;
  for (; n + W <= nn; n += W) {
    simd::vdouble old[3], force[3], bc[3], nv[3];
    simd::vmask fx[3] = {simd::vmask(false), simd::vmask(false), simd::vmask(false)};
    unsigned any = 0;
    for (std::size_t l = 0; l < W; ++l) any |= fixed[n + l];
    for (int i = 0; i < 3; ++i) {
      old[i] = simd::load(v[i] + n);
      force[i] = simd::load(f[i] + n);
      bc[i] = simd::load(v_bc_[i].data() + n);
      if (any != 0)
        fx[i] = simd::vdouble([&](auto l) { return double((fixed[n + l] >> i) & 1u); }) != 0.0;
    }
    const simd::vdouble e = advance_velocity(old, force, bc, fx, simd::load(m + n), dt_avg, g, nv);
    for (int i = 0; i < 3; ++i) {
      simd::store(old[i], v_prev[i] + n);
      simd::store(nv[i], v[i] + n);
    }
    for (std::size_t l = 0; l < W; ++l)
      if (owned[n + l]) ke_nodes += e[static_cast<int>(l)];
  }
  for (; n < nn; ++n) {
    double old[3], force[3], bc[3], nv[3];
    bool fx[3];
    for (int i = 0; i < 3; ++i) {
      old[i] = v[i][n];
      force[i] = f[i][n];
      bc[i] = v_bc_[i][n];
      fx[i] = ((fixed[n] >> i) & 1u) != 0;
    }
    const double e = advance_velocity(old, force, bc, fx, m[n], dt_avg, g, nv);
    for (int i = 0; i < 3; ++i) {
      v_prev[i][n] = old[i];
      v[i][n] = nv[i];
    }
    if (owned[n]) ke_nodes += e;
  }
  ke = ke_nodes; // (ke is 0 before the nodes: the same sum)
  // The work of the step's external impulses: the constraints', the body force's on the
  // free components (its work to t(n) then equals a free fall's kinetic energy at t(n) to
  // round-off, whatever g does; on constrained components the reactions hold it), the
  // loads' and the particles'. (Gravity's in a local whose address is not taken too.)
  ImpulseWork impulses = constraint_work;
  if (g[0] != 0.0 || g[1] != 0.0 || g[2] != 0.0) {
    ImpulseWork gravity_work;
    for (std::size_t k = 0; k < nn; ++k)
      if (owned[k])
        for (int i = 0; i < 3; ++i)
          if (!((fixed[k] >> i) & 1u))
            gravity_work.add(m[k] * g[i] * dt_avg, v_prev[i][k], v[i][k]);
    impulses += gravity_work;
  }
  add_load_work(dt_avg, impulses);
  if (sph_) predict_particles(dt_avg, ke, impulses);
  work_later_ = impulses.later;
  external_work_ += impulses.whole;
  kinetic_local_ = ke; // correct() adds what contact and walls change
  sample_time_ = clock_.time;
  sample_cycle_ = clock_.cycle;
  sample_dt_ = dt;
}

void Simulation::sph_forces() {
  clock_.dt_particle = -1;
  if (!sph_) return;
  sph_->forces(clock_.dt_prev, timers_);
  ScopedPhase t(timers_, Phase::sph);
  // One reduction: the particles' stable step and the smallest failing particle.
  const sph::SphResult& r = sph_->result();
  const double none = std::numeric_limits<double>::infinity();
  double red[2] = {r.dt_stable, r.nonfinite_gid >= 0 ? static_cast<double>(r.nonfinite_gid) : none};
  comm_.min(std::span<double>(red, 2));
  // An infinite step is no failure (particles of a gas expanded to zero pressure, at
  // rest relative to their neighbours, constrain nothing); a NaN is.
  if (red[1] != none || std::isnan(red[0]))
    throw PhysicsError(red[1] != none
                           ? fmt::format("particle {}", static_cast<std::int64_t>(red[1]) + 1)
                           : "the particles",
                       clock_.time, "non-finite stress or force");
  if (red[0] < dt_stable_) {
    dt_stable_ = red[0];
    clock_.dt_particle = static_cast<std::int64_t>(
        comm_.min(r.dt_stable == red[0] ? static_cast<double>(r.stable_gid) : none));
  }
}

ContactNodes Simulation::contact_view() {
  return {{nodes_.x[0].data(), nodes_.x[1].data(), nodes_.x[2].data()},
          {nodes_.v[0].data(), nodes_.v[1].data(), nodes_.v[2].data()},
          nodes_.mass.data(),
          {contact_force_[0].data(), contact_force_[1].data(), contact_force_[2].data()}};
}

void Simulation::detect_contacts() {
  if (!contact_) return;
  if (sph_) contact_->set_extra_nodes(particle_contact_items(clock_.dt));
  contact_->detect(contact_view(), clock_.dt, timers_);
}

void Simulation::correct() {
  if (contact_) {
    // The penalty's stiffness cap and friction's sticking limit take the full step: the
    // last step, shortened to land on the end time, acts on the velocity over dt_avg, so
    // with its own tiny dt it would let a stiff penalty kick the penetrated nodes out
    // (QA round 6: kinetic energy 19.5 -> 31.2 J in the last step, balance error 0.65).
    contact_->forces(contact_view(), dt_full_, timers_);
    ScopedPhase t(timers_, Phase::contact_force);
    // The penalty impulse acts over the velocity step: dv = dt_avg f / m. Its work is the
    // impulse times the mean of the step's start and end velocities (attributing the
    // kinetic energy change of the step exactly among the impulses that make it).
    // Only the contact nodes can carry a force (ascending: the sums' order is that of a
    // pass over every node). The sums are locals whose address is not taken (work's is,
    // below). Where every node is a contact node (a thin wall), a vector of nodes without
    // force is skipped at once.
    double work_c = 0, reaction = 0;
    const double* cf[3] = {contact_force_[0].data(), contact_force_[1].data(),
                           contact_force_[2].data()};
    double ke_change = 0; // of 1/2 m |v(n)|^2, v(n) = (v(n-1/2) + v(n+1/2)) / 2
    auto impulse = [&](std::size_t n) {
      if (cf[0][n] == 0.0 && cf[1][n] == 0.0 && cf[2][n] == 0.0)
        return;                                           // most nodes: no pair acts on them
      if (!rigid_node_.empty() && rigid_node_[n]) return; // their bodies take it, below
      const double inv_m = dt_avg_ / nodes_.mass[n];
      for (int i = 0; i < 3; ++i) {
        const double f = cf[i][n];
        if (f == 0.0) continue;
        if (constrained_[n] & (1u << i)) {
          // The constraint cancels the impulse: the contact force still works on the node
          // (part of the pair's energy) and the constraint's reaction is external work.
          if (fe_.node_owned[n]) {
            work_c += f * dt_avg_ * nodes_.v[i][n];
            reaction -= f * dt_avg_ * nodes_.v[i][n];
          }
          bc_reaction_[i][n] -= f;
          continue;
        }
        const double before = 0.5 * (v_prev_[i][n] + nodes_.v[i][n]);
        nodes_.v[i][n] += inv_m * f;
        const double after = 0.5 * (v_prev_[i][n] + nodes_.v[i][n]);
        if (fe_.node_owned[n]) {
          work_c += f * dt_avg_ * after;
          ke_change += 0.5 * nodes_.mass[n] * (after * after - before * before);
        }
      }
    };
    const std::span<const int> fn = contact_->force_nodes();
    const std::size_t nn = nodes_.size();
    if (fn.size() == nn) {
      constexpr auto W = static_cast<std::size_t>(simd::width);
      std::size_t n = 0;
      for (; n + W <= nn; n += W) {
        if (all_of((simd::load(cf[0] + n) == 0.0) & (simd::load(cf[1] + n) == 0.0) &
                   (simd::load(cf[2] + n) == 0.0)))
          continue;
        for (std::size_t k = n; k < n + W; ++k) impulse(k);
      }
      for (; n < nn; ++n) impulse(n);
    } else {
      for (const int l : fn) impulse(static_cast<std::size_t>(l));
    }
    if (!rigid_gids_.empty()) {
      // The rigid bodies move again with the contact forces on their nodes: each node's
      // change of velocity is its contact impulse plus the body's internal one (external
      // work, as the constraints' are; it sums to zero over a body).
      move_rigid_bodies(true);
      for (const auto& rn : rigid_nodes_) {
        const auto n = static_cast<std::size_t>(rn.local);
        const Vec3 x{nodes_.x[0][n], nodes_.x[1][n], nodes_.x[2][n]};
        const Vec3 v = rigid_motion_[static_cast<std::size_t>(rn.body)].point_velocity(x);
        for (int i = 0; i < 3; ++i) {
          const double before = 0.5 * (v_prev_[i][n] + nodes_.v[i][n]);
          const double after = 0.5 * (v_prev_[i][n] + v[i]);
          if (rn.owned) {
            const double f = cf[i][n];
            work_c += f * dt_avg_ * after;
            ke_change += 0.5 * nodes_.mass[n] * (after * after - before * before);
            reaction += (nodes_.mass[n] * (v[i] - nodes_.v[i][n]) - f * dt_avg_) * after;
          }
          nodes_.v[i][n] = v[i];
        }
      }
    }
    double work = work_c; // (the same sum)
    if (sph_) correct_particles(work, ke_change, reaction);
    external_work_ += reaction;
    contact_energy_ -= work;
    kinetic_local_ += ke_change;
  }
  if (!config_.rigid_walls.empty()) {
    ScopedPhase t(timers_, Phase::contact_force);
    apply_walls();
  }
  sample_probe_velocities(); // (a few values: timed with the cycle's own work, untimed)
}

void Simulation::apply_walls() {
  // The rigid bodies met the walls in their motion (move_rigid_bodies); their hits first.
  wall_hits_.assign(rigid_wall_hits_.begin(), rigid_wall_hits_.end());
  const WallNodes wn{{nodes_.x[0].data(), nodes_.x[1].data(), nodes_.x[2].data()},
                     {nodes_.v[0].data(), nodes_.v[1].data(), nodes_.v[2].data()},
                     {v_prev_[0].data(), v_prev_[1].data(), v_prev_[2].data()},
                     nodes_.mass.data(),
                     constrained_.data(),
                     fe_.node_owned.data(),
                     fe_.node_gid.data(),
                     0,
                     nodes_.size()};
  auto add = [&](const WallResult& r) {
    external_work_ += r.work;
    kinetic_local_ += r.kinetic;
  };
  add(apply_rigid_walls(config_.rigid_walls, clock_.dt, wn, wall_hits_));
  if (sph_) {
    // Particles meet the walls as nodes do (every own particle is "owned").
    auto& pt = sph_->particles();
    particle_owned_.assign(pt.size(), 1);
    const WallNodes wp{{pt.x[0].data(), pt.x[1].data(), pt.x[2].data()},
                       {pt.v[0].data(), pt.v[1].data(), pt.v[2].data()},
                       {pv_prev_[0].data(), pv_prev_[1].data(), pv_prev_[2].data()},
                       pt.mass.data(),
                       pt.constrained.data(),
                       particle_owned_.data(),
                       pt.gid.data(),
                       global_nodes_,
                       pt.size()};
    add(apply_rigid_walls(config_.rigid_walls, clock_.dt, wp, wall_hits_));
  }
}

// The probes' velocity at t(n): the mean of v(n-1/2) and the corrected v(n+1/2).
void Simulation::sample_probe_velocities() {
  for (std::size_t p = 0; p < probe_node_.size(); ++p)
    if (probe_node_[p] >= 0) {
      const auto n = static_cast<std::size_t>(probe_node_[p]);
      for (int i = 0; i < 3; ++i)
        probe_local_[6 * p + 3 + i] = 0.5 * (v_prev_[i][n] + nodes_.v[i][n]);
    }
  if (sph_) sample_particle_probe_velocities();
}

void Simulation::update() {
  ScopedPhase t(timers_, Phase::update);
  const double dt = clock_.dt;
  const std::size_t nn = nodes_.size();
  for (int i = 0; i < 3; ++i) {
    double* x = nodes_.x[i].data();
    const double* v = nodes_.v[i].data();
#pragma omp simd
    for (std::size_t n = 0; n < nn; ++n) x[n] += dt * v[n];
  }
  if (sph_) update_particles(dt);
  // A step shortened to land on the end time lands on it exactly (the sum could miss it by
  // an ulp: the last fields' time read 2.0000000000000002e-05 for an end of 2e-05).
  clock_.time = dt < dt_full_ ? config_.end_time : clock_.time + dt;
  clock_.cycle += 1;
  clock_.dt_prev = dt;
}

// ---------------------------------------------------------------------------------------
// Diagnostics.

Sample Simulation::sample() const {
  Sample s;
  s.time = clock_.cycle == 0 ? 0.0 : sample_time_;
  s.cycle = clock_.cycle == 0 ? 0 : sample_cycle_;
  s.dt = sample_dt_;
  // The constraints' and the loads' work of step n, booked whole in its predict(), is not
  // all done at t(n) (work_later_). (Booked whole, a body driven at a constant acceleration showed
  // work ahead of its kinetic energy by F v dt / 2 at every row, QA round 24; now the two agree to
  // round-off, as a free fall's do.)
  double local[5] = {kinetic_local_, 0, 0, external_work_ - work_later_, contact_energy_};
  for (const auto& b : blocks_)
    for (int e = 0; e < b.size(); ++e) {
      local[1] += b.internal_energy[e];
      local[2] += b.hourglass_energy[e];
    }
  local[1] += particle_internal_energy();
  comm_.sum(std::span<double>(local, 5));
  s.contact = local[4];
  s.kinetic = local[0];
  s.internal = local[1];
  s.hourglass = local[2];
  s.external_work = local[3];
  // The probes and the element probes in one sum: each value is its rank's, the other
  // ranks add +0. (On one rank a -0, from a curve that scaled a negative value to 0,
  // stayed -0, on several it became +0, QA round 23: the same value, other bits. Adding +0
  // makes every zero +0.) An element probe reads its element's state at t(n), which the
  // last fe_forces() computed.
  std::vector<double> values = probe_local_;
  const std::size_t node_values = values.size();
  values.resize(node_values + 7 * element_probe_.size(), 0.0);
  for (std::size_t p = 0; p < element_probe_.size(); ++p) {
    const auto [bi, e] = element_probe_[p];
    if (bi < 0) continue;
    const HexBlock& b = blocks_[static_cast<std::size_t>(bi)];
    double* out = values.data() + node_values + 7 * p;
    for (int k = 0; k < 6; ++k) out[k] = b.stress[k][static_cast<std::size_t>(e)];
    out[6] = b.plastic_strain.empty() ? 0.0 : b.plastic_strain[static_cast<std::size_t>(e)];
  }
  comm_.sum(std::span<double>(values));
  for (double& v : values) v += 0.0;
  s.probes.assign(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(node_values));
  s.element_probes.assign(values.begin() + static_cast<std::ptrdiff_t>(node_values), values.end());
  // The walls' forces: every rank's hits, summed in ascending key (DESIGN.md section 3).
  s.wall_force.assign(config_.rigid_walls.size(), 0.0);
  if (!s.wall_force.empty()) {
    std::vector<WallHit> all = comm_.allgatherv(std::span<const WallHit>(wall_hits_));
    wall_forces(all, dt_avg_, s.wall_force);
  }
  s.reaction = reactions();
  // The moments of the conditions that hold rotations: the torque each held rotation
  // takes (the same on every rank: every rank computed the motion).
  for (std::size_t b = 0; b < config_.boundary_conditions.size(); ++b) {
    if (!config_.boundary_conditions[b].holds_spin()) continue;
    Vec3 moment{0, 0, 0};
    for (std::size_t o = 0; o < rigid_holder_.size(); ++o)
      for (int i = 0; i < 3; ++i)
        if (rigid_holder_[o][static_cast<std::size_t>(3 + i)] == static_cast<int>(b))
          moment[i] += rigid_motion_[o].held_torque[i];
    for (int i = 0; i < 3; ++i) s.reaction_moment.push_back(moment[i]);
  }
  // The rigid bodies' motion over the last step (the same on every rank); before the first
  // step, at rest where they stand.
  for (std::size_t o = 0; o < rigid_motion_.size(); ++o) {
    const RigidMotion& m = rigid_motion_[o];
    const bool moved = m.mass > 0;
    const Vec3 u = moved ? m.centre - rigid_centre0_[o] : Vec3{0, 0, 0};
    for (const Vec3& q : {u, moved ? m.velocity : Vec3{0, 0, 0}, moved ? m.omega : Vec3{0, 0, 0}})
      for (int i = 0; i < 3; ++i) s.rigid_bodies.push_back(q[i]);
  }
  if (config_.part_energies) {
    s.part_energies = part_energies();
    comm_.sum(std::span<double>(s.part_energies));
  }
  return s;
}

// Each part's and particle set's share of the kinetic, internal and hourglass energies of
// this rank. A node's kinetic energy is split among its elements by the mass each gave it
// (the element's corner shares: the lumped mass), so the parts' kinetic energies add up to
// the nodes'; the velocity is the one the total uses (the deck's at t = 0, then the mean
// of the half-step velocities around t(n)).
std::vector<double> Simulation::part_energies() const {
  const std::size_t parts = config_.parts.size();
  std::vector<double> e(3 * (parts + config_.particles.size()), 0.0);
  const bool initial = clock_.cycle == 0;
  auto speed2 = [&](const std::array<std::vector<double>, 3>& v,
                    const std::array<std::vector<double>, 3>& v_prev, std::size_t n) {
    double s = 0;
    for (int i = 0; i < 3; ++i) {
      const double a = initial ? v[i][n] : 0.5 * (v_prev[i][n] + v[i][n]);
      s += a * a;
    }
    return s;
  };
  for (const auto& b : blocks_) {
    double* out = e.data() + 3 * static_cast<std::size_t>(b.part);
    for (int el = 0; el < b.size(); ++el) {
      const auto k = static_cast<std::size_t>(el);
      double v2 = 0; // (mass-weighted: corner_share is 1/8 on a hexahedron)
      for (int a = 0; a < 8; ++a)
        v2 += 8 * b.corner_share(k, a) *
              speed2(nodes_.v, v_prev_, static_cast<std::size_t>(b.conn[a][k]));
      out[0] += 0.5 * (b.scaled_mass(k) / 8) * v2;
      out[1] += b.internal_energy[k];
      out[2] += b.hourglass_energy[k];
    }
  }
  if (sph_) {
    const auto& pt = sph_->particles();
    for (std::size_t i = 0; i < pt.size(); ++i) {
      double* out = e.data() + 3 * (parts + static_cast<std::size_t>(pt.set[i]));
      out[0] += 0.5 * pt.mass[i] * speed2(pt.v, pv_prev_, i);
      out[1] += pt.mass[i] * pt.energy[i];
    }
  }
  return e;
}

// Per boundary condition, the force it applies to its nodes and particles over the current
// step (fx, fy, fz): every rank's constrained components gathered and summed in ascending
// node id, then particle id (DESIGN.md section 3: the same bits on any number of ranks).
// Collective.
std::vector<double> Simulation::reactions() const {
  const auto& bcs = config_.boundary_conditions;
  std::vector<double> out(3 * bcs.size(), 0.0);
  if (bcs.empty()) return out;
  std::vector<ReactionTerm> mine;
  for (const int n : constrained_nodes_) {
    if (!fe_.node_owned[static_cast<std::size_t>(n)]) continue;
    for (int i = 0; i < 3; ++i)
      if (const int b = bc_source_[i][n]; b >= 0 && (constrained_[n] & (1u << i)))
        mine.push_back({fe_.node_gid[n], b, i, 1, bc_reaction_[i][n]});
  }
  if (sph_) {
    const auto& pt = sph_->particles();
    for (std::size_t k = 0; k < std::min(pt.size(), p_reaction_[0].size()); ++k)
      for (int i = 0; i < 3; ++i)
        if (const int b = pt.bc_source[i][k]; b >= 0 && (pt.constrained[k] & (1u << i)))
          mine.push_back({global_nodes_ + pt.gid[k], b, i, 1, p_reaction_[i][k]});
  }
  // The rigid bodies' held components: the force on the body (every rank computed the
  // same motion; rank 0 gives it once).
  if (comm_.rank() == 0)
    for (std::size_t o = 0; o < rigid_holder_.size(); ++o)
      for (int i = 0; i < 3; ++i)
        if (const int b = rigid_holder_[o][static_cast<std::size_t>(i)]; b >= 0)
          mine.push_back(
              {-1 - static_cast<std::int64_t>(o), b, i, 1, rigid_motion_[o].held_force[i]});
  // The first step's row (t = 0) holds the impulses that set the constrained components at
  // t = 0 (apply_boundary_conditions), spread over its velocity interval as the walls'.
  if (sample_cycle_ == 0 && clock_.cycle > 0)
    for (ReactionTerm r : initial_impulses_) {
      r.force /= dt_avg_;
      mine.push_back(r);
    }
  std::vector<ReactionTerm> all = comm_.allgatherv(std::span<const ReactionTerm>(mine));
  std::sort(all.begin(), all.end(), [](const ReactionTerm& a, const ReactionTerm& b) {
    return std::tie(a.condition, a.key, a.component, a.part) <
           std::tie(b.condition, b.key, b.component, b.part);
  });
  for (const auto& r : all) out[3 * static_cast<std::size_t>(r.condition) + r.component] += r.force;
  return out;
}

double Simulation::balance_error(const Sample& s, double scale) const {
  const double e = s.total();
  scale =
      std::max({std::abs(e), std::abs(s.external_work), std::abs(initial_energy_), scale, 1e-300});
  return std::abs(e - initial_energy_ - s.external_work) / scale;
}

void Simulation::restore(const Checkpoint& c) {
  const std::string from = c.file.empty() ? "the checkpoint of '" + c.deck + "'"
                                          : "checkpoint '" + c.file + "' (of '" + c.deck + "')";
  const std::int64_t particles = sph_ ? sph_->global_count() : 0;
  if (c.model_nodes != global_nodes_ || c.model_elements != global_elements_)
    throw InputError(fmt::format("{} ({} nodes, {} elements) does not match this model "
                                 "({} nodes, {} elements)",
                                 from, c.model_nodes, c.model_elements, global_nodes_,
                                 global_elements_));
  if (c.model_particles != particles)
    throw InputError(fmt::format("{} holds {} particles, this model has {}", from,
                                 c.model_particles, particles));
  if (c.particle_fingerprint != particle_fingerprint_)
    throw InputError(fmt::format("{} was written for other particles: the deck's particle sets "
                                 "(their order, lattices, spacing or density) differ from those "
                                 "of the run that wrote it (restart with the deck it came from)",
                                 from));
  // The masses: mass scaling's (QA round 30: a restart without it, or with another step,
  // ran on with other masses and the velocities of the old ones, the balance off by 16%).
  if (c.mass_scaling_target != mass_scaling_target()) {
    auto said = [](double target) {
      return target > 0 ? fmt::format("scales masses to an element step of {:.9g} s", target)
                        : std::string("scales no masses");
    };
    throw InputError(fmt::format("{} {}, this deck {} (time_step.mass_scaling step / scale): "
                                 "the masses would change under the run; restart with the "
                                 "mass scaling of the run that wrote it",
                                 from, said(c.mass_scaling_target), said(mass_scaling_target())));
  }
  if (c.time > config_.end_time * (1 + 1e-12) || c.cycle > config_.end_cycles)
    throw InputError(fmt::format(
        "{}: {} is at t = {:.9g} s (cycle {}), past the deck's termination ({}): nothing is "
        "left to run; extend the termination to continue",
        config_.deck_file, from, c.time, c.cycle,
        config_.end_time < std::numeric_limits<double>::infinity()
            ? fmt::format("time {:.9g} s", config_.end_time)
            : fmt::format("{} cycles", config_.end_cycles)));
  auto find = [](const std::vector<std::int64_t>& ids, std::int64_t id) -> std::int64_t {
    const auto it = std::lower_bound(ids.begin(), ids.end(), id);
    return it != ids.end() && *it == id ? it - ids.begin() : -1;
  };
  // The parts' thick_shell as the checkpoint's run had it, before the mesh (a thick shell
  // turns its elements, so the connectivity differs too): the smallest element whose
  // points through the thickness differ, on every rank.
  const std::int64_t none = std::numeric_limits<std::int64_t>::max();
  {
    std::int64_t first = none;
    for (const auto& b : blocks_)
      for (int e = 0; e < b.size(); ++e) {
        const std::int64_t kp = find(c.point_gid, b.gid[e]);
        const int had = kp < 0 ? 0 : c.point_count[static_cast<std::size_t>(kp)];
        if (had != (b.thick_shell.enabled() ? b.thick_shell.points : 0))
          first = std::min(first, b.gid[e]);
      }
    first = comm_.min(first);
    if (first != none) {
      std::int64_t points[2] = {-1, -1}; // the checkpoint's, the deck's
      for (const auto& b : blocks_)
        for (int e = 0; e < b.size(); ++e)
          if (b.gid[e] == first) {
            const std::int64_t kp = find(c.point_gid, first);
            points[0] = kp < 0 ? 0 : c.point_count[static_cast<std::size_t>(kp)];
            points[1] = b.thick_shell.enabled() ? b.thick_shell.points : 0;
          }
      comm_.max(std::span<std::int64_t>(points, 2));
      auto section = [](std::int64_t n) {
        return n == 0 ? std::string("no thick_shell")
                      : fmt::format("thick_shell {{points: {}}}", n);
      };
      throw InputError(fmt::format(
          "{} was written with {} for {}, the deck gives {}: a part's thick_shell cannot change "
          "on restart (its state lives at the points through the thickness)",
          from, section(points[0]), describe_element(first), section(points[1])));
    }
  }
  if (c.mesh_fingerprint != mesh_fingerprint_)
    throw InputError(fmt::format("{} was written for another mesh: the deck's node coordinates "
                                 "or element connectivity differ from those of the run that "
                                 "wrote it (restart with the deck it came from)",
                                 from));
  // What the checkpoint lacks is found on the ranks holding it; every rank must throw
  // (the smallest such id over all ranks), not only those.
  std::int64_t missing[2] = {none, none}; // node, element
  for (std::size_t n = 0; n < nodes_.size(); ++n)
    if (find(c.node_gid, fe_.node_gid[n]) < 0) missing[0] = std::min(missing[0], fe_.node_gid[n]);
  for (const auto& b : blocks_)
    for (int e = 0; e < b.size(); ++e)
      if (find(c.element_gid, b.gid[e]) < 0) missing[1] = std::min(missing[1], b.gid[e]);
  comm_.min(std::span<std::int64_t>(missing, 2));
  if (missing[0] != none) throw InputError(from + " lacks node " + std::to_string(missing[0] + 1));
  if (missing[1] != none)
    throw InputError(from + " lacks element " + std::to_string(missing[1] + 1));
  clock_.time = c.time;
  clock_.cycle = c.cycle;
  initial_impulses_.clear(); // (the t = 0 row is the interrupted run's)
  clock_.dt = c.dt;
  clock_.dt_prev = c.dt_prev;
  clock_.dt_initial = c.dt_initial;
  // Global diagnostics restart on rank 0 (they are sums over ranks).
  external_work_ = comm_.rank() == 0 ? c.external_work : 0.0;
  contact_energy_ = comm_.rank() == 0 ? c.contact_energy : 0.0;
  for (std::size_t n = 0; n < nodes_.size(); ++n) {
    const std::int64_t k = find(c.node_gid, fe_.node_gid[n]);
    const double* d = &c.node_data[static_cast<std::size_t>(k) * Checkpoint::node_values];
    for (int i = 0; i < 3; ++i) {
      nodes_.x[i][n] = d[i];
      nodes_.v[i][n] = d[3 + i];
    }
    if (contact_) contact_->set_history(n, c.node_face[static_cast<std::size_t>(k)], d[6]);
  }
  for (auto& b : blocks_)
    for (int e = 0; e < b.size(); ++e) {
      const std::int64_t k = find(c.element_gid, b.gid[e]);
      const double* d = &c.element_data[static_cast<std::size_t>(k) * Checkpoint::element_values];
      for (int j = 0; j < 6; ++j) b.stress[j][e] = d[j];
      if (!b.plastic_strain.empty()) b.plastic_strain[e] = d[6];
      if (!b.temperature.empty()) b.temperature[e] = d[7];
      b.internal_energy[e] = d[8];
      b.hourglass_energy[e] = d[9];
      for (int j = 0; j < 12; ++j)
        if (!b.hourglass_force[j].empty()) b.hourglass_force[j][e] = d[10 + j];
      b.alive[e] = c.element_eroded[static_cast<std::size_t>(k)] != 0 ? 0.0 : 1.0;
      if (!b.thick_shell.enabled()) continue;
      const std::int64_t kp = find(c.point_gid, b.gid[e]);
      const double* pd = &c.point_data[static_cast<std::size_t>(kp) * Checkpoint::point_values];
      for (int p = 0; p < b.thick_shell.points; ++p, pd += 8) {
        for (int j = 0; j < 6; ++j) b.point_stress[p][j][e] = pd[j];
        if (!b.point_plastic_strain.empty()) b.point_plastic_strain[p][e] = pd[6];
        if (!b.point_temperature.empty()) b.point_temperature[p][e] = pd[7];
      }
    }
  // The eroded elements (padding lanes stay alive, as HexBlock::init made them).
  eroded_ = 0;
  for (auto& b : blocks_) {
    b.eroded = 0;
    for (int e = 0; e < b.size(); ++e) b.eroded += b.alive[e] == 0.0 ? 1 : 0;
    eroded_ += b.eroded;
  }
  share_eroded(false);
  // The padding lanes of each block repeat its last element (see HexBlock::init).
  for (auto& b : blocks_) {
    const int n = b.size();
    for (std::size_t e = static_cast<std::size_t>(n); n > 0 && e < b.mass.size(); ++e) {
      for (auto& a : b.stress) a[e] = a[n - 1];
      if (!b.plastic_strain.empty()) b.plastic_strain[e] = b.plastic_strain[n - 1];
      if (!b.temperature.empty()) b.temperature[e] = b.temperature[n - 1];
      for (auto& a : b.hourglass_force)
        if (!a.empty()) a[e] = a[n - 1];
      for (auto& ps : b.point_stress)
        for (auto& a : ps) a[e] = a[n - 1];
      for (auto& a : b.point_plastic_strain) a[e] = a[n - 1];
      for (auto& a : b.point_temperature) a[e] = a[n - 1];
    }
  }
  if (sph_) restore_particles(c, from);
}

void Simulation::scale_masses() {
  part_added_mass_.assign(config_.parts.size(), 0.0);
  mass_scaled_elements_ = 0;
  if (!(config_.mass_scaling_step > 0)) return;
  // The step each element would set, at rest in its initial shape (the kernel with
  // dt_prev = 0 changes no state), against the element step that gives the wanted one.
  const double target = config_.mass_scaling_step / config_.time_step_scale;
  const NodalView view{{nodes_.x[0].data(), nodes_.x[1].data(), nodes_.x[2].data()},
                       {nodes_.v[0].data(), nodes_.v[1].data(), nodes_.v[2].data()}};
  const CornerView corners{
      {corner_force_[0].data(), corner_force_[1].data(), corner_force_[2].data()}};
  std::vector<double> dte;
  std::int64_t overflow = 0; // a factor whose mass is not a finite number
  for (auto& b : blocks_) {
    if (b.size() == 0 || b.rigid) continue;
    dte.assign(b.mass.size(), 1e300);
    HexResult r;
    r.element_dt = dte.data();
    hex_forces(b, view, 0.0, corners, workspace_, r);
    // The inertia of a density f times higher, and its wave speed (1 / sqrt f): the
    // element's step scales with sqrt f, so f = (target / step)^2 raises it to the
    // target. Padding lanes repeat the last element, as HexBlock::init made them.
    b.mass_scale.assign(b.mass.size(), 1.0);
    b.wave_scale.assign(b.mass.size(), 1.0);
    const auto n = static_cast<std::size_t>(b.size());
    for (std::size_t e = 0; e < b.mass.size(); ++e) {
      const std::size_t k = std::min(e, n - 1);
      if (!(dte[k] < target)) continue;
      const double f = (target / dte[k]) * (target / dte[k]);
      if (!std::isfinite(b.mass[e] * f)) overflow = 1;
      const double added = b.mass[e] * (f - 1);
      b.mass_scale[e] = f;
      b.wave_scale[e] = 1 / std::sqrt(f);
      if (e < n) {
        part_added_mass_[static_cast<std::size_t>(b.part)] += added;
        ++mass_scaled_elements_;
      }
    }
  }
  for (auto& c : corner_force_) std::fill(c.begin(), c.end(), 0.0);
  // (QA round 30: a step of 1e300 s made masses of inf, and the run failed at t = 0 with a
  // non-finite force.)
  comm_.max(std::span<std::int64_t>(&overflow, 1));
  if (overflow != 0)
    throw InputError(config_.mass_scaling_where,
                     fmt::format("mass scaling to the step {:g} s needs element masses beyond "
                                 "any number (the smallest elements' steps are many orders of "
                                 "magnitude below it): give a step near the model's own",
                                 config_.mass_scaling_step));
  comm_.sum(std::span<double>(part_added_mass_));
  comm_.sum(std::span<std::int64_t>(&mass_scaled_elements_, 1));
  // LS-DYNA's users keep the added mass of a part under a few per cent (its effect on a
  // dynamic run is F = m a's): say where it is more.
  for (std::size_t p = 0; p < part_added_mass_.size(); ++p)
    if (part_added_mass_[p] > 0.05 * part_mass_[p])
      warnings_.push_back(fmt::format(
          "{}: mass scaling adds {:.3g} kg to part {}, {:.3g}% of its {:.6g} kg, to reach the "
          "step {:g} s: the dynamics of this part are those of a heavier one",
          config_.mass_scaling_where.file.empty() ? config_.deck_file
                                                  : config_.mass_scaling_where.str(),
          part_added_mass_[p], config_.parts[p].name, 100 * part_added_mass_[p] / part_mass_[p],
          part_mass_[p], config_.mass_scaling_step));
}

void Simulation::decompose_now() {
  if (contact_) contact_->detect(contact_view(), 0.0, timers_);
}

double Simulation::stable_time_step(std::int64_t* element) {
  const NodalView view{{nodes_.x[0].data(), nodes_.x[1].data(), nodes_.x[2].data()},
                       {nodes_.v[0].data(), nodes_.v[1].data(), nodes_.v[2].data()}};
  const CornerView corners{
      {corner_force_[0].data(), corner_force_[1].data(), corner_force_[2].data()}};
  HexResult r;
  // With dt_prev = 0 the kernel changes no state: rotation by the identity, no increment.
  for (auto& b : blocks_)
    if (b.size() > 0 && !b.rigid) hex_forces(b, view, 0.0, corners, workspace_, r);
  const double dt = comm_.min(r.dt_stable);
  if (element) {
    const double none = std::numeric_limits<double>::infinity();
    const double gid = comm_.min(
        r.stable_gid >= 0 && r.dt_stable == dt ? static_cast<double>(r.stable_gid) : none);
    *element = gid == none ? -1 : static_cast<std::int64_t>(gid);
  }
  return dt;
}

} // namespace anvil
