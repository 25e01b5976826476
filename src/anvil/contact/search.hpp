// Contact detection inside one rank of the contact decomposition, knowing nothing of MPI:
// global search by binning (a bucket sort of face capture boxes on a uniform grid, in the
// spirit of Benson and Hallquist 1990), then the detailed check of Heinstein et al. (1993):
// the normal projection of each node onto each candidate face, the penetration, and the
// best face. A node keeps the face it was in contact with last cycle while it still
// penetrates it (tracking: near an edge a side face can show less penetration than the
// face the node came through); otherwise the least penetration wins, ties by face global
// id. Tracked pairs are followed twice as deep as new ones are accepted. A pair needs the
// node's outward normal (from its own faces) to oppose the face's. The result
// depends only on the nodes and faces given, not on their order or on which rank holds
// them.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "anvil/contact/geometry.hpp"

#include "anvil/core/vec3.hpp"

namespace anvil {

// A contact node in the contact decomposition (trivially copyable: moved by Migration).
struct ContactNodeItem {
  std::int64_t gid;       // global node id
  int holders;            // FE ranks that hold the node (FeDecomposition's holder group)
  std::int32_t dormant;   // 1: inside an eroding part, no exposed face yet: never paired
  double x[3];            // predicted position x* = x(n) + dt v(n+1/2)
  double v[3];            // predicted velocity v(n+1/2)
  double mass;            // lumped nodal mass
  std::int64_t last_face; // face it was in contact with last cycle, or -1 (tracking)
  double allowance;       // penetration that draws no force (see ContactPair), m
};

// A contact face with everything the check and the forces need.
struct ContactFaceItem {
  std::int64_t gid;         // global face id (ExteriorFaces order)
  std::int64_t node[4];     // global node ids, counter-clockwise seen from outside
  std::int64_t opposite[4]; // the element's other four nodes (never in contact with the face)
  int holders[4];           // FE ranks that hold each node (holder groups)
  double x[4][3];           // predicted node positions
  double v[4][3];           // predicted node velocities
  double mass[4];           // nodal masses
  double stiffness;         // penalty stiffness, N/m
  double depth; // largest penetration accepted for a new pair (twice for a tracked one), m
  // Set by set_capture() from x and depth, once per cycle where the face is made, and
  // travelling with its copies: the mean plane and the capture box (below).
  double normal[3];    // unit normal of the mean plane
  double offset;       // normal . centre, m
  double warp;         // largest distance of a corner from the mean plane, m
  double lo[3], hi[3]; // capture box, m
  // 1 on the cycle erosion exposed the face (ContactPhase::set_eroded): a node already
  // behind it may pair without having come through it this step.
  std::int32_t exposed;
};

struct ContactPair {
  int node = 0;           // index into the node list
  int face = 0;           // index into the face list
  double xi = 0, eta = 0; // foot of the normal on the face
  double gap = 0;         // signed distance along the normal (< 0: penetration), m
  Vec3 normal;            // unit outward normal of the face at the foot
  // Penetration allowed without force. A pair found already penetrating (a fold closing
  // faster than the search sees it, an initial overlap) would otherwise receive the whole
  // penalty force at once and be kicked out with energy it never had; instead the depth at
  // first detection is allowed and the force resists only further penetration, the
  // allowance shrinking as the node moves out (LS-DYNA's IGNORE option).
  double allowance = 0;
};

// Mean plane of a face: centre, unit normal (from the diagonals), and size (square root
// of the area).
struct FacePlane {
  Vec3 centre, normal;
  double size = 0;
  double warp = 0; // largest distance of a corner from the plane
};
FacePlane face_plane(const ContactFaceItem& face);

// Where a node can be in contact with the face: the face swept backwards along its normal
// by twice its depth (the deepest a tracked pair goes), padded by 5% of its size for the
// parametric tolerance. The contact decomposition ghosts a face to every rank this box
// touches.
Box3 capture_box(const ContactFaceItem& face, const FacePlane& plane);

// Computes the face's mean plane and capture box from its corners and depth and stores
// them in the item (the search reads them from there); returns the plane.
FacePlane set_capture(ContactFaceItem& face);

struct SearchOptions {
  double dt = 0; // the step just predicted: x - dt v is the start of the step (0: no check)
  double parametric_tolerance = 0.02; // the foot may lie this far outside [-1, 1]^2
  // Width, in parent coordinates, of the band along a face's edges where a pair's normal
  // and gap blend with those of the faces across the edge (see check_queued): at an edge
  // or corner they are the plain average of the faces that share it, and they change
  // continuously as the foot moves across.
  double edge_blend = 0.05;
  // Skin of the candidate lists, as a fraction of the median capture-box size: a list
  // holds the faces whose capture box, enlarged by the skin, held the node when it was
  // built, and stays valid until a node or a capture-box side has moved half the skin.
  // Only the cost depends on it: every cycle tests the exact boxes of the candidates.
  // 0.14: the can crush on one rank runs as fast from 0.07 to 0.14 and slower above (longer
  // lists), on two ranks 4% faster than with 0.1 (a finer mesh, so half the skin, and each
  // rank waits while the other rebuilds; docs/performance_contact.md, "Two ranks").
  double skin = 0.14;
};

// The capture boxes, mean planes and depths of the faces (structure of arrays, one entry
// per face of the face list): what the search tests every cycle. The items' own lo, hi,
// normal, offset, warp and depth are not read.
struct FaceBoxes {
  std::span<const double> lo[3], hi[3];
  std::span<const double> normal[3], offset, warp, depth;
};

// Scratch space and candidate lists kept between cycles (no allocation in steady state).
struct SearchWorkspace {
  // Faces binned by cell, entries of a cell contiguous (cell_start, + end), in columns so
  // that a node's scan tests a vector of entries at a time: each entry's face and its
  // capture box enlarged by the skin (lo x, y, z, hi x, y, z), padded by a vector.
  std::vector<int> cell_start, cursor; // per cell: first entry; fill cursors
  std::vector<int> face_cells;         // 6 per face: the range of cells its box covers
  std::vector<int> entry_face;
  std::vector<double> entry_box[6];
  std::vector<std::int64_t> face_ids; // 8 per face: its nodes, then its opposite nodes
  std::vector<double> extent;         // largest side of each capture box
  std::vector<int> own, cand;         // a node's own faces and its candidates (scratch)
  // The detailed checks of a cycle, projected together (project_on_quads): per active
  // node its range of queries (+ end), each query's face and the feet found.
  std::vector<int> query_start, query_face;
  std::vector<QuadQuery> queries;
  std::vector<QuadProjection> feet;
  // A pair's faces across the edge or corner its foot is near (check_queued): face id,
  // query and weight.
  struct BlendEntry {
    std::int64_t gid;
    int query;
    double weight;
  };
  std::vector<BlendEntry> blend;

