// The paper's contact decomposition (steps 4 and 5 of the cycle). Every cycle the contact
// nodes (owned copies) and the exterior faces (from their elements' owners) are moved from
// the static FE decomposition to a dynamic RCB decomposition of node positions and face
// centroids: a node to the rank whose box holds its predicted position, a face to every
// rank whose box its capture box overlaps (ghosting). Each rank searches its own nodes
// against the faces it holds, computes penalty forces, and sends each force to the FE
// owner of the node it acts on; owners sum them in ascending pair id and pass the sums to
// the other ranks that hold the node. The RCB is recomputed only when the load imbalance
// exceeds a threshold (incrementally, from the previous cuts).
//
// Most cycles are lazy: while every item is within the budgets that the candidate lists
// of its receivers and the ghosting allow (faces are ghosted by their capture box
// enlarged by a margin), the last full cycle's destinations, plans and received layout
// are kept, and only what the receivers' lists read is computed and sent (detect(),
// set_shared_reference()). The pairs are those of the exact search on every cycle.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "anvil/contact/capture.hpp"
#include "anvil/contact/penalty.hpp"
#include "anvil/contact/search.hpp"
#include "anvil/contact/surface.hpp"
#include "anvil/core/gid_index.hpp"
#include "anvil/core/timer.hpp"
#include "anvil/fe/hex_block.hpp"
#include "anvil/io/config.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/parallel/fe_decomposition.hpp"
#include "anvil/parallel/migration.hpp"
#include "anvil/parallel/rcb.hpp"

namespace anvil {

struct ContactStats {
  std::int64_t cycles = 0;
  std::int64_t rebalances = 0; // RCB recomputations
  std::int64_t pairs = 0;      // node-face pairs in the last cycle (all ranks)
  double imbalance = 1;        // last cycle's max/mean contact work per rank
  double imbalance_max = 1;    // the largest seen
  double bytes_sent = 0; // this rank, all cycles: items sent to other ranks (transfers, forces)
  double max_penetration = 0;   // largest gap behind a face, over all cycles, m
  std::int64_t list_builds = 0; // this rank's candidate-list builds (SearchWorkspace)
  std::int64_t plan_builds = 0; // node and face migration plans built (destinations changed)
  // Cycles on which the bound held on every rank: only the faces in some candidate list
  // got their capture box, and on several ranks the destinations, plans and received
  // layout were kept and only what the lists read was sent.
  std::int64_t lazy_cycles = 0;
  // Largest penetration beyond the pair's allowance, over all cycles, m: the part the
  // penalty force resists. max_penetration minus this is depth a pair already had when the
  // search first found it (docs/contact.md, "The can crush and its limits").
  double max_penetration_resisted = 0;
  // Largest penetration as a share of its face's contact depth (the element's V / A times
  // depth_fraction), over all cycles: new pairs are taken to 1, a tracked pair is followed
  // to 2 and then released, so a node past 1 is close to passing through unseen (docs/
  // contact.md, "Tunnelling").
  double max_penetration_of_depth = 0;
};

// FE-side view of the nodes the contact phase reads and writes.
struct ContactNodes {
  const double* x[3]; // positions at t(n)
  const double* v[3]; // predicted velocities v(n+1/2)
  const double* mass;
  // out: contact force per local node (N). forces() writes the entries of
  // ContactPhase::force_nodes() only (zero where no pair acts); the caller keeps the others
  // at zero.
  double* force[3];
};

class ContactPhase {
public:
  // Builds the surfaces of the deck's contact parts from the global mesh (every rank holds
  // it at setup) and the element data of this rank's blocks. Collective. The contact RCB
  // chooses its cut directions in coordinates stretched by rcb_scale (Rcb).
  ContactPhase(const ContactConfig& config, const Mesh& mesh, const FeDecomposition& fe,
               const std::vector<HexBlock>& blocks, const Comm& comm,
               const Vec3& rcb_scale = {1, 1, 1});
  ~ContactPhase();

  // Step 4 for the motion predicted over dt: moves nodes and faces to the contact
  // decomposition (rebalancing it when due) and finds the node-face pairs. Collective.
  void detect(const ContactNodes& nodes, double dt, PhaseTimers& timers);
  // Step 5: penalty forces of the pairs, returned to the FE owners, summed in ascending
  // pair id and copied to every rank holding the node: fills `nodes.force`. Collective.
  // dt: the step that bounds the stiffness and the friction (PenaltyOptions), the full
  // step also where the last one is shortened to end on the end time.
  void forces(const ContactNodes& nodes, double dt, PhaseTimers& timers);

