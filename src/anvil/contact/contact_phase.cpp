#include "anvil/contact/contact_phase.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "anvil/core/simd.hpp"

namespace anvil {

namespace {

// Writes face j's capture box and mean plane (lo, hi, normal, offset, warp) from a received
// item or motion into the search's arrays (lo x y z, hi x y z, normal x y z, offset, warp).
template <class Face>
void put_box_and_plane(std::vector<double> (&box)[12], std::size_t j, const Face& f) {
  for (int i = 0; i < 3; ++i) {
    box[i][j] = f.lo[i];
    box[3 + i][j] = f.hi[i];
    box[6 + i][j] = f.normal[i];
  }
  box[9][j] = f.offset;
  box[10][j] = f.warp;
}
// The same from face f of this rank's captures.
void put_box_and_plane(std::vector<double> (&box)[12], std::size_t j, const FaceCaptures& c,
                       std::size_t f) {
  for (int i = 0; i < 3; ++i) {
    box[i][j] = c.lo[i][f];
    box[3 + i][j] = c.hi[i][f];
    box[6 + i][j] = c.normal[i][f];
  }
  box[9][j] = c.offset[f];
  box[10][j] = c.warp[f];
}

// Orders (element gid, index) pairs by element, for equal_range on an element gid.
struct ByElement {
  template <class T>
  bool operator()(const std::pair<std::int64_t, T>& a, std::int64_t el) const {
    return a.first < el;
  }
  template <class T>
  bool operator()(std::int64_t el, const std::pair<std::int64_t, T>& a) const {
    return el < a.first;
  }
};

// The bound of a face's capture box (derived above set_lazy_reference()):
// its sides move by at most m = delta (1 + A (B + 4 delta)) when no corner has moved more
// than delta since the reference, with A and B from the reference geometry (len = |D1 x
// D2|, diag = |D1| + |D2| of the diagonals, depth the face's contact depth).
template <class V>
inline V bound_a(const V& depth, const V& len) {
  using std::sqrt;
  return 4.0 * depth / len + 0.025 / sqrt(0.5 * len);
}
template <class V>
inline V side_move(const V& delta, const V& a, const V& b) {
  return delta * (1 + a * (b + 4 * delta));
}

// The lanes of a per-face column: face f (double) or the faces from f (simd::vdouble);
// and those of a column through an index column (a vector only: face_motion()).
inline double lanes(const std::vector<double>& c, std::size_t f, double) {
  return c[f];
}
inline simd::vdouble lanes(const std::vector<double>& c, std::size_t f, simd::vdouble) {
  return simd::load(c.data() + f);
}
inline void put(double v, std::vector<double>& c, std::size_t f) {
  c[f] = v;
}
inline void put(const simd::vdouble& v, std::vector<double>& c, std::size_t f) {
  simd::store(v, c.data() + f);
}
inline simd::vdouble at(const std::vector<double>& c, const std::vector<int>& idx, std::size_t f,
                        simd::vdouble) {
  return simd::gather(c.data(), idx.data() + f);
}

} // namespace

ContactPhase::~ContactPhase() = default;

ContactPhase::ContactPhase(const ContactConfig& config, const Mesh& mesh, const FeDecomposition& fe,
                           const std::vector<HexBlock>& blocks, const Comm& comm,
                           const Vec3& rcb_scale)
    : config_(config), fe_(fe), comm_(comm), rcb_(comm, rcb_scale) {
  global_nodes_ = mesh.num_nodes();
  const std::vector<bool> selected = blocks_named(mesh, config.parts);
  // Parts that erode also list the faces between their elements, active once erosion
  // exposes them (set_eroded).
  std::vector<bool> erodible(mesh.blocks.size(), false);
  for (std::size_t b = 0; b < blocks.size() && b < erodible.size(); ++b)
    erodible[b] = blocks[b].erosion.enabled();
  const ExteriorFaces surf = exterior_faces(mesh, selected, erodible);
  extra_offset_ = global_nodes_ + static_cast<std::int64_t>(surf.size());

  node_index_ = GidIndex(fe.node_gid);
  auto local = [&](std::int64_t gid) { return node_index_.find(gid); };
  for (auto gid : surf.contact_nodes) {
    const int l = local(gid);
    if (l >= 0 && fe.node_owned[l]) my_nodes_.push_back(l);
    if (l >= 0) force_nodes_.push_back(l);
  }
  std::sort(force_nodes_.begin(), force_nodes_.end());
  history_set_.reserve(force_nodes_.size()); // a node is the slave of one pair at most
  // Nodes on no exterior face (inside an eroding part) are dormant, searched for no pair,
  // until an element they belong to erodes (set_eroded): the elements of each.
  {
    std::vector<std::int64_t> exterior;
    for (std::size_t f = 0; f < surf.size(); ++f)
      if (surf.behind[f] < 0)
        exterior.insert(exterior.end(), surf.nodes[f].begin(), surf.nodes[f].end());
    std::sort(exterior.begin(), exterior.end());
    node_dormant_.assign(my_nodes_.size(), 0);
    std::vector<std::pair<std::int64_t, std::size_t>> inner; // (gid, k) of dormant nodes
    for (std::size_t k = 0; k < my_nodes_.size(); ++k) {
      const std::int64_t g = fe.node_gid[static_cast<std::size_t>(my_nodes_[k])];
      if (!std::binary_search(exterior.begin(), exterior.end(), g)) {
        node_dormant_[k] = 1;
        inner.emplace_back(g, k);
      }
    }
    auto& adj = dormant_by_element_;
    if (!inner.empty()) {
      std::int64_t el = 0;
      for (const auto& b : mesh.blocks)
        for (const auto& h : b.elements) {
          for (const std::int64_t g : h) {
            const auto it =
                std::lower_bound(inner.begin(), inner.end(), std::make_pair(g, std::size_t{0}));
            if (it != inner.end() && it->first == g) adj.emplace_back(el, it->second);
          }
          ++el;
        }
      std::sort(adj.begin(), adj.end());
      adj.erase(std::unique(adj.begin(), adj.end()), adj.end());
    }
  }
  // Faces of owned elements, with the penalty stiffness k = scale K A^2 / V and the
  // contact depth fraction V / A of their element, from the initial geometry.
  const auto offsets = mesh.block_offsets();
  for (std::size_t f = 0; f < surf.size(); ++f) {
    const std::int64_t el = surf.element[f];
    const auto b = static_cast<std::size_t>(std::upper_bound(offsets.begin(), offsets.end(), el) -
                                            offsets.begin() - 1);
    const auto& gids = blocks[b].gid;
    const auto it = std::lower_bound(gids.begin(), gids.end(), el);
    if (it == gids.end() || *it != el) continue;
    const auto e = static_cast<std::size_t>(it - gids.begin());
    std::array<int, 4> ln;
    std::array<Vec3, 4> p;
    for (int a = 0; a < 4; ++a) {
      ln[a] = local(surf.nodes[f][a]);
      p[a] = mesh.nodes[surf.nodes[f][a]];
    }
    const double area = 0.5 * norm(cross(p[2] - p[0], p[3] - p[1]));
    const double vol = blocks[b].volume[e];
    const double K = blocks[b].material->elastic().bulk;
    my_face_gid_.push_back(static_cast<std::int64_t>(f));
    my_face_nodes_.push_back(ln);
    std::array<int, 4> opp{};
    int k = 0;
    for (int a = 0; a < 8; ++a)
      if (std::find(hex_faces[surf.side[f]].begin(), hex_faces[surf.side[f]].end(), a) ==
          hex_faces[surf.side[f]].end())
        opp[k++] = blocks[b].conn[a][e];
    my_face_opposite_.push_back(opp);
    my_face_stiffness_.push_back(config.penalty_scale * K * area * area / vol);
    my_face_depth_.push_back(config.depth_fraction * vol / area);
    my_face_element_.emplace_back(el, surf.side[f]);
    my_face_behind_.push_back(surf.behind[f]);
  }
  face_active_.resize(my_face_gid_.size());
  face_exposed_.assign(my_face_gid_.size(), 0);
  for (std::size_t f = 0; f < face_active_.size(); ++f) {
    face_active_[f] = my_face_behind_[f] < 0;
    faces_by_element_.emplace_back(my_face_element_[f].first, f);
    if (my_face_behind_[f] >= 0) faces_by_element_.emplace_back(my_face_behind_[f], f);
  }
  std::sort(faces_by_element_.begin(), faces_by_element_.end());
  live_ = static_cast<std::size_t>(std::count(face_active_.begin(), face_active_.end(), 1));
  list_live_faces();
  my_face_rank_.assign(my_face_gid_.size(), comm.rank());
  const std::size_t nf_all = my_face_gid_.size();
  // The fields of the items that never change (ids, owners, penalty data), set once.
  node_out_.resize(my_nodes_.size());
  for (std::size_t k = 0; k < my_nodes_.size(); ++k) {
    node_out_[k] = {};
    node_out_[k].gid = fe.node_gid[static_cast<std::size_t>(my_nodes_[k])];
    node_out_[k].holders = fe.node_holders[static_cast<std::size_t>(my_nodes_[k])];
  }
  face_local_.resize(my_face_gid_.size());
  for (std::size_t f = 0; f < face_local_.size(); ++f) {
    auto& it = face_local_[f];
    it = {};
    it.gid = my_face_gid_[f];
    for (int a = 0; a < 4; ++a) {
      const auto l = static_cast<std::size_t>(my_face_nodes_[f][a]);
      it.node[a] = fe.node_gid[l];
      it.holders[a] = fe.node_holders[l];
      it.opposite[a] = fe.node_gid[static_cast<std::size_t>(my_face_opposite_[f][a])];
    }
    it.stiffness = my_face_stiffness_[f];
    it.depth = my_face_depth_[f];
  }
  // The surface points: owned contact nodes and face corners, each once.
  surf_local_ = my_nodes_;
  for (const auto& ln : my_face_nodes_) surf_local_.insert(surf_local_.end(), ln.begin(), ln.end());
  std::sort(surf_local_.begin(), surf_local_.end());
  surf_local_.erase(std::unique(surf_local_.begin(), surf_local_.end()), surf_local_.end());
  auto point = [&](int l) {
    return static_cast<int>(std::lower_bound(surf_local_.begin(), surf_local_.end(), l) -
                            surf_local_.begin());
  };
  for (int i = 0; i < 3; ++i) xs_[i].resize(surf_local_.size());
  for (int l : my_nodes_) node_point_.push_back(point(l));
  const auto padded = static_cast<std::size_t>(simd::padded_size(static_cast<int>(nf_all)));
  for (int a = 0; a < 4; ++a) {
    corner_[a].assign(padded, 0);
    for (std::size_t f = 0; f < nf_all; ++f) corner_[a][f] = point(my_face_nodes_[f][a]);
  }
  depth_pad_.assign(padded, 0.0);
  std::copy(my_face_depth_.begin(), my_face_depth_.end(), depth_pad_.begin());
  cap_.resize(nf_all);
  packed_.assign(nf_all, -1);
  last_face_.assign(fe.node_gid.size(), -1);
  allowance_.assign(fe.node_gid.size(), 0.0);
  {
    const auto P = static_cast<std::size_t>(comm.size());
    mine_.assign(stat_values + P, 0.0);
    gathered_.assign((stat_values + P) * P, 0.0);
    force_counts_.assign(P, 0);
    force_recv_.assign(P, 0);
  }
  // Several ranks: the ghosting margin g (set_shared_reference), the skin the candidate
  // lists use (SearchOptions::skin of the median capture-box extent) for the initial
  // geometry, the least over the ranks so that every rank uses the same.
  if (comm.size() > 1) {
    for (std::size_t k = 0; k < surf_local_.size(); ++k) {
      const Vec3& p = mesh.nodes[static_cast<std::size_t>(
          fe.node_gid[static_cast<std::size_t>(surf_local_[k])])];
      for (int i = 0; i < 3; ++i) xs_[i][k] = p[i];
    }
    compute_captures(corners(), cap_);
    std::vector<double> extent(nf_all);
    for (std::size_t f = 0; f < nf_all; ++f)
      extent[f] = std::max({cap_.hi[0][f] - cap_.lo[0][f], cap_.hi[1][f] - cap_.lo[1][f],
                            cap_.hi[2][f] - cap_.lo[2][f]});
    double median = std::numeric_limits<double>::infinity();
    if (!extent.empty()) {
      std::nth_element(extent.begin(), extent.begin() + static_cast<std::ptrdiff_t>(nf_all / 2),
                       extent.end());
      median = extent[nf_all / 2];
    }
    const double g = comm.min(SearchOptions{}.skin * median);
    ghost_margin_ = std::isfinite(g) ? g : 0.0;
  }
}

void ContactPhase::set_extra_nodes(std::span<const ContactNodeItem> items) {
  extra_.assign(items.begin(), items.end());
}

void ContactPhase::pack_face(std::size_t f, const ContactNodes& nd) {
  pack_cycle(f, nd, face_local_[f]);
}

void ContactPhase::pack_copy(std::size_t f, const ContactNodes& nd, ContactFaceItem& it) const {
  const ContactFaceItem& c = face_local_[f]; // its constant fields
  it.gid = c.gid;
  for (int a = 0; a < 4; ++a) {
    it.node[a] = c.node[a];
    it.opposite[a] = c.opposite[a];
    it.holders[a] = c.holders[a];
  }
  it.stiffness = c.stiffness;
  it.depth = c.depth;
  pack_cycle(f, nd, it);
}

template <class Item>
void ContactPhase::pack_cycle(std::size_t f, const ContactNodes& nd, Item& it) const {
  for (int a = 0; a < 4; ++a) {
    const int l = my_face_nodes_[f][a];
    const auto k = static_cast<std::size_t>(corner_[a][f]);
    for (int i = 0; i < 3; ++i) {
      it.x[a][i] = xs_[i][k];
      it.v[a][i] = nd.v[i][l];
    }
    it.mass[a] = nd.mass[l];
  }
  for (int i = 0; i < 3; ++i) {
    it.normal[i] = cap_.normal[i][f];
    it.lo[i] = cap_.lo[i][f];
    it.hi[i] = cap_.hi[i][f];
  }
  it.offset = cap_.offset[f];
  it.warp = cap_.warp[f];
  it.exposed = face_exposed_[f];
}

// (Inlined: it runs once per owned contact node on full cycles.)
[[gnu::always_inline]] inline void ContactPhase::pack_node(std::size_t k, const ContactNodes& nd,
                                                           ContactNodeItem& it) const {
  const auto l = static_cast<std::size_t>(my_nodes_[k]);
  const auto p = static_cast<std::size_t>(node_point_[k]);
  it.gid = node_out_[k].gid;
  it.holders = node_out_[k].holders;
  for (int i = 0; i < 3; ++i) {
    it.x[i] = xs_[i][p];
    it.v[i] = nd.v[i][l];
  }
  it.mass = nd.mass[l];
  it.last_face = last_face_[l];
  it.allowance = allowance_[l];
  it.dormant = node_dormant_[k];
}

void ContactPhase::unpack_motion(const FaceMotion& m, std::size_t j) {
  put_box_and_plane(recv_box_, j, m);
}

void ContactPhase::complete_item(const FaceMotion& m, std::size_t j) {
  ContactFaceItem& it = face_in_[j];
  for (int a = 0; a < 4; ++a) {
    for (int i = 0; i < 3; ++i) {
      it.x[a][i] = m.x[a][i];
      it.v[a][i] = m.v[a][i];
    }
    it.mass[a] = m.mass[a];
  }
  for (int i = 0; i < 3; ++i) {
    it.normal[i] = m.normal[i];
    it.lo[i] = m.lo[i];
    it.hi[i] = m.hi[i];
  }
  it.offset = m.offset;
  it.warp = m.warp;
  it.exposed = m.exposed;
}

void ContactPhase::set_eroded(std::span<const std::int64_t> fresh, bool exposing) {
  // (Merged through a kept buffer: std::inplace_merge takes a temporary one each call.)
  eroded_merge_.resize(eroded_.size() + fresh.size());
  std::merge(eroded_.begin(), eroded_.end(), fresh.begin(), fresh.end(), eroded_merge_.begin());
  eroded_.swap(eroded_merge_);
  auto gone = [&](std::int64_t el) {
    return std::binary_search(eroded_.begin(), eroded_.end(), el);
  };
  bool changed = false;
  // The marks of last cycle's exposures go now (a restart after that cycle has none).
  if (exposed_age_ != 0) {
    std::fill(face_exposed_.begin(), face_exposed_.end(), 0);
    exposed_age_ = 0;
    changed = true;
  }
  // Of each fresh element: its dormant nodes wake, and the faces of it and behind it are
  // looked at again (a face is active while its element lives, exterior or exposed).
  auto of = [](const auto& pairs, std::int64_t el) {
    return std::equal_range(pairs.begin(), pairs.end(), el, ByElement{});
  };
  for (const std::int64_t el : fresh) {
    for (auto [it, end] = of(dormant_by_element_, el); it != end; ++it) {
      changed |= node_dormant_[it->second] != 0;
      node_dormant_[it->second] = 0;
    }
    for (auto [it, end] = of(faces_by_element_, el); it != end; ++it) {
      const std::size_t f = it->second;
      const std::int64_t behind = my_face_behind_[f];
      const std::uint8_t a = !gone(my_face_element_[f].first) && (behind < 0 || gone(behind));
      if (a == face_active_[f]) continue;
      changed = true;
      if (a != 0 && behind >= 0 && exposing) {
        face_exposed_[f] = 1;
        exposed_age_ = 1;
      }
      face_active_[f] = a;
      live_ = a != 0 ? live_ + 1 : live_ - 1;
    }
  }
  if (!changed) return;
  list_live_faces();
  ++surface_version_;
}

void ContactPhase::list_live_faces() {
  live_faces_.clear();
  if (live_ == face_active_.size()) return; // (every face: no list needed)
  for (std::size_t f = 0; f < face_active_.size(); ++f)
    if (face_active_[f] != 0) live_faces_.push_back(static_cast<int>(f));
}

// The planes and boxes of the live faces: of an eroding part's interior faces, which
// outnumber its exterior ones several times, only those erosion has exposed.
void ContactPhase::compute_live_captures() {
  if (live_ == my_face_gid_.size())
    compute_captures(corners(), cap_);
  else
    compute_captures(corners(), live_faces_, cap_);
}

FaceCorners ContactPhase::corners() const {
  return {{xs_[0].data(), xs_[1].data(), xs_[2].data()},
          {corner_[0].data(), corner_[1].data(), corner_[2].data(), corner_[3].data()},
          depth_pad_.data(),
          my_face_gid_.size()};
}

// The bound. The lists stay valid while every node and every capture-box side is within
// h = 0.45 skin of where it was at the build (lists_valid in search.cpp). A box's sides
// move by at most m = delta (1 + A (B + 4 delta)) when no corner of the face has moved
// more than delta since a reference (a cycle that computed its box exactly): a corner term
// moves by delta, the swept corner also by 2 d |n' - n| <= 4 d |N' - N| / |N| (N the
// cross product of the diagonals D1, D2, n = N / |N|), and the pad by 0.05 |size' - size|
// <= 0.025 |N' - N| / size; and |N' - N| <= 2 delta (|D1| + |D2|) + 4 delta^2. So A = 4 d /
// |N| + 0.025 / size and B = 2 (|D1| + |D2|), at the reference. A flat face (|N| = 0)
// never passes. On one rank each face has its own reference, and its budget is h less its
// box's deviation from the build there; the nodes are tested exactly every cycle
// (lazy_bound_holds()). Set here, on a cycle that computed every box and found the lists
// valid.
void ContactPhase::set_lazy_reference() {
  const std::size_t nf = my_face_gid_.size();
  const std::size_t nfp = static_cast<std::size_t>(simd::padded_size(static_cast<int>(nf)));
  const SearchWorkspace& w = search_;
  const double h = 0.45 * w.skin;
  sf_ref_.resize(nfp);
  sf_due_.assign(nfp, 0.0); // (the padding is looked at once, and never fails)
  sf_due_rel_.assign(nfp, 0.0);
  sf_budget_.assign(nfp, std::numeric_limits<double>::infinity());
  fail_.reserve(nfp);
  for (std::size_t f = 0; f < nf; ++f) sf_budget_[f] = h - build_deviation(f);
  set_bound_references();
  const std::size_t nn = my_nodes_.size();
  node_due_.assign(static_cast<std::size_t>(simd::padded_size(static_cast<int>(nn))),
                   std::numeric_limits<double>::infinity());
  for (std::size_t k = 0; k < nn; ++k) node_due_[k] = drift_ + 0.999999 * (h - node_deviation(k));
  lazy_ = true;
  lazy_builds_ = w.builds;
}

// One rank: owned node k's largest coordinate deviation from its position at the build.
double ContactPhase::node_deviation(std::size_t k) const {
  const auto p = static_cast<std::size_t>(node_point_[k]);
  const double* r = &search_.node_ref[3 * k];
  return std::max(
      {std::abs(xs_[0][p] - r[0]), std::abs(xs_[1][p] - r[1]), std::abs(xs_[2][p] - r[2])});
}

// One rank: the largest deviation of face f's exact box (cap_) from its box at the build.
double ContactPhase::build_deviation(std::size_t f) const {
  const std::size_t nf = my_face_gid_.size();
  const double* r = search_.box_ref.data();
  double e = 0;
  for (int i = 0; i < 3; ++i) {
    e = std::max(e, std::abs(cap_.lo[i][f] - r[static_cast<std::size_t>(i) * nf + f]));
    e = std::max(e, std::abs(cap_.hi[i][f] - r[static_cast<std::size_t>(3 + i) * nf + f]));
  }
  return e;
}

// Several ranks. A lazy cycle keeps the last full cycle's destinations, plans and received
// layout; its pairs are the exact search's when (1) every receiver's candidate lists are
// still valid, and (2) every face whose capture box holds a node is held where the node is.
// (1): each receiver tells each item's sender how far it may still move (its lists' 0.45
// skin less its deviation from the build, as set_lazy_reference() does on one rank). (2):
// at the cycle its destinations were computed, node n was in the box of its rank r, and
// face f went to every rank that its capture box B0, enlarged by g, touches (so B0 is at
// least g from the box of every other rank, in the largest coordinate). Kept: every node
// within 0.45 g of its rank's box, and every face's box B more than 0.45 g from the box
// of every rank it did not go to. Then a box B that holds n is within 0.45 g of r's box,
// and f is on r. A node's ghosting budget is therefore 0.45 g plus how deep inside r's
// box its reference position is (negative outside; ghost_budget()); a face's, how far its
// box may move before it comes within 0.5 g of another rank's box: at least 0.45 g less
// its moves since B0 (B0 is g from them), and, where it went to one rank only, its box's
// depth inside that rank's box less 0.5 g (every other box is outside that one); where it
// went to every rank, unlimited. The budget of each item is the smaller of the two. Each
// cycle checks the nodes against their budgets (each when drift_ says it could fail) and
// bounds every face's box (shared_bound_holds); a face whose bound fails is checked
// exactly, and if within its budget gets a new reference (rebase_faces). Any failure
// makes the next cycle full on every rank (detect()).
void ContactPhase::set_shared_reference(const FaceBoxes& boxes, bool recomputed) {
  const std::size_t nf = my_face_gid_.size(), nn = my_nodes_.size();
  const std::size_t nfp = static_cast<std::size_t>(simd::padded_size(static_cast<int>(nf)));
  const SearchWorkspace& w = search_;
  const std::vector<ContactNodeItem>& held = *search_nodes_;
  const double inf = std::numeric_limits<double>::infinity();
  const double h = 0.45 * w.skin, gh = 0.45 * ghost_margin_;
  // The ghosting: full budgets where the destinations were just computed, else what is
  // left of them (the references are those of the last full cycle or rebase); the faces'
  // budgets from their depth inside their rank's box are added in set_face_reference().
  // A node's from its position in its rank's box, now.
  sn_ghost_.resize(nn);
  for (std::size_t k = 0; k < nn; ++k) {
    const auto p = static_cast<std::size_t>(node_point_[k]);
    sn_ghost_[k] = gh + depth_in_box(xs_[0][p], xs_[1][p], xs_[2][p], xs_[0][p], xs_[1][p],
                                     xs_[2][p], node_dest_[k]);
  }
  if (recomputed) {
    sf_ghost_.assign(nfp, gh);
    // Per face: its one rank, -2 where it went to every rank, else -1.
    sf_dest_.assign(nf, -1);
    for (std::size_t c0 = 0; c0 < face_src_.size();) {
      std::size_t c1 = c0 + 1;
      while (c1 < face_src_.size() && face_src_[c1] == face_src_[c0]) ++c1;
      const auto f = static_cast<std::size_t>(face_src_[c0]);
      if (c1 - c0 == 1)
        sf_dest_[f] = face_dest_[c0];
      else if (c1 - c0 == static_cast<std::size_t>(comm_.size()))
        sf_dest_[f] = -2;
      c0 = c1;
    }
  } else {
    for (std::size_t f = 0; f < nf; ++f) {
      double e = 0;
      for (int s = 0; s < 6; ++s)
        e = std::max(e, std::abs((s < 3 ? cap_.lo[s][f] : cap_.hi[s - 3][f]) - sf_box_[s][f]));
      sf_ghost_[f] -= e;
    }
  }
  // Without lists (no node or no face held here) nothing held here can pair while the
  // destinations are kept.
  const bool built = w.built;

  // Nodes: the receiver's budgets and flags (the active nodes), back to the senders.
  fb_recv_.resize(held.size());
  for (std::size_t j = 0; j < held.size(); ++j) {
    double e = 0;
    if (built)
      for (int i = 0; i < 3; ++i) e = std::max(e, std::abs(held[j].x[i] - w.node_ref[3 * j + i]));
    fb_recv_[j] = {built ? h - e : inf, 0};
  }
  for (int n : w.active) fb_recv_[static_cast<std::size_t>(n)].keep = 1;
  node_plan_.reverse(fb_recv_, fb_send_);
  keep_recv_.resize(fb_recv_.size());
  for (std::size_t j = 0; j < fb_recv_.size(); ++j)
    keep_recv_[j] = static_cast<char>(fb_recv_[j].keep);
  keep_send_.resize(fb_send_.size());
  for (std::size_t k = 0; k < fb_send_.size(); ++k)
    keep_send_[k] = static_cast<char>(fb_send_[k].keep);
  node_sub_.build_subset(node_plan_, keep_send_, keep_recv_);
  sn_budget_.resize(nn);
  sn_due_.assign(static_cast<std::size_t>(simd::padded_size(static_cast<int>(nn))), inf);
  for (int i = 0; i < 3; ++i) sn_x_[i].resize(nn);
  for (std::size_t k = 0; k < nn; ++k) {
    const auto p = static_cast<std::size_t>(node_point_[k]);
    for (int i = 0; i < 3; ++i) sn_x_[i][k] = xs_[i][p];
    sn_budget_[k] = std::min(fb_send_[k].budget, sn_ghost_[k]);
    sn_due_[k] = drift_ + 0.999999 * sn_budget_[k];
  }

  // Faces: the same per copy (the faces in some list), each face's budget the least of
  // its copies'.
  const std::size_t nr = face_plan_.recv_count();
  fb_recv_.resize(nr);
  for (std::size_t j = 0; j < nr; ++j) {
    double e = 0;
    if (built)
      for (int s = 0; s < 6; ++s) {
        const double b = s < 3 ? boxes.lo[s][j] : boxes.hi[s - 3][j];
        e = std::max(e, std::abs(b - w.box_ref[static_cast<std::size_t>(s) * nr + j]));
      }
    fb_recv_[j] = {built ? h - e : inf, 0};
  }
  for (int f : w.needed) fb_recv_[static_cast<std::size_t>(f)].keep = 1;
  face_plan_.reverse(fb_recv_, fb_send_);
  keep_recv_.resize(nr);
  for (std::size_t j = 0; j < nr; ++j) keep_recv_[j] = static_cast<char>(fb_recv_[j].keep);
  keep_send_.resize(fb_send_.size());
  sf_list_.assign(nfp, inf); // dead faces and the padding never fail
  sf_budget_.assign(nfp, inf);
  sub_faces_.clear();
  for (std::size_t c = 0; c < fb_send_.size(); ++c) { // copies in ascending face order
    const int f = face_src_[c];
    keep_send_[c] = static_cast<char>(fb_send_[c].keep);
    auto& budget = sf_list_[static_cast<std::size_t>(f)];
    budget = std::min(budget, fb_send_[c].budget);
    if (keep_send_[c] != 0 && (sub_faces_.empty() || sub_faces_.back() != f))
      sub_faces_.push_back(f);
  }
  face_sub_.build_subset(face_plan_, keep_send_, keep_recv_);
  // What lazy cycles may need, at most, so that they allocate nothing.
  node_sub_.reserve(node_plan_.send_count() * sizeof(ContactNodeItem));
  face_sub_.reserve(face_plan_.send_count() * sizeof(FaceMotion));
  node_sub_in_.reserve(node_plan_.recv_count());
  face_sub_in_.reserve(face_plan_.recv_count());
  motion_.resize(face_plan_.recv_count());
  unpacked_.assign(face_plan_.recv_count(), -1);
  fail_.reserve(nfp);
  near_.reserve(nf);

  sf_ref_.resize(nfp);
  for (auto& v : sf_box_) v.resize(nf);
  sf_due_.resize(nfp);
  sf_due_rel_.resize(nfp);
  sf_near_.assign(nf, 0);
  near_.clear();
  for (std::size_t f = 0; f < nfp; ++f) set_face_budget(f);
  set_bound_references();
  version_ref_ = surface_version_;
  shared_ = true; // (never with extra nodes anywhere: they change every cycle)
}

void ContactPhase::FaceRefs::resize(std::size_t n) {
  for (int k = 0; k < 4; ++k) {
    corner[k].resize(n);
    for (auto& c : x[k]) c.resize(n);
  }
  a.resize(n);
  b.resize(n);
  largest.resize(n);
}

template <class V>
void ContactPhase::set_bound_reference(std::size_t f) {
  using std::sqrt;
  constexpr std::size_t n = std::is_same_v<V, double> ? 1 : simd::width;
  FaceRefs& r = sf_ref_;
  for (std::size_t g = f; g < f + n; ++g)
    for (int k = 0; k < 4; ++k) {
      r.corner[k][g] = corner_[k][g];
      for (int i = 0; i < 3; ++i) r.x[k][i][g] = xs_[i][static_cast<std::size_t>(corner_[k][g])];
    }
  if constexpr (std::is_same_v<V, double>)
    if (f >= my_face_gid_.size()) { // padding
      r.a[f] = r.b[f] = r.largest[f] = 0;
      return;
    }
  const V a = bound_a(lanes(my_face_depth_, f, V()), lanes(cap_.len, f, V()));
  const V b = 2.0 * lanes(cap_.diag, f, V());
  // The largest delta for which the first bound holds: the root of 1.001 m(delta) = budget.
  const V beta = lanes(sf_budget_, f, V()) / 1.001, p = 1.0 + a * b;
  const V largest = simd::select(beta < std::numeric_limits<double>::infinity(),
                                 2.0 * beta / (p + sqrt(p * p + 16.0 * a * beta)), beta);
  put(a, r.a, f);
  put(b, r.b, f);
  put(largest, r.largest, f);
  V due, due_rel;
  due_drifts<V>(f, {0.0, 0.0, 0.0}, due, due_rel); // no motion at the reference
  put(due, sf_due_, f);
  put(due_rel, sf_due_rel_, f);
}

void ContactPhase::set_bound_references() {
  const std::size_t nf = my_face_gid_.size(), nfp = sf_budget_.size();
  std::size_t f = 0;
  for (; f + simd::width <= nf; f += simd::width) set_bound_reference<simd::vdouble>(f);
  for (; f < nfp; ++f) set_bound_reference<double>(f);
}

void ContactPhase::set_face_reference(std::size_t f) {
  set_face_budget(f);
  set_bound_reference<double>(f);
}

void ContactPhase::set_face_budget(std::size_t f) {
  if (f >= my_face_gid_.size() || !active(f)) { // (sf_budget_[f] is infinite)
    if (f < my_face_gid_.size())
      for (int i = 0; i < 3; ++i) {
        sf_box_[i][f] = cap_.lo[i][f];
        sf_box_[3 + i][f] = cap_.hi[i][f];
      }
    return;
  }
  for (int i = 0; i < 3; ++i) {
    sf_box_[i][f] = cap_.lo[i][f];
    sf_box_[3 + i][f] = cap_.hi[i][f];
  }
  // The ghosting budget from the box's depth inside its one rank's box (set_shared_reference()).
  const int d = sf_dest_[f];
  if (d == -2) {
    sf_ghost_[f] = std::numeric_limits<double>::infinity();
  } else if (d >= 0) {
    const double depth = depth_in_box(cap_.lo[0][f], cap_.lo[1][f], cap_.lo[2][f], cap_.hi[0][f],
                                      cap_.hi[1][f], cap_.hi[2][f], d);
    sf_ghost_[f] = std::max(sf_ghost_[f], depth - 0.5 * ghost_margin_);
  }
  double budget = std::min(sf_list_[f], sf_ghost_[f]);
  // The centre moves no more than the bound allows the box sides (face_motion()): a face
  // whose centre is 0.5 g or more inside its rank's box keeps its rank while its budget is
  // within 0.9 of that depth; only the others (near_) can change rank.
  const double c[3] = {cap_.centre[0][f], cap_.centre[1][f], cap_.centre[2][f]};
  update_face_rank(f, c);
  const double depth = depth_in_box(c[0], c[1], c[2], c[0], c[1], c[2], my_face_rank_[f]);
  const Box3& b = rank_box_[static_cast<std::size_t>(my_face_rank_[f])];
  bool far = true;
  for (int i = 0; i < 3; ++i)
    far &= c[i] - b.lo[i] > 0.5 * ghost_margin_ && b.hi[i] - c[i] > 0.5 * ghost_margin_;
  if (!far && sf_near_[f] == 0) {
    sf_near_[f] = 1;
    near_.push_back(static_cast<int>(f));
  }
  if (sf_near_[f] == 0) budget = std::min(budget, 0.9 * depth);
  sf_budget_[f] = budget;
}

// How deep the box [lo, hi] (a point where lo = hi) lies inside rank r's box: the least
// distance of a side from the rank box's side beyond it, negative where it sticks out.
double ContactPhase::depth_in_box(double lo0, double lo1, double lo2, double hi0, double hi1,
                                  double hi2, int r) const {
  const Box3& b = rank_box_[static_cast<std::size_t>(r)];
  return std::min(
      {lo0 - b.lo[0], lo1 - b.lo[1], lo2 - b.lo[2], b.hi[0] - hi0, b.hi[1] - hi1, b.hi[2] - hi2});
}

// Face f's motion since its reference: delta, the largest distance of a corner from where
// it was then; the mean move T of its corners (t: its largest coordinate), and the largest
// distance r of a corner from where T alone would have taken it. The box of the face moved
// by T is its box moved by T (the plane, size and warp are those of the reference), so its
// sides have moved at most t + m(r), and at most m(delta) (m: side_move(), with A and B of
// the reference geometry). A NaN gives a NaN.
template <class V>
ContactPhase::FaceMotionBound<V> ContactPhase::face_motion(std::size_t f) const {
  using std::abs;
  using std::sqrt;
  const FaceRefs& ref = sf_ref_;
  V u[4][3], T[3] = {0.0, 0.0, 0.0};
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) {
      u[a][i] = at(xs_[i], ref.corner[a], f, V()) - lanes(ref.x[a][i], f, V());
      T[i] += 0.25 * u[a][i];
    }
  V t = 0.0, r2 = 0.0, d2 = 0.0;
  for (int i = 0; i < 3; ++i) {
    const V Ti = abs(T[i]);
    t = simd::select(!(t >= Ti), Ti, t);
  }
  for (int a = 0; a < 4; ++a) {
    V q = 0.0, e = 0.0;
    for (int i = 0; i < 3; ++i) {
      const V d = u[a][i] - T[i];
      q += d * d;
      e += u[a][i] * u[a][i];
    }
    r2 = simd::select(!(r2 >= q), q, r2);
    d2 = simd::select(!(d2 >= e), e, d2);
  }
  return {sqrt(d2), t, sqrt(r2)};
}