  // Candidate lists (Verlet lists): for each node with at least one candidate (active),
  // the faces whose enlarged capture box held it at the last build, ascending: first the
  // candidates, then its own faces (faces of the node's elements are left out). Valid
  // while the node and face ids are those of the build and nothing has moved more than
  // half the skin from where it was then.
  bool built = false;
  double skin = 0;                    // m, at the last build
  std::vector<std::int64_t> node_gid; // node ids at the last build
  std::vector<std::int64_t> face_gid; // face ids at the last build
  std::vector<double> node_ref;       // 3 per node: position at the last build
  std::vector<double> box_ref;        // 6 per face: capture box at the last build
  std::vector<int> active;            // nodes with candidates, ascending
  std::vector<int> list_start;        // per active node: its first candidate (+ end)
  std::vector<int> own_start;         // per active node: its first own face
  std::vector<int> list;              // face indices
  int longest = 0;                    // the longest range of candidates or own faces
  std::vector<int> needed;            // the faces in some list, ascending (each once)
  std::vector<char> mark;             // per face: in some list (scratch of the build)
  std::vector<double> box[12];        // find_contacts(): the items' FaceBoxes
  std::int64_t builds = 0;            // lists built since the workspace was made
};

// Finds, for every node, the face it penetrates (if any): pairs in ascending node index.
// A node never pairs with a face of an element it belongs to. Reads the capture boxes
// from the items (lo, hi): update_candidate_lists() then find_pairs().
void find_contacts(const std::vector<ContactNodeItem>& nodes,
                   const std::vector<ContactFaceItem>& faces, const SearchOptions& options,
                   SearchWorkspace& work, std::vector<ContactPair>& pairs);

// The two halves of find_contacts(), for a caller that keeps the boxes apart from the
// items. First: makes the candidate lists valid for these nodes and boxes (rebuilds them
// when a node or a box has moved too far, or the node or face ids changed); returns true
// when it rebuilt them. It reads the faces' ids, nodes and opposite nodes only. Afterwards
// work.needed lists the faces find_pairs() may read beyond those: of every other face it
// reads nothing, so the rest of their items (positions, velocities, plane) need not be
// filled.
bool update_candidate_lists(const std::vector<ContactNodeItem>& nodes,
                            const std::vector<ContactFaceItem>& faces, const FaceBoxes& boxes,
                            const SearchOptions& options, SearchWorkspace& work);
// Second: the exact capture-box test of the listed candidates and the detailed check:
// queue_candidates() then check_queued().
void find_pairs(const std::vector<ContactNodeItem>& nodes,
                const std::vector<ContactFaceItem>& faces, const FaceBoxes& boxes,
                const SearchOptions& options, SearchWorkspace& work,
                std::vector<ContactPair>& pairs);
// The two halves of find_pairs(). First, from the boxes and planes alone (no face item is
// read): the candidates that pass the cheap tests (box, mean-plane side, facing surfaces),
// per active node, into work.query_start and work.query_face. Then the detailed check of
// those, which reads the items of the faces in work.query_face only (ids, depths,
// positions and velocities): the caller may fill just those in between.
void queue_candidates(const std::vector<ContactNodeItem>& nodes, const FaceBoxes& boxes,
                      SearchWorkspace& work);
void check_queued(const std::vector<ContactNodeItem>& nodes,
                  const std::vector<ContactFaceItem>& faces, const SearchOptions& options,
                  SearchWorkspace& work, std::vector<ContactPair>& pairs);

} // namespace anvil