  // Contact nodes of another decomposition (SPH particles) for this cycle, given before
  // detect(): gids >= extra_gid_offset(), ascending, owner this rank. They take part in
  // the search as slave nodes (they have no faces); after forces(), extra_forces() holds
  // the force on each (N, in the order given, summed like a node's) and extra_faces() the
  // face it touched (-1: none), for its tracking next cycle.
  void set_extra_nodes(std::span<const ContactNodeItem> items);
  std::int64_t extra_gid_offset() const { return extra_offset_; }
  std::span<const std::array<double, 3>> extra_forces() const { return extra_force_; }
  std::span<const std::int64_t> extra_faces() const { return extra_face_; }

  // The elements of the whole mesh eroded since the last call (global ids, ascending;
  // every rank the same list): their faces leave the surfaces, and the faces they covered
  // join them, from the next detect() on (LS-DYNA's eroding contact). Collective in effect:
  // every rank calls it with the same list whenever an element has eroded anywhere (after
  // a restart, once with every eroded element). Only the faces and nodes of those elements
  // are looked at. `exposing`: the faces that join the surface were exposed this cycle
  // (false after a restart: they were exposed before the checkpoint).
  void set_eroded(std::span<const std::int64_t> fresh, bool exposing = true);

  const ContactStats& stats() const { return stats_; }
  // Local indices, ascending, of the nodes that a contact force can act on here: the
  // contact nodes this rank holds, owned or not. forces() writes nodes.force there only.
  std::span<const int> force_nodes() const { return force_nodes_; }
  // Contact history per local node (meaningful on the node's owner): the face it touched
  // last cycle (-1 for none) and its allowance. For checkpoints; set_history restores it.
  const std::vector<std::int64_t>& last_face() const { return last_face_; }
  const std::vector<double>& allowance() const { return allowance_; }
  void set_history(std::size_t local_node, std::int64_t face, double allowance) {
    history_set_all_ = true; // the next forces() clears every owned node's history
    last_face_[local_node] = face;
    allowance_[local_node] = allowance;
  }
  // The contact RCB (valid after the first detect()).
  const Rcb& rcb() const { return rcb_; }
  // Items this rank held in the contact decomposition at the last detect(): its own
  // nodes, and the faces it held (owned by centroid plus ghosts).
  std::size_t nodes_held() const { return search_nodes_->size(); }
  std::size_t faces_held() const { return search_faces_->size(); }
  // RCB owner rank of each face of each owned element, -1 where the element has none
  // (first active face by side), per block and element (for the contact_rank field).
  std::vector<std::vector<int>> element_contact_rank(const std::vector<HexBlock>& blocks) const;

private:
  const ContactConfig config_;
  const FeDecomposition& fe_;
  GidIndex node_index_; // fe_.node_gid[k] -> k
  const Comm& comm_;
  std::int64_t global_nodes_ = 0; // offset that keeps face point ids apart from node ids
  std::int64_t extra_offset_ = 0; // first id of extra nodes (after nodes and faces)

  // Extra nodes of this cycle (set_extra_nodes) and what forces() returns for them.
  std::vector<ContactNodeItem> extra_;
  std::vector<std::array<double, 3>> extra_force_;
  std::vector<std::int64_t> extra_face_;