// Whether face f's sides are within its budget by either bound, with 0.1% for rounding.
template <class V>
auto ContactPhase::within_budget(std::size_t f, const FaceMotionBound<V>& m) const {
  const V a = lanes(sf_ref_.a, f, V()), b = lanes(sf_ref_.b, f, V());
  const V first = side_move(m.delta, a, b), second = m.t + side_move(m.r, a, b);
  return 1.001 * simd::select(second < first, second, first) <= lanes(sf_budget_, f, V());
}

// How much further drift_ may grow before both of face f's bounds could fail, from its
// motion now: in that time no corner moves more than s, so delta grows at most s, T moves
// at most s and r grows at most 1.5 s (a corner's offset from T, u_a - T = 3/4 u_a - 1/4
// of the other three corners' moves, changes by at most 3/4 s + 3/4 s). The larger of
// the largest s with 1.001 m(delta + s) <= budget and of the largest s with
// 1.001 (t + s + m(r + 1.5 s)) <= budget (with D = r + 1.5 s the root of
// 4 A D^2 + (5/3 + A B) D = budget / 1.001 - t + 2/3 r); infinite for an infinite budget.
template <class V>
V ContactPhase::drift_allowed(std::size_t f, const FaceMotionBound<V>& m) const {
  using std::sqrt;
  const V a = lanes(sf_ref_.a, f, V()), b = lanes(sf_ref_.b, f, V());
  const V beta = lanes(sf_budget_, f, V()) / 1.001;
  const V s1 = lanes(sf_ref_.largest, f, V()) - m.delta;
  const V c = beta - m.t + (2.0 / 3.0) * m.r;
  const V p2 = 5.0 / 3.0 + a * b;
  const V s2 = (2.0 / 3.0) * (2.0 * c / (p2 + sqrt(p2 * p2 + 16.0 * a * c)) - m.r);
  return simd::select(beta < std::numeric_limits<double>::infinity(), simd::select(s1 < s2, s2, s1),
                      beta);
}

// Face f's due drifts from its motion m now: its bound cannot fail while drift_ grows by at
// most Ad and rel_drift_ by at most Br. Either drift_allowed() with rel_drift_ free (the
// offsets' growth bounded by 1.5 times drift_'s), or, from the second bound's slack S now
// (budget / 1.001 - t - m(r)), half of it to the translation (Ad = S / 2: t grows at most
// by drift_'s growth) and half to the offsets (r grows at most 1.5 times rel_drift_'s:
// Br = (D - r) / 1.5 with m(D) = m(r) + S / 2, D the root of 4 A D^2 + (1 + A B) D =
// m(r) + S / 2). Which of the two: the second where it lasts a quarter longer if
// rel_drift_ keeps growing at its recent rate against drift_'s (only when the face is
// looked at depends on the choice, not what the look finds).
template <class V>
void ContactPhase::due_drifts(std::size_t f, const FaceMotionBound<V>& m, V& due,
                              V& due_rel) const {
  using std::sqrt;
  const double inf = std::numeric_limits<double>::infinity();
  const V one = drift_allowed(f, m);
  due = drift_ + 0.999999 * one;
  due_rel = inf;
  if (!(drift_ > 0)) return;
  const V a = lanes(sf_ref_.a, f, V()), b = lanes(sf_ref_.b, f, V());
  const V beta = lanes(sf_budget_, f, V()) / 1.001;
  const V mr = side_move(m.r, a, b);
  const V half = 0.5 * (beta - m.t - mr);
  const V q = 1.0 + a * b, c = mr + half;
  const V br = (2.0 * c / (q + sqrt(q * q + 16.0 * a * c)) - m.r) / 1.5;
  const double rate = rel_rate_ / drift_rate_; // rel_drift_'s recent growth per drift_'s
  const V lasts = rate > 0 ? V(br / rate) : V(inf);
  const auto second = (beta < inf) && (half > one) &&
                      (simd::select(lasts < half, lasts, half) > 1.25 * one); // (not a NaN)
  due = simd::select(second, drift_ + 0.999999 * half, due);
  due_rel = simd::select(second, rel_drift_ + 0.999999 * br, due_rel);
}