  // FE side (this rank): contact nodes it owns and faces of elements it owns.
  std::vector<int> my_nodes_;           // local node indices
  std::vector<int> force_nodes_;        // every local contact node, owned or not, ascending
  std::vector<std::int64_t> last_face_; // per local node: face contacted last cycle
  std::vector<double> allowance_;       // per local node: penetration allowed without force
  std::vector<int> history_set_;        // local nodes whose history forces() set last cycle
  bool history_set_all_ = false;        // set_history() may have set any
  // forces(): per rank, stat_values values (load, pairs, deepest, deepest resisted, deepest
  // share of the depth) and the force items' counts
  static constexpr std::size_t stat_values = 5;
  std::vector<double> mine_, gathered_;
  // per destination, of this rank and all-gathered
  std::vector<std::int64_t> force_counts_, force_recv_; // force items to, from each rank
  std::vector<std::int64_t> my_face_gid_;
  std::vector<std::array<int, 4>> my_face_nodes_;    // local node indices
  std::vector<std::array<int, 4>> my_face_opposite_; // the element's other four nodes
  std::vector<double> my_face_stiffness_, my_face_depth_;
  std::vector<std::pair<std::int64_t, int>> my_face_element_; // (element gid, side)
  std::vector<std::int64_t> my_face_behind_;                  // ExteriorFaces::behind of each face
  std::vector<std::uint8_t> face_active_;  // its element alive, and exterior or exposed
  std::vector<std::uint8_t> face_exposed_; // 1 on the cycle erosion exposed it
  // Per owned contact node (my_nodes_): 1 while no element it belongs to has eroded
  // (inside an eroding part).
  std::vector<std::uint8_t> node_dormant_;
  // (element gid, owned node k) of the dormant nodes, and (element gid, face f) of each
  // face's element and of the element behind it, ascending: what an erosion changes.
  std::vector<std::pair<std::int64_t, std::size_t>> dormant_by_element_, faces_by_element_;
  std::vector<std::int64_t> eroded_;       // every element eroded so far (ascending)
  std::vector<std::int64_t> eroded_merge_; // set_eroded()'s buffer for the merge
  int exposed_age_ = 0;               // 1: set_eroded() exposed faces this cycle; 2: last cycle
  std::vector<int> my_face_rank_;     // contact rank of the centroid, last cycle
  std::size_t live_ = 0;              // faces active (face_active_)
  std::vector<int> live_faces_;       // the active faces, ascending, when not every face is
  std::uint64_t surface_version_ = 0; // counts the changes of face_active_
  // The surface's points on this rank: the owned contact nodes and the corners of the
  // faces above (local node indices, ascending), with their predicted positions, computed
  // once a cycle; the nodes' and the faces' corners as indices into them.
  std::vector<int> surf_local_;
  std::vector<double> xs_[3];
  std::vector<int> node_point_;   // per owned contact node
  std::vector<int> corner_[4];    // per face, padded to whole vectors: its corners' points
  std::vector<double> depth_pad_; // per face, padded: its depth
  FaceCaptures cap_;              // per face: mean plane and capture box of this cycle
  // True when every node and face stays on this rank (one copy each): the search then
  // reads the boxes and planes from cap_ and the items in place, and only the faces it
  // queues for the detailed check get their positions, velocities and plane packed
  // (pack_face).
  bool in_place_ = false;
  std::vector<std::int64_t> packed_; // per face: the cycle (stats_.cycles) it was packed
  // One rank, every face alive, no extra nodes: a cycle may skip the capture boxes of the
  // faces in no candidate list when the nodes and a bound of the boxes show the lists still
  // valid (lazy_bound_holds(); the faces' references sf_*, as on several ranks). Set on the
  // last cycle that computed every box:
  bool lazy_ = false;             // it is set
  std::int64_t lazy_builds_ = -1; // for the lists of this build (search_.builds)
  std::vector<double> node_due_;  // per owned node (padded): the drift_ (below) at which it
                                  // may first have moved 0.45 skin from the build
  // Several ranks: a bound of the same kind, per item, with budgets from the receivers'
  // candidate lists and from the ghosting, lets a cycle keep the last full cycle's
  // destinations, plans and received layout and send only what the receivers' lists read
  // (detect()). Faces are ghosted by their capture box enlarged by ghost_margin_ (g),
  // nodes by their position: while no node has moved 0.45 g and no box side 0.45 g since,
  // every face whose box holds a node is held where the node is (set_shared_reference()).
  // Each item has its own reference: a face whose bound fails is checked exactly and, if
  // within its budget, gets a new reference on its own (rebase_faces()).
  double ghost_margin_ = 0;                  // g, m (the same on every rank, set at construction)
  bool shared_ = false;                      // the references are set
  std::uint64_t version_ref_ = 0;            // surface_version_ at the last full cycle
  std::vector<double> sn_x_[3];              // per owned contact node: x* at its reference
  std::vector<double> sn_budget_, sn_ghost_; // per node: how far it may move from there
                                             // (largest coordinate), and for the ghosting
  std::vector<double> sn_due_; // per node (padded): the drift_ at which it may first have
                               // moved its budget (shared_bound_holds() looks at it then)
  struct FaceRefs { // per face (padded), at its reference, in columns (a look takes a vector):
    std::vector<int> corner[4];  // its corners' points (corner_)
    std::vector<double> x[4][3]; // their x*
    std::vector<double> a, b;    // the bound's coefficients
    std::vector<double> largest; // the largest corner move its budget allows (first bound)
    void resize(std::size_t n);
  };
  FaceRefs sf_ref_;               // what a look at a face reads
  std::vector<double> sf_box_[6]; // per face: capture box then (lo, then hi)
  // drift_: the sum over cycles of the largest move of any point's x* since the previous
  // cycle, m. sf_due_: per face (padded), the drift_ at which its corners may first have
  // moved too far for its budget (find_failing_faces() looks at it again then).
  double drift_ = 0;
  std::vector<double> sf_due_;
  // rel_drift_: the same sum of the largest move of a point less a common vector W (the
  // mean move of the previous cycle), or of its move where that is less, m: no corner's
  // offset from its face's mean move grows by more than 1.5 times its growth (u_a - T =
  // 3/4 (u_a - W) - 1/4 of the other three corners' moves less W). sf_due_rel_: per face
  // (padded), the rel_drift_ at which it may first fail (infinite when sf_due_ alone says).
  double rel_drift_ = 0;
  double w_step_[3] = {0, 0, 0};
  double drift_rate_ = 0, rel_rate_ = 0; // their recent growths per cycle, m
  std::vector<double> sf_due_rel_;
  std::vector<double> sf_budget_, sf_ghost_; // per face (padded): how far its box sides may
                                             // move from there, and for the ghosting, m
  std::vector<double> sf_list_;              // per face (padded): for the receivers' lists, m
  std::vector<int> sf_dest_;                 // per face: its one rank, -2 for every rank, else -1
  std::vector<char> sf_near_;                // per face: listed in near_
  std::vector<int> near_;      // alive faces whose centre may leave its rank's box (contact_rank)
  std::vector<int> fail_;      // faces whose bound failed this cycle
  bool one_copy_each_ = false; // every live face has one copy (copy k is face k)
  struct Feedback {            // a receiver's word on one item it holds:
    double budget;             // how far it may move before the lists fail, m
    std::int64_t keep;         // its lists read it (1) or not (0)
  };
  std::vector<Feedback> fb_recv_, fb_send_; // per received item, per local item (or copy)
  std::vector<char> keep_recv_, keep_send_; // the keep flags, for the subset plans
  std::vector<int> sub_faces_;              // faces with some kept copy, ascending
  // What a lazy cycle sends of a face: the fields that change (those of pack_cycle()).
  struct FaceMotion {
    double x[4][3], v[4][3], mass[4];
    double normal[3], offset, warp, lo[3], hi[3];
    std::int32_t exposed;
  };
  Migration node_sub_, face_sub_; // the kept part of node_plan_, face_plan_
  std::vector<ContactNodeItem> node_sub_in_;
  std::vector<FaceMotion> face_sub_in_;
  std::vector<int> motion_; // per received face: its index in face_sub_in_, or -1 - f for
                            // face f of this rank (its motion not packed)
  std::vector<std::int64_t> unpacked_; // per received face: the cycle its item was completed
  // FaceBoxes of face_in_: lo x, y, z, hi x, y, z, normal x, y, z, offset, warp, depth.
  std::vector<double> recv_box_[12];