// The nodes against their budgets, each when its move could have reached it (sn_due_: a
// node moves no more than the growth of drift_), and the faces by their bounds
// (find_failing_faces()).
bool ContactPhase::shared_bound_holds() {
  unsigned bad = 0; // also when anything is not a number
  const std::size_t nn = sn_due_.size();
  for (std::size_t k0 = 0; k0 < nn; k0 += simd::width) {
    if (all_of(simd::load(sn_due_.data() + k0) >= drift_)) continue; // (a NaN is looked at)
    for (std::size_t k = k0; k < k0 + simd::width; ++k) {
      if (sn_due_[k] >= drift_) continue; // (the padding never is)
      const auto p = static_cast<std::size_t>(node_point_[k]);
      const double e =
          std::max({std::abs(xs_[0][p] - sn_x_[0][k]), std::abs(xs_[1][p] - sn_x_[1][k]),
                    std::abs(xs_[2][p] - sn_x_[2][k])});
      bad |= static_cast<unsigned>(!(e <= sn_budget_[k]));
      sn_due_[k] = drift_ + 0.999999 * (sn_budget_[k] - e);
    }
  }
  find_failing_faces();
  return bad == 0;
}

void ContactPhase::find_failing_faces() {
  fail_.clear();
  // No corner moves more than the growth of drift_ in the meantime, and no corner's offset
  // from the mean move more than 1.5 times the growth of rel_drift_: a face is looked at
  // again only when its bound could fail (sf_due_, sf_due_rel_, due_drifts()), and the
  // others pass. A vector of faces is looked at together, when one of them is due, and
  // every face of it whose bound holds gets its due drifts from its motion now (as safe
  // as the old ones, and later: 40% fewer looks on the can crush); only a due face can
  // fail, and a face fails at the first cycle its bound fails whichever faces are looked
  // at, so the full cycles do not depend on the looks.
  using V = simd::vdouble;
  const std::size_t nfp = sf_budget_.size();
  for (std::size_t f = 0; f < nfp; f += simd::width) {
    const V due = simd::load(sf_due_.data() + f), due_rel = simd::load(sf_due_rel_.data() + f);
    const simd::vmask look = !((due >= drift_) & (due_rel >= rel_drift_)); // (and a NaN)
    if (none_of(look)) continue;
    const FaceMotionBound<V> m = face_motion<V>(f);
    const simd::vmask holds = within_budget(f, m);
    V next, next_rel;
    due_drifts(f, m, next, next_rel);
    simd::store(simd::select(holds, next, due), sf_due_.data() + f);
    simd::store(simd::select(holds, next_rel, due_rel), sf_due_rel_.data() + f);
    const simd::vmask fails = look && !holds;
    if (any_of(fails))
      for (int l = 0; l < simd::width; ++l)
        if (fails[l]) fail_.push_back(static_cast<int>(f) + l);
  }
}