  Rcb rcb_;
  std::vector<Box3> rank_box_; // rcb_.box(r) of every rank, since the last partition
  bool partitioned_ = false;
  bool rebalance_due_ = true;
  // The imbalance a rebalance left (measured in the same cycle's forces()): the next one is
  // due only past 5% above it, where the cut cannot bring it under the threshold (QA round
  // 17: a small model on 6 ranks recut every cycle at 1.39 against 1.2).
  bool just_rebalanced_ = false;
  double rebalance_floor_ = 1;

  // Buffers reused every cycle.
  std::vector<double> px_, py_, pz_, pw_;
  std::vector<std::int64_t> pid_;
  std::vector<ContactNodeItem> node_out_, node_in_;
  std::vector<ContactFaceItem> face_local_, face_in_;         // per face, received
  std::vector<int> node_dest_, face_dest_, face_src_, ranks_; // face_src_: face of each copy
  // The destinations the plans were built for (reused while nobody's have changed).
  std::vector<int> node_dest_built_, face_dest_built_, face_src_built_;
  bool plans_built_ = false;
  bool face_in_full_ = false; // face_in_ holds the items of face_plan_ (constant fields too)
  // What the search and the forces read: the received items, or the local ones in place
  // where every item stays on this rank.
  const std::vector<ContactNodeItem>* search_nodes_ = &node_in_;
  const std::vector<ContactFaceItem>* search_faces_ = &face_in_;
  std::vector<ContactPair> pairs_;
  std::vector<ContactForceItem> force_out_, force_in_;
  std::vector<int> item_key_, key_start_, item_order_; // grouping of the force items by node
  std::vector<int> force_dest_;
  SearchWorkspace search_;
  Migration node_plan_, face_plan_, force_plan_;
  ContactStats stats_;