bool ContactPhase::rebase_faces() {
  compute_captures(corners(), fail_, cap_);
  unsigned bad = 0; // also when anything is not a number
  // Against the lists' and the ghosting's budgets (sf_budget_ may be less: the limit that
  // keeps the face's rank, which its new reference looks at again).
  for (int f : fail_) {
    const double budget = std::min(sf_list_[f], sf_ghost_[f]);
    for (int s = 0; s < 6; ++s) {
      const double b = s < 3 ? cap_.lo[s][f] : cap_.hi[s - 3][f];
      bad |= static_cast<unsigned>(!(std::abs(b - sf_box_[s][f]) <= budget));
    }
  }
  if (bad != 0) return false;
  for (int fi : fail_) {
    const auto f = static_cast<std::size_t>(fi);
    double e = 0;
    for (int s = 0; s < 6; ++s)
      e = std::max(e, std::abs((s < 3 ? cap_.lo[s][f] : cap_.hi[s - 3][f]) - sf_box_[s][f]));
    sf_list_[f] -= e;
    sf_ghost_[f] -= e;
    set_face_reference(f);
  }
  return true;
}

bool ContactPhase::compute_destinations(std::size_t live) {
  const std::size_t nf = my_face_gid_.size();
  node_dest_.resize(node_out_.size());
  for (std::size_t k = 0; k < node_out_.size(); ++k) {
    // Last cycle's rank when the point is still in its half-open box (exactly
    // Rcb::owner's answer there), else the tree.
    const Vec3 x{node_out_[k].x[0], node_out_[k].x[1], node_out_[k].x[2]};
    const Box3& b = rank_box_[static_cast<std::size_t>(node_dest_[k])];
    if (!(x.x >= b.lo.x && x.x < b.hi.x && x.y >= b.lo.y && x.y < b.hi.y && x.z >= b.lo.z &&
          x.z < b.hi.z))
      node_dest_[k] = rcb_.owner(x);
  }
  // Faces go to every rank their capture box, enlarged by the ghosting margin, touches
  // (ghosts), as copies.
  const double g = ghost_margin_;
  face_dest_.clear();
  face_src_.clear();
  one_copy_each_ = live == nf; // then copy k is face k
  for (std::size_t f = 0; f < nf; ++f) {
    if (!active(f)) continue;
    const Box3 q{{cap_.lo[0][f] - g, cap_.lo[1][f] - g, cap_.lo[2][f] - g},
                 {cap_.hi[0][f] + g, cap_.hi[1][f] + g, cap_.hi[2][f] + g}};
    // A box strictly inside the box of the face's last rank overlaps that rank only, and
    // a centre in its half-open box is that rank's: Rcb::overlapping's and Rcb::owner's
    // answers, without the tree.
    {
      const Box3& b = rank_box_[static_cast<std::size_t>(my_face_rank_[f])];
      bool inside = true;
      for (int i = 0; i < 3; ++i)
        inside &= q.lo[i] > b.lo[i] && q.hi[i] < b.hi[i] && cap_.centre[i][f] >= b.lo[i] &&
                  cap_.centre[i][f] < b.hi[i];
      if (inside) {
        face_src_.push_back(static_cast<int>(f));
        face_dest_.push_back(my_face_rank_[f]);
        continue;
      }
    }
    my_face_rank_[f] = rcb_.owner({cap_.centre[0][f], cap_.centre[1][f], cap_.centre[2][f]});
    rcb_.overlapping(q, ranks_);
    one_copy_each_ &= ranks_.size() == 1;
    for (int r : ranks_) {
      face_src_.push_back(static_cast<int>(f));
      face_dest_.push_back(r);
    }
  }
  return !plans_built_ || node_dest_ != node_dest_built_ || face_dest_ != face_dest_built_ ||
         face_src_ != face_src_built_;
}

void ContactPhase::update_face_rank(std::size_t f, const double (&c)[3]) {
  int& r = my_face_rank_[f];
  const Box3& b = rank_box_[static_cast<std::size_t>(r)];
  bool in = true;
  for (int i = 0; i < 3; ++i) in &= c[i] >= b.lo[i] && c[i] < b.hi[i];
  if (!in) r = rcb_.owner({c[0], c[1], c[2]});
}

bool ContactPhase::lazy_bound_holds() {
  const SearchWorkspace& w = search_;
  const double h = 0.45 * w.skin;
  unsigned bad = 0; // also when anything is not a number
  // The nodes exactly, as lists_valid() tests them, each when its deviation could have
  // reached h (node_due_: a node moves no more than the growth of drift_).
  const std::size_t nn = node_due_.size();
  for (std::size_t k0 = 0; k0 < nn; k0 += simd::width) {
    if (all_of(simd::load(node_due_.data() + k0) >= drift_)) continue; // (a NaN is looked at)
    for (std::size_t k = k0; k < k0 + simd::width; ++k) {
      if (node_due_[k] >= drift_) continue; // (the padding never is)
      const double e = node_deviation(k);
      bad |= static_cast<unsigned>(!(e <= h));
      node_due_[k] = drift_ + 0.999999 * (h - e);
    }
  }
  if (bad != 0) return false;
  // The faces by their bounds; those whose bound fails get their exact box, tested as
  // lists_valid() would, and this cycle as their reference.
  find_failing_faces();
  if (fail_.empty()) return true;
  compute_captures(corners(), fail_, cap_);
  for (int f : fail_)
    bad |= static_cast<unsigned>(!(build_deviation(static_cast<std::size_t>(f)) <= h));
  if (bad != 0) return false;
  for (int fi : fail_) {
    const auto f = static_cast<std::size_t>(fi);
    sf_budget_[f] = h - build_deviation(f);
    set_bound_reference<double>(f);
  }
  return true;
}