  // Writes this cycle's corners (predicted positions, velocities, masses), plane and
  // capture box into face_local_[f].
  void pack_face(std::size_t f, const ContactNodes& nodes);
  // The same fields, and the constant ones of face_local_[f], into another item.
  void pack_copy(std::size_t f, const ContactNodes& nodes, ContactFaceItem& it) const;
  template <class Item>
  void pack_cycle(std::size_t f, const ContactNodes& nodes, Item& it) const;
  // Writes this cycle's fields of owned contact node k (x*, v, mass, history) into it.
  void pack_node(std::size_t k, const ContactNodes& nodes, ContactNodeItem& it) const;
  // The faces' corners and depths as compute_captures() reads them.
  FaceCorners corners() const;
  // Sets the bound's reference from this cycle's exact boxes and the lists just checked.
  void set_lazy_reference();
  // One rank: the largest deviation of face f's box (cap_) from the build's, and of owned
  // node k's position.
  double build_deviation(std::size_t f) const;
  double node_deviation(std::size_t k) const;
  // Several ranks, after a full cycle's search (collective): the receivers' budgets and
  // keep flags back to the senders, the bound's reference, and the subset plans.
  void set_shared_reference(const FaceBoxes& boxes, bool recomputed);
  // Several ranks: true when every node is within its budget; fail_ gets the faces whose
  // bound fails.
  bool shared_bound_holds();
  // The bound of the vector of faces from f (V = simd::vdouble) or of face f (V = double;
  // one template, the same operations lane by lane): their motion since the reference
  // (vectors only: looks), whether their sides are within their budgets, how much further
  // drift_ may grow before that could fail, and their due drifts from there (sf_due_,
  // sf_due_rel_).
  template <class V>
  struct FaceMotionBound {
    V delta; // largest move of a corner, m
    V t, r;  // largest coordinate of the corners' mean move; largest move about it, m
  };
  template <class V>
  FaceMotionBound<V> face_motion(std::size_t f) const;
  template <class V>
  auto within_budget(std::size_t f, const FaceMotionBound<V>& m) const;
  template <class V>
  V drift_allowed(std::size_t f, const FaceMotionBound<V>& m) const;
  template <class V>
  void due_drifts(std::size_t f, const FaceMotionBound<V>& m, V& due, V& due_rel) const;
  // The faces of fail_ checked exactly: true when each is within its budget; each then
  // gets this cycle as its reference, its budgets less what it used.
  bool rebase_faces();
  // Face f's reference: this cycle's corners and exact box (cap_), and its rank
  // (set_face_budget(), then set_bound_reference()).
  void set_face_reference(std::size_t f);
  void set_face_budget(std::size_t f); // its box, budget and rank
  // How deep the box [lo, hi] lies inside rank r's box (rank_box_), m; negative outside.
  double depth_in_box(double lo0, double lo1, double lo2, double hi0, double hi1, double hi2,
                      int r) const;
  // Its bound's part (corners and coefficients, when it is next looked at), given its
  // budget: of face f (V = double), or of the faces from f (V = simd::vdouble; no
  // padding among them).
  template <class V>
  void set_bound_reference(std::size_t f);
  void set_bound_references(); // of every face (padded), a vector at a time where it can
  // fail_: the faces whose bound fails (the others are within their budgets).
  void find_failing_faces();
  // A lazy cycle's fields of a received face: the box and plane (recv_box_), and the
  // rest of them into its item face_in_[j] (only for the faces the search checks).
  void unpack_motion(const FaceMotion& m, std::size_t j);
  void complete_item(const FaceMotion& m, std::size_t j);
  // Face f is on the surface: its element has not eroded, and it is exterior or erosion
  // has removed the element across it.
  bool active(std::size_t f) const { return face_active_[f] != 0; }
  void list_live_faces();
  void compute_live_captures();
  // Several ranks: node and face destinations (faces by their enlarged capture box); true
  // when they differ from those the plans were built for.
  bool compute_destinations(std::size_t live);
  // my_face_rank_ of face f from its centre c (Rcb::owner's answer).
  void update_face_rank(std::size_t f, const double (&c)[3]);
  // One rank: true when every node and every capture-box side is within 0.45 skin of where
  // the candidate lists were built, computing the boxes only of the faces whose bound
  // fails (they get new references).
  bool lazy_bound_holds();
};

} // namespace anvil