void ContactPhase::detect(const ContactNodes& nd, double dt, PhaseTimers& timers) {
  ++stats_.cycles;

  // The predicted positions x* = x + dt v of the surface points, then the planes and
  // capture boxes of the faces of owned elements (vectorised across faces), and the items
  // of the owned contact nodes (their constant fields were set at construction). Face
  // items are packed below, all of them only where they leave this rank.
  const std::size_t nf = my_face_gid_.size();
  // On one rank every item stays: no RCB look-ups.
  const bool alone = comm_.size() == 1;
  std::size_t live = 0;    // faces alive
  bool lazy_cycle = false; // one rank: the bound holds
  bool bound_ok = false;   // several ranks: this rank's items are within their budgets
  {
    ScopedPhase t(timers, Phase::transfer);
    // The points' predicted positions, and the largest move of a point since last cycle,
    // summed into drift_ (several ranks: shared_bound_holds()). (A NaN is not carried: the
    // element phase stops the run on non-finite values.)
    // Also the largest move of a point less the mean move of last cycle (w0, w1, w2; any
    // common vector W serves, see find_failing_faces()), summed into rel_drift_.
    const std::size_t np = surf_local_.size();
    double step2 = 0, rel2 = 0, s0 = 0, s1 = 0, s2 = 0;
    const double w0 = w_step_[0], w1 = w_step_[1], w2 = w_step_[2];
    if (np == fe_.node_gid.size()) { // every local node is a surface point (point k: node k)
      const double *x0 = nd.x[0], *x1 = nd.x[1], *x2 = nd.x[2];
      const double *v0 = nd.v[0], *v1 = nd.v[1], *v2 = nd.v[2];
      double *y0 = xs_[0].data(), *y1 = xs_[1].data(), *y2 = xs_[2].data();
#pragma omp simd reduction(max : step2, rel2) reduction(+ : s0, s1, s2)
      for (std::size_t k = 0; k < np; ++k) {
        const double a0 = x0[k] + dt * v0[k], a1 = x1[k] + dt * v1[k], a2 = x2[k] + dt * v2[k];
        const double d0 = a0 - y0[k], d1 = a1 - y1[k], d2 = a2 - y2[k];
        step2 = std::max(step2, d0 * d0 + d1 * d1 + d2 * d2);
        const double e0 = d0 - w0, e1 = d1 - w1, e2 = d2 - w2;
        rel2 = std::max(rel2, e0 * e0 + e1 * e1 + e2 * e2);
        s0 += d0;
        s1 += d1;
        s2 += d2;
        y0[k] = a0;
        y1[k] = a1;
        y2[k] = a2;
      }
    } else {
      for (std::size_t k = 0; k < np; ++k) {
        const auto l = static_cast<std::size_t>(surf_local_[k]);
        double d[3];
        for (int i = 0; i < 3; ++i) {
          const double y = nd.x[i][l] + dt * nd.v[i][l];
          d[i] = y - xs_[i][k];
          xs_[i][k] = y;
        }
        const double e0 = d[0] - w0, e1 = d[1] - w1, e2 = d[2] - w2;
        step2 = std::max(step2, d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        rel2 = std::max(rel2, e0 * e0 + e1 * e1 + e2 * e2);
        s0 += d[0];
        s1 += d[1];
        s2 += d[2];
      }
    }
    drift_ += std::sqrt(step2);
    rel_drift_ += std::sqrt(std::min(step2, rel2));
    // Their recent growths (over some 64 cycles), for set_due()'s choice.
    drift_rate_ += (std::sqrt(step2) - drift_rate_) / 64;
    rel_rate_ += (std::sqrt(std::min(step2, rel2)) - rel_rate_) / 64;
    if (np > 0) {
      w_step_[0] = s0 / static_cast<double>(np);
      w_step_[1] = s1 / static_cast<double>(np);
      w_step_[2] = s2 / static_cast<double>(np);
    }
    live = live_; // (set_eroded() counts them)
    // Faces erosion exposed are marked for the cycle of their exposure only; clearing the
    // marks changes the surface as exposing them did (a full cycle sends every item).
    if (exposed_age_ == 1) {
      exposed_age_ = 2;
    } else if (exposed_age_ == 2) {
      std::fill(face_exposed_.begin(), face_exposed_.end(), 0);
      exposed_age_ = 0;
      ++surface_version_;
    }
    // While the bound shows the candidate lists valid (and, on several ranks, the
    // ghosting), only the faces some list reads need their box (below); otherwise every
    // face gets it.
    if (alone)
      lazy_cycle = live == nf && extra_.empty() && lazy_ && search_.built &&
                   search_.builds == lazy_builds_ && lazy_bound_holds();
    else if (shared_ && !rebalance_due_ && extra_.empty() && surface_version_ == version_ref_) {
      // Faces whose bound fails may still be within their budgets (exact boxes).
      bound_ok = shared_bound_holds();
      if (bound_ok && !fail_.empty()) bound_ok = rebase_faces();
    }
    if (!lazy_cycle && !bound_ok) compute_live_captures();
    if (lazy_cycle) {
      // One rank, the lists valid: the search reads the nodes with candidates only (in
      // place: the item of node k is node_out_[k]).
      for (int k : search_.active) pack_node(static_cast<std::size_t>(k), nd, node_out_[k]);
    } else if (!bound_ok) {
      node_out_.resize(my_nodes_.size());
      for (std::size_t k = 0; k < my_nodes_.size(); ++k) pack_node(k, nd, node_out_[k]);
      node_out_.insert(node_out_.end(), extra_.begin(), extra_.end());
    }
  }

  // Rebalance: RCB of node positions and face centroids, unit weights.
  if (rebalance_due_) {
    ScopedPhase t(timers, Phase::rebalance);
    const std::size_t np = node_out_.size() + nf;
    px_.resize(np);
    py_.resize(np);
    pz_.resize(np);
    pid_.resize(np);
    for (std::size_t k = 0; k < node_out_.size(); ++k) {
      px_[k] = node_out_[k].x[0];
      py_[k] = node_out_[k].x[1];
      pz_[k] = node_out_[k].x[2];
      pid_[k] = node_out_[k].gid;
    }
    for (std::size_t f = 0; f < nf; ++f) {
      double c[3] = {0, 0, 0};
      for (int a = 0; a < 4; ++a)
        for (int i = 0; i < 3; ++i) c[i] += 0.25 * xs_[i][static_cast<std::size_t>(corner_[a][f])];
      const std::size_t k = node_out_.size() + f;
      px_[k] = c[0];
      py_[k] = c[1];
      pz_[k] = c[2];
      pid_[k] = global_nodes_ + my_face_gid_[f];
    }
    const RcbPoints pts{px_, py_, pz_, pid_, {}};
    if (partitioned_)
      rcb_.repartition(pts);
    else
      rcb_.partition(pts);
    partitioned_ = true;
    rebalance_due_ = false;
    just_rebalanced_ = true;
    rank_box_.resize(static_cast<std::size_t>(comm_.size()));
    for (int r = 0; r < comm_.size(); ++r) rank_box_[static_cast<std::size_t>(r)] = rcb_.box(r);
    ++stats_.rebalances;
  }

  bool lazy = false;            // several ranks: every rank's bound holds
  bool motions_only = false;    // several ranks, full cycle, plans kept: faces sent as motions
  bool extra_somewhere = false; // some rank has extra nodes this cycle
  {
    ScopedPhase t(timers, Phase::transfer);
    bool changed = false;
    if (alone) {
      // Rank 0 holds each live face once: the lists change only when an element erodes.
      node_dest_.assign(node_out_.size(), 0);
      one_copy_each_ = live == nf;
      if (!one_copy_each_ || face_src_.size() != nf) { // else they are 0..nf-1, all to 0
        face_dest_.assign(live, 0);
        face_src_.clear();
        for (std::size_t f = 0; f < nf; ++f)
          if (active(f)) face_src_.push_back(static_cast<int>(f));
      }
      changed = !plans_built_ || node_dest_ != node_dest_built_ || face_dest_ != face_dest_built_ ||
                face_src_ != face_src_built_;
    } else if (!bound_ok) {
      changed = compute_destinations(live);
    } else {
      // The destinations stay; the centres near a rank's box side may have left it.
      for (int f : near_) {
        double c[3];
        for (int i = 0; i < 3; ++i)
          c[i] = 0.25 * (xs_[i][static_cast<std::size_t>(corner_[0][f])] +
                         xs_[i][static_cast<std::size_t>(corner_[1][f])] +
                         xs_[i][static_cast<std::size_t>(corner_[2][f])] +
                         xs_[i][static_cast<std::size_t>(corner_[3][f])]);
        update_face_rank(static_cast<std::size_t>(f), c);
      }
    }
    // One reduction: 2 when some rank's destinations have changed (the plans are rebuilt,
    // instead of two all-to-alls of counts), 1 when some rank's bound fails (a full
    // cycle), 0 when every rank's bound holds (a lazy cycle); whether some rank has
    // extra nodes (then the next cycle cannot be lazy either: no reference is set); and
    // whether some rank that exchanges faces cannot send them as motions (below): the
    // senders and receivers of the face plan must agree on what travels, FaceMotion or
    // ContactFaceItem (QA round 7: on 5 to 8 ranks with particles, a rank that had never
    // received whole items took motions from one that sent items, and read garbage).
    const bool keeps_items =
        node_plan_.stays() && face_plan_.stays() && one_copy_each_; // (in place: no peers)
    const bool can_send_motions =
        keeps_items ||
        (face_in_full_ && motion_.size() == face_in_.size() && unpacked_.size() == face_in_.size());
    std::int64_t red[3] = {changed ? 2 : (alone || bound_ok ? 0 : 1),
                           static_cast<std::int64_t>(!extra_.empty()),
                           static_cast<std::int64_t>(!can_send_motions)};
    comm_.max(std::span<std::int64_t>(red, 3));
    const std::int64_t worst = red[0];
    lazy = !alone && worst == 0;
    extra_somewhere = red[1] != 0;
    const bool motions_everywhere = red[2] == 0;
    if (worst == 2) {
      node_plan_.build(comm_, node_dest_);
      face_plan_.build(comm_, face_dest_);
      node_dest_built_ = node_dest_;
      face_dest_built_ = face_dest_;
      face_src_built_ = face_src_;
      plans_built_ = true;
      ++stats_.plan_builds;
    }
    if (lazy) {
      // Only the items some receiver's lists read, and of a face only what changes.
      // Those that stay on this rank are written where the search reads them, not packed
      // and copied (a face's box and plane from cap_; its item, if queued, below).
      compute_captures(corners(), sub_faces_, cap_, true);
      std::vector<ContactNodeItem>& held = node_plan_.stays() ? node_out_ : node_in_;
      node_sub_.forward_packed(
          node_sub_in_, [&](std::size_t k, ContactNodeItem& it) { pack_node(k, nd, it); },
          [&](std::size_t k, std::size_t j) {
            pack_node(k, nd, held[node_sub_.base_position(j)]);
          });
      const int me = comm_.rank();
      for (std::size_t j = 0; j < node_sub_in_.size(); ++j)
        if (j - node_sub_.recv_offset(me) >= node_sub_.recv_count(me)) // (from another rank)
          held[node_sub_.base_position(j)] = node_sub_in_[j];
      if (!in_place_) { // (in place: the items the search reads are packed below)
        face_sub_.forward_packed(
            face_sub_in_,
            [&](std::size_t k, FaceMotion& m) {
              pack_cycle(static_cast<std::size_t>(face_src_[k]), nd, m);
            },
            [&](std::size_t k, std::size_t j) {
              const std::size_t b = face_sub_.base_position(j);
              const int f = face_src_[k];
              put_box_and_plane(recv_box_, b, cap_, static_cast<std::size_t>(f));
              motion_[b] = -1 - f; // its item from face f, if queued (complete_item())
            });
        for (std::size_t j = 0; j < face_sub_in_.size(); ++j) {
          if (j - face_sub_.recv_offset(me) < face_sub_.recv_count(me)) continue; // stayed
          const std::size_t b = face_sub_.base_position(j);
          unpack_motion(face_sub_in_[j], b);
          motion_[b] = static_cast<int>(j);
        }
      }
      stats_.bytes_sent +=
          static_cast<double>(node_sub_.sent_elsewhere() * sizeof(ContactNodeItem) +
                              face_sub_.sent_elsewhere() * sizeof(FaceMotion));
    } else {
      if (!alone && bound_ok) {
        // Some other rank's bound failed: this rank keeps its destinations, and its items
        // go in full.
        compute_live_captures();
        node_out_.resize(my_nodes_.size());
        for (std::size_t k = 0; k < my_nodes_.size(); ++k) pack_node(k, nd, node_out_[k]);
      }
      // Where every item stays on this rank, the search reads the local items in place.
      if (node_plan_.stays()) {
        search_nodes_ = &node_out_;
      } else {
        node_plan_.forward(node_out_, node_in_);
        search_nodes_ = &node_in_;
      }
      in_place_ = node_plan_.stays() && face_plan_.stays() && one_copy_each_;
      // With the plans as they were (nobody's destinations changed), the received items'
      // constant fields are in place: every face sends only what changes, and the items
      // that stay give their boxes and planes straight from cap_ (as on a lazy cycle; the
      // items of the queued faces are completed below).
      motions_only = !alone && worst == 1 && !in_place_ && motions_everywhere;
      if (worst == 2) face_in_full_ = false;
      if (in_place_) {
        search_faces_ = &face_local_;
      } else if (motions_only) {
        const int me = comm_.rank();
        face_plan_.forward_packed(
            face_sub_in_,
            [&](std::size_t k, FaceMotion& m) {
              pack_cycle(static_cast<std::size_t>(face_src_[k]), nd, m);
            },
            [&](std::size_t k, std::size_t j) {
              const int f = face_src_[k];
              put_box_and_plane(recv_box_, j, cap_, static_cast<std::size_t>(f));
              motion_[j] = -1 - f;
            });
        for (std::size_t j = 0; j < face_sub_in_.size(); ++j) {
          if (j - face_plan_.recv_offset(me) < face_plan_.recv_count(me)) continue; // stayed
          unpack_motion(face_sub_in_[j], j);
          motion_[j] = static_cast<int>(j);
        }
        search_faces_ = &face_in_;
      } else {
        if (lazy_cycle) compute_captures(corners(), cap_); // (cannot happen: one rank stays)
        // Each copy is packed straight into the send buffer of its rank, or into face_in_
        // where it stays: no face item is copied.
        face_plan_.forward_packed(face_in_, [&](std::size_t k, ContactFaceItem& it) {
          pack_copy(static_cast<std::size_t>(face_src_[k]), nd, it);
        });
        search_faces_ = &face_in_;
        face_in_full_ = true;
      }
      // Only what goes to another rank: items kept here are no traffic.
      stats_.bytes_sent +=
          static_cast<double>(node_plan_.sent_elsewhere() * sizeof(ContactNodeItem) +
                              face_plan_.sent_elsewhere() *
                                  (motions_only ? sizeof(FaceMotion) : sizeof(ContactFaceItem)));
    }
  }

  SearchOptions opt;
  opt.dt = dt;
  FaceBoxes boxes;
  if (in_place_) {
    // The boxes and planes straight from cap_ (of the faces in some candidate list only on
    // a lazy cycle).
    auto part = [nf](const std::vector<double>& v) {
      return std::span<const double>(v.data(), nf);
    };
    for (int i = 0; i < 3; ++i) {
      boxes.lo[i] = part(cap_.lo[i]);
      boxes.hi[i] = part(cap_.hi[i]);
      boxes.normal[i] = part(cap_.normal[i]);
    }
    boxes.offset = part(cap_.offset);
    boxes.warp = part(cap_.warp);
    boxes.depth = part(depth_pad_);
    if (!lazy_cycle && !lazy) {
      ScopedPhase t(timers, Phase::contact_search);
      update_candidate_lists(*search_nodes_, face_local_, boxes, opt, search_);
    }
    if (!lazy) {
      ScopedPhase t(timers, Phase::transfer);
      if (lazy_cycle) compute_captures(corners(), search_.needed, cap_, true);
      if (!lazy_cycle && alone && extra_.empty() && search_.built) set_lazy_reference();
    }
    // The cheap tests read the arrays; only the items of the faces queued for the detailed
    // check (and so of the pairs) get this cycle's corners, velocities and plane.
    {
      ScopedPhase t(timers, Phase::contact_search);
      queue_candidates(*search_nodes_, boxes, search_);
    }
    {
      ScopedPhase t(timers, Phase::transfer);
      for (int f : search_.query_face)
        if (packed_[static_cast<std::size_t>(f)] != stats_.cycles) {
          packed_[static_cast<std::size_t>(f)] = stats_.cycles;
          pack_face(static_cast<std::size_t>(f), nd);
        }
    }
    ScopedPhase t(timers, Phase::contact_search);
    check_queued(*search_nodes_, face_local_, opt, search_, pairs_);
  } else {
    lazy_ = false;
    // The boxes and planes of the received items, as find_contacts() reads them (a lazy
    // cycle has updated those of the items the lists read; the depths do not change).
    const std::size_t nr = face_in_.size();
    for (auto& v : recv_box_) v.resize(nr);
    if (!lazy && !motions_only)
      for (std::size_t j = 0; j < nr; ++j) {
        const ContactFaceItem& it = face_in_[j];
        put_box_and_plane(recv_box_, j, it);
        recv_box_[11][j] = it.depth;
      }
    for (int i = 0; i < 3; ++i) {
      boxes.lo[i] = recv_box_[i];
      boxes.hi[i] = recv_box_[3 + i];
      boxes.normal[i] = recv_box_[6 + i];
    }
    boxes.offset = recv_box_[9];
    boxes.warp = recv_box_[10];
    boxes.depth = recv_box_[11];
    if (!lazy) {
      ScopedPhase t(timers, Phase::contact_search);
      update_candidate_lists(*search_nodes_, face_in_, boxes, opt, search_);
    }
    {
      ScopedPhase t(timers, Phase::contact_search);
      queue_candidates(*search_nodes_, boxes, search_);
    }
    if (lazy || motions_only) {
      // The received motions of the faces queued for the detailed check into their items
      // (the others' items are not read this cycle).
      ScopedPhase t(timers, Phase::transfer);
      for (int f : search_.query_face) {
        const auto j = static_cast<std::size_t>(f);
        if (unpacked_[j] != stats_.cycles) {
          unpacked_[j] = stats_.cycles;
          if (motion_[j] < 0) // a face of this rank: its fields straight from it
            pack_cycle(static_cast<std::size_t>(-1 - motion_[j]), nd, face_in_[j]);
          else
            complete_item(face_sub_in_[static_cast<std::size_t>(motion_[j])], j);
        }
      }
    }
    ScopedPhase t(timers, Phase::contact_search);
    check_queued(*search_nodes_, *search_faces_, opt, search_, pairs_);
  }
  if (!alone && !lazy && !extra_somewhere) {
    ScopedPhase t(timers, Phase::transfer);
    set_shared_reference(boxes, !bound_ok);
  } else if (extra_somewhere) {
    shared_ = false;
  }
  stats_.list_builds = search_.builds;
  stats_.lazy_cycles += lazy_cycle || lazy ? 1 : 0;
}

void ContactPhase::forces(const ContactNodes& nd, double dt, PhaseTimers& timers) {
  const std::size_t nn = fe_.node_gid.size();
  // Only contact nodes receive forces (below: every rank that holds a node sums its items,
  // the same items in the same order); every other entry stays at the zero the caller
  // keeps there.
  if (force_nodes_.size() == nn) { // (every node is on the surface: a thin wall)
    for (int i = 0; i < 3; ++i) std::fill(nd.force[i], nd.force[i] + nn, 0.0);
  } else {
    for (int l : force_nodes_)
      for (int i = 0; i < 3; ++i) nd.force[i][l] = 0.0;
  }
  {
    ScopedPhase t(timers, Phase::contact_force);
    force_out_.clear();
    force_dest_.clear();
    penalty_forces(*search_nodes_, *search_faces_, pairs_, {config_.friction, dt},
                   {fe_.holder_start, fe_.holder_ranks}, force_out_, force_dest_);
    double deepest = 0, resisted = 0, deepest_share = 0;
    for (const auto& p : pairs_) {
      deepest = std::max(deepest, -p.gap);
      resisted = std::max(resisted, -p.gap - p.allowance);
      const double depth = (*search_faces_)[static_cast<std::size_t>(p.face)].depth;
      if (depth > 0) deepest_share = std::max(deepest_share, -p.gap / depth);
    }
    // Load of this rank: nodes searched plus faces held. One collective (an all-gather of
    // stat_values values per rank, reduced here in rank order) for the balance test, the
    // pair count and the deepest penetrations, which need both sums and maxima; and of the
    // force items' counts per destination rank, for the force plan (no all-to-all).
    const auto P = static_cast<std::size_t>(comm_.size());
    constexpr std::size_t K = stat_values;
    mine_[0] = static_cast<double>(search_nodes_->size() + search_faces_->size());
    mine_[1] = static_cast<double>(pairs_.size());
    mine_[2] = deepest;
    mine_[3] = resisted;
    mine_[4] = deepest_share;
    Migration::count(comm_.size(), force_dest_, force_counts_);
    for (std::size_t q = 0; q < P; ++q) mine_[K + q] = static_cast<double>(force_counts_[q]);
    comm_.allgather_bytes(mine_.data(), mine_.size() * sizeof(double), gathered_.data());
    for (std::size_t q = 0; q < P; ++q)
      force_recv_[q] = static_cast<std::int64_t>(
          gathered_[(K + P) * q + K + static_cast<std::size_t>(comm_.rank())]);
    double load_max = 0, load_sum = 0, pair_sum = 0, deep_max = 0, resisted_max = 0, share_max = 0;
    for (int r = 0; r < comm_.size(); ++r) {
      const double* g = gathered_.data() + (K + P) * static_cast<std::size_t>(r);
      load_max = std::max(load_max, g[0]);
      load_sum += g[0];
      pair_sum += g[1];
      deep_max = std::max(deep_max, g[2]);
      resisted_max = std::max(resisted_max, g[3]);
      share_max = std::max(share_max, g[4]);
    }
    const double mean = load_sum / comm_.size();
    stats_.imbalance = mean > 0 ? load_max / mean : 1.0;
    stats_.imbalance_max = std::max(stats_.imbalance_max, stats_.imbalance);
    stats_.pairs = static_cast<std::int64_t>(pair_sum);
    stats_.max_penetration = std::max(stats_.max_penetration, deep_max);
    stats_.max_penetration_resisted = std::max(stats_.max_penetration_resisted, resisted_max);
    stats_.max_penetration_of_depth = std::max(stats_.max_penetration_of_depth, share_max);
    if (just_rebalanced_) rebalance_floor_ = stats_.imbalance;
    just_rebalanced_ = false;
    rebalance_due_ =
        stats_.imbalance > std::max(config_.rebalance_threshold, 1.05 * rebalance_floor_);
  }

  {
    ScopedPhase t(timers, Phase::transfer);
    force_plan_.build(comm_, force_dest_, force_recv_);
    if (!force_plan_.stays()) force_plan_.forward(force_out_, force_in_);
    stats_.bytes_sent +=
        static_cast<double>(force_plan_.sent_elsewhere() * sizeof(ContactForceItem));
  }

  {
    ScopedPhase t(timers, Phase::contact_force);
    // Every rank that holds a node adds the contributions to it in ascending (node, pair
    // node): the sum depends neither on where the pairs were found nor on which copy of
    // the node it is (each copy gets the same items; no exchange of sums afterwards). The items are
    // grouped by receiving node (a counting sort on its local index; extra nodes after the mesh's),
    // and each group, a handful of items, is put in pair-node order by insertion: the order of
    // std::sort by (node, pair node) within every node, in linear time.
    const std::vector<ContactForceItem>& items = force_plan_.stays() ? force_out_ : force_in_;
    const std::size_t ni = items.size(), nk = nn + extra_.size();
    item_key_.reserve(items.capacity()); // grows only where the items did
    item_order_.reserve(items.capacity());
    item_key_.resize(ni);
    for (std::size_t j = 0; j < ni; ++j) {
      const std::int64_t g = items[j].target;
      if (g >= extra_offset_) {
        item_key_[j] =
            static_cast<int>(nn + static_cast<std::size_t>(
                                      std::lower_bound(extra_.begin(), extra_.end(), g,
                                                       [](const ContactNodeItem& a,
                                                          std::int64_t x) { return a.gid < x; }) -
                                      extra_.begin()));
      } else {
        item_key_[j] = node_index_.find(g); // a node this rank holds: always found
      }
    }
    key_start_.assign(nk + 1, 0);
    for (int k : item_key_) ++key_start_[static_cast<std::size_t>(k) + 1];
    for (std::size_t k = 0; k < nk; ++k) key_start_[k + 1] += key_start_[k];
    item_order_.resize(ni);
    for (std::size_t j = 0; j < ni; ++j)
      item_order_[static_cast<std::size_t>(key_start_[static_cast<std::size_t>(item_key_[j])]++)] =
          static_cast<int>(j);
    // The history of last cycle's pairs is cleared (of every owned node after a restore).
    for (int l :
         history_set_all_ ? std::span<const int>(my_nodes_) : std::span<const int>(history_set_)) {
      last_face_[static_cast<std::size_t>(l)] = -1;
      allowance_[static_cast<std::size_t>(l)] = 0;
    }
    history_set_all_ = false;
    history_set_.clear();
    extra_force_.assign(extra_.size(), {0.0, 0.0, 0.0});
    extra_face_.assign(extra_.size(), -1);
    // After the placement key_start_[k] is the end of group k, the start of group k + 1.
    for (std::size_t j0 = 0; j0 < ni;) {
      const auto k = static_cast<std::size_t>(item_key_[static_cast<std::size_t>(item_order_[j0])]);
      const auto j1 = static_cast<std::size_t>(key_start_[k]);
      for (std::size_t j = j0 + 1; j < j1; ++j) // insertion by pair node
        for (std::size_t i = j;
             i > j0 && items[static_cast<std::size_t>(item_order_[i])].slave <
                           items[static_cast<std::size_t>(item_order_[i - 1])].slave;
             --i)
          std::swap(item_order_[i], item_order_[i - 1]);
      double* sum = k >= nn ? extra_force_[k - nn].data() : nullptr;
      for (std::size_t j = j0; j < j1; ++j) {
        const auto& it = items[static_cast<std::size_t>(item_order_[j])];
        if (sum) {
          for (int i = 0; i < 3; ++i) sum[i] += it.f[i];
          if (it.target == it.slave) extra_face_[k - nn] = it.face;
          continue;
        }
        for (int i = 0; i < 3; ++i) nd.force[i][k] += it.f[i];
        if (it.target == it.slave) {
          last_face_[k] = it.face;
          allowance_[k] = it.allowance;
          history_set_.push_back(static_cast<int>(k));
        }
      }
      j0 = j1;
    }
  }
}

std::vector<std::vector<int>>
ContactPhase::element_contact_rank(const std::vector<HexBlock>& blocks) const {
  std::vector<std::vector<int>> out(blocks.size());
  for (std::size_t b = 0; b < blocks.size(); ++b)
    out[b].assign(static_cast<std::size_t>(blocks[b].size()), -1);
  for (std::size_t f = 0; f < my_face_gid_.size(); ++f) {
    if (!active(f)) continue; // (a face erosion has not exposed has no contact rank)
    const auto [el, side] = my_face_element_[f];
    for (std::size_t b = 0; b < blocks.size(); ++b) {
      const auto& g = blocks[b].gid;
      const auto it = std::lower_bound(g.begin(), g.end(), el);
      if (it != g.end() && *it == el) {
        auto& slot = out[b][static_cast<std::size_t>(it - g.begin())];
        if (slot < 0) slot = my_face_rank_[f];
        break;
      }
    }
  }
  return out;
}

} // namespace anvil
