#include "anvil/contact/search.hpp"

#include <algorithm>
#include <cmath>

#include "anvil/contact/geometry.hpp"
#include "anvil/core/simd.hpp"

namespace anvil {

FacePlane face_plane(const ContactFaceItem& f) {
  const auto& x = f.x;
  FacePlane p;
  p.centre = {0.25 * (x[0][0] + x[1][0] + x[2][0] + x[3][0]),
              0.25 * (x[0][1] + x[1][1] + x[2][1] + x[3][1]),
              0.25 * (x[0][2] + x[1][2] + x[2][2] + x[3][2])};
  const Vec3 n = cross(Vec3{x[2][0] - x[0][0], x[2][1] - x[0][1], x[2][2] - x[0][2]},
                       Vec3{x[3][0] - x[1][0], x[3][1] - x[1][1], x[3][2] - x[1][2]});
  const double len = norm(n);
  p.normal = len > 0 ? n * (1 / len) : Vec3{};
  p.size = std::sqrt(0.5 * len); // the diagonals' cross product is twice the area
  for (int a = 0; a < 4; ++a)
    p.warp = std::max(p.warp, std::abs(dot(Vec3{x[a][0], x[a][1], x[a][2]} - p.centre, p.normal)));
  return p;
}

Box3 capture_box(const ContactFaceItem& f, const FacePlane& p) {
  const Vec3 back = p.normal * (-2 * f.depth);
  const double pad = 0.05 * p.size;
  Box3 b;
  for (int i = 0; i < 3; ++i) {
    double lo = 1e300, hi = -1e300;
    for (int a = 0; a < 4; ++a) {
      const double v = f.x[a][i], w = v + back[i];
      lo = std::min(lo, std::min(v, w));
      hi = std::max(hi, std::max(v, w));
    }
    b.lo[i] = lo - pad;
    b.hi[i] = hi + pad;
  }
  return b;
}

FacePlane set_capture(ContactFaceItem& f) {
  const FacePlane p = face_plane(f);
  const Box3 b = capture_box(f, p);
  for (int i = 0; i < 3; ++i) {
    f.normal[i] = p.normal[i];
    f.lo[i] = b.lo[i];
    f.hi[i] = b.hi[i];
  }
  f.offset = dot(p.centre, p.normal);
  f.warp = p.warp;
  return p;
}

namespace {

// True when the candidate lists of the last build still hold every face whose capture box
// holds each node: the same nodes and faces, none moved more than half the skin. (A node
// in a box now was then within half a skin of a box side that was itself within half a
// skin of where it is now. 0.45 rather than 0.5 leaves room for rounding.)
bool lists_valid(const std::vector<ContactNodeItem>& nodes,
                 const std::vector<ContactFaceItem>& faces, const FaceBoxes& boxes,
                 const SearchWorkspace& w) {
  const std::size_t nn = nodes.size(), nf = faces.size();
  if (!w.built || nn != w.node_gid.size() || nf != w.face_gid.size()) return false;
  const double half = 0.45 * w.skin;
  // No early exit; "bad" also when anything is not a number.
  unsigned bad = 0;
  for (std::size_t n = 0; n < nn; ++n) {
    const double* r = &w.node_ref[3 * n];
    bad |= static_cast<unsigned>(nodes[n].gid != w.node_gid[n]);
    for (int i = 0; i < 3; ++i)
      bad |= static_cast<unsigned>(!(std::abs(nodes[n].x[i] - r[i]) <= half));
  }
  for (std::size_t f = 0; f < nf; ++f) bad |= static_cast<unsigned>(faces[f].gid != w.face_gid[f]);
  // The boxes, a whole vector of faces at a time.
  const std::size_t nv = nf / simd::width * simd::width;
  simd::vmask badv(false);
  for (int s = 0; s < 6; ++s) {
    const double* b = (s < 3 ? boxes.lo[s] : boxes.hi[s - 3]).data();
    const double* r = w.box_ref.data() + static_cast<std::size_t>(s) * nf;
    for (std::size_t f = 0; f < nv; f += simd::width)
      badv |= !(abs(simd::load(b + f) - simd::load(r + f)) <= half);
    for (std::size_t f = nv; f < nf; ++f)
      bad |= static_cast<unsigned>(!(std::abs(b[f] - r[f]) <= half));
  }
  return bad == 0 && none_of(badv);
}

// Builds the candidate lists by binning: the enlarged capture boxes are bucket-sorted on a
// uniform grid, and each node scans the faces of its cell.
void build_lists(const std::vector<ContactNodeItem>& nodes,
                 const std::vector<ContactFaceItem>& faces, const FaceBoxes& boxes,
                 const SearchOptions& opt, SearchWorkspace& w) {
  const std::size_t nf = faces.size();
  w.extent.resize(nf);
  for (std::size_t f = 0; f < nf; ++f)
    w.extent[f] = std::max({boxes.hi[0][f] - boxes.lo[0][f], boxes.hi[1][f] - boxes.lo[1][f],
                            boxes.hi[2][f] - boxes.lo[2][f]});
  std::nth_element(w.extent.begin(), w.extent.begin() + static_cast<std::ptrdiff_t>(nf / 2),
                   w.extent.end());
  const double median = w.extent[nf / 2];
  w.skin = opt.skin * median;
  // Cells the size of the median enlarged capture box: a typical face lands in at most
  // 2 x 2 x 2 cells, the few large ones (a crushing block's) in more, and a node's cell
  // lists only the faces near it.
  double cell = median + 2 * w.skin;
  // Grid over the nodes' bounding box, never more cells than 8 per item.
  double lo[3], hi[3];
  for (int i = 0; i < 3; ++i) {
    lo[i] = hi[i] = nodes[0].x[i];
    for (const auto& n : nodes) {
      lo[i] = std::min(lo[i], n.x[i]);
      hi[i] = std::max(hi[i], n.x[i]);
    }
  }
  const double limit = 8.0 * static_cast<double>(nodes.size() + nf);
  int dims[3];
  for (;;) {
    double cells = 1;
    for (int i = 0; i < 3; ++i) {
      dims[i] = std::max(1, static_cast<int>(std::ceil((hi[i] - lo[i]) / cell)));
      cells *= dims[i];
    }
    if (cells <= limit) break;
    cell *= std::cbrt(cells / limit) * 1.01;
  }
  // The cell of a coordinate: any monotone map will do (a face is binned in every cell
  // from its box's low side's to its high side's, so a node in the box is in one of them).
  const double inv_cell = 1 / cell;
  auto index = [&](int i, double v) {
    return std::clamp(static_cast<int>(std::floor((v - lo[i]) * inv_cell)), 0, dims[i] - 1);
  };
  const std::size_t ncell = static_cast<std::size_t>(dims[0]) * dims[1] * dims[2];
  w.cell_start.assign(ncell + 1, 0);
  // The range of cells each enlarged box covers, clipped to the grid (i0, i1, j0, j1, k0,
  // k1; empty for a face entirely outside the nodes' box), and the count of each cell.
  w.face_cells.resize(6 * nf);
  for (std::size_t f = 0; f < nf; ++f) {
    int* r = w.face_cells.data() + 6 * f;
    bool outside = false;
    for (int i = 0; i < 3; ++i) {
      const double b0 = boxes.lo[i][f] - w.skin, b1 = boxes.hi[i][f] + w.skin;
      outside |= b1 < lo[i] || b0 > hi[i];
      r[2 * i] = index(i, b0);
      r[2 * i + 1] = index(i, b1);
    }
    if (outside) r[1] = r[0] - 1;
    for (int k = r[4]; k <= r[5]; ++k)
      for (int j = r[2]; j <= r[3]; ++j)
        for (int i = r[0]; i <= r[1]; ++i)
          ++w.cell_start[(static_cast<std::size_t>(k) * dims[1] + j) * dims[0] + i + 1];
  }
  for (std::size_t c = 0; c < ncell; ++c) w.cell_start[c + 1] += w.cell_start[c];
  // The faces into their cells (ascending in each: the pass runs over the faces in order),
  // then, entry after entry, their enlarged boxes (one vector of padding past the last
  // entry: a scan loads whole vectors).
  const auto used = static_cast<std::size_t>(w.cell_start[ncell]);
  const std::size_t ne = used + simd::width;
  w.entry_face.resize(ne);
  for (auto& v : w.entry_box) v.resize(ne);
  w.cursor.assign(w.cell_start.begin(), w.cell_start.end() - 1);
  for (std::size_t f = 0; f < nf; ++f) {
    const int* r = w.face_cells.data() + 6 * f;
    for (int k = r[4]; k <= r[5]; ++k)
      for (int j = r[2]; j <= r[3]; ++j)
        for (int i = r[0]; i <= r[1]; ++i)
          w.entry_face[static_cast<std::size_t>(
              w.cursor[(static_cast<std::size_t>(k) * dims[1] + j) * dims[0] + i]++)] =
              static_cast<int>(f);
  }
  for (int i = 0; i < 3; ++i) {
    const double* l = boxes.lo[i].data();
    const double* h = boxes.hi[i].data();
    double* el = w.entry_box[i].data();
    double* eh = w.entry_box[3 + i].data();
    for (std::size_t e = 0; e < used; ++e) {
      const auto f = static_cast<std::size_t>(w.entry_face[e]);
      el[e] = l[f] - w.skin;
      eh[e] = h[f] + w.skin;
    }
  }
  // Each face's nodes and opposite nodes side by side: the test of a candidate below
  // reads 64 bytes of a compact array, not the item.
  w.face_ids.resize(8 * nf);
  for (std::size_t f = 0; f < nf; ++f) {
    std::copy(faces[f].node, faces[f].node + 4, w.face_ids.begin() + 8 * f);
    std::copy(faces[f].opposite, faces[f].opposite + 4, w.face_ids.begin() + 8 * f + 4);
  }

  // The lists: for each node with at least one candidate (the active nodes), the faces of
  // its cell whose enlarged box holds it, in ascending face index (the fill pass runs
  // over the faces in order), first the candidates, then its own faces; faces of elements
  // it belongs to are left out. A node with no candidate cannot pair before the next build.
  // The entries of the cell are tested a vector at a time and those that hold the node
  // compressed, in order, into `cand`.
  w.active.clear();
  w.list_start.clear();
  w.own_start.clear();
  w.list.clear();
  int longest_cell = 0;
  for (std::size_t c = 0; c < ncell; ++c)
    longest_cell = std::max(longest_cell, w.cell_start[c + 1] - w.cell_start[c]);
  w.cand.resize(static_cast<std::size_t>(longest_cell) + simd::width);
  const double* const eb[6] = {w.entry_box[0].data(), w.entry_box[1].data(), w.entry_box[2].data(),
                               w.entry_box[3].data(), w.entry_box[4].data(), w.entry_box[5].data()};
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    const auto& nd = nodes[n];
    if (nd.dormant != 0) continue; // (no list: it cannot pair before the next build)
    const std::size_t c =
        (static_cast<std::size_t>(index(2, nd.x[2])) * dims[1] + index(1, nd.x[1])) * dims[0] +
        index(0, nd.x[0]);
    const int b = w.cell_start[c], e = w.cell_start[c + 1];
    const simd::vdouble x0 = nd.x[0], x1 = nd.x[1], x2 = nd.x[2];
    int m = 0;
    for (int k = b; k < e; k += simd::width) {
      const auto kz = static_cast<std::size_t>(k);
      unsigned out = simd::outside_lanes(x0, simd::load(eb[0] + kz), simd::load(eb[3] + kz)) |
                     simd::outside_lanes(x1, simd::load(eb[1] + kz), simd::load(eb[4] + kz)) |
                     simd::outside_lanes(x2, simd::load(eb[2] + kz), simd::load(eb[5] + kz));
      unsigned in = ~out & ((1u << simd::width) - 1u);
      if (e - k < simd::width) in &= (1u << (e - k)) - 1u; // (past the cell's end)
      m += simd::compress_store(in, w.entry_face.data() + kz, w.cand.data() + m);
    }
    const std::size_t first = w.list.size();
    w.own.clear();
    for (int i = 0; i < m; ++i) {
      const int f = w.cand[static_cast<std::size_t>(i)];
      const std::int64_t* ids = w.face_ids.data() + 8 * static_cast<std::size_t>(f);
      const std::int64_t g = nd.gid;
      const bool own = (ids[0] == g) | (ids[1] == g) | (ids[2] == g) | (ids[3] == g);
      const bool opposite = (ids[4] == g) | (ids[5] == g) | (ids[6] == g) | (ids[7] == g);
      if (own)
        w.own.push_back(f);
      else if (!opposite)
        w.list.push_back(f);
    }
    if (w.list.size() == first) continue;
    w.active.push_back(static_cast<int>(n));
    w.list_start.push_back(static_cast<int>(first));
    w.own_start.push_back(static_cast<int>(w.list.size()));
    w.list.insert(w.list.end(), w.own.begin(), w.own.end());
  }
  w.list_start.push_back(static_cast<int>(w.list.size()));

  w.node_gid.resize(nodes.size());
  w.node_ref.resize(3 * nodes.size());
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    w.node_gid[n] = nodes[n].gid;
    for (int i = 0; i < 3; ++i) w.node_ref[3 * n + i] = nodes[n].x[i];
  }
  w.face_gid.resize(nf);
  for (std::size_t f = 0; f < nf; ++f) w.face_gid[f] = faces[f].gid;
  w.box_ref.resize(6 * nf); // lo x, y, z, then hi x, y, z, each over all faces
  for (int i = 0; i < 3; ++i) {
    std::copy(boxes.lo[i].begin(), boxes.lo[i].begin() + static_cast<std::ptrdiff_t>(nf),
              w.box_ref.begin() + static_cast<std::ptrdiff_t>(i * nf));
    std::copy(boxes.hi[i].begin(), boxes.hi[i].begin() + static_cast<std::ptrdiff_t>(nf),
              w.box_ref.begin() + static_cast<std::ptrdiff_t>((3 + i) * nf));
  }
  // The faces the pair search may read: every face in some list.
  w.mark.assign(nf, 0);
  for (int f : w.list) w.mark[static_cast<std::size_t>(f)] = 1;
  w.needed.clear();
  for (std::size_t f = 0; f < nf; ++f)
    if (w.mark[f]) w.needed.push_back(static_cast<int>(f));
  // The longest range of candidates or own faces (filter_entries() writes at most that
  // many).
  w.longest = 0;
  for (std::size_t k = 0; k < w.active.size(); ++k)
    w.longest = std::max(
        {w.longest, w.own_start[k] - w.list_start[k], w.list_start[k + 1] - w.own_start[k]});
  // Room for a cycle's detailed checks: at most one per candidate entry.
  w.query_start.reserve(w.active.capacity() + 1);
  w.query_face.reserve(w.list.capacity()); // capacities: they grow only where the lists did
  w.queries.reserve(w.list.capacity());
  w.feet.reserve(w.list.capacity());
  w.built = true;
  ++w.builds;
}

// The detailed check's cheap filters, for the entries list[b..e) of a node at p: the
// face's capture box holds p (each side compared as p < lo, p > hi: a box with a NaN side
// holds) and, with Side, p lies behind the face's mean plane no deeper than a tracked pair
// may go (see find_pairs). Writes the faces that pass to out, in their order, and returns
// their number. Without branches on the outcomes (late in the can crush a little over
// half the candidates pass the box test, in no pattern a predictor could learn): every
// entry is written, and the count advances by the test's result.
template <bool Side>
int filter_entries(const int* list, int b, int e, const FaceBoxes& boxes, const Vec3& p, int* out) {
  const double *l0 = boxes.lo[0].data(), *l1 = boxes.lo[1].data(), *l2 = boxes.lo[2].data();
  const double *h0 = boxes.hi[0].data(), *h1 = boxes.hi[1].data(), *h2 = boxes.hi[2].data();
  using u = unsigned;
  int n = 0;
  for (int j = b; j < e; ++j) {
    const int f = list[j];
    const auto k = static_cast<std::size_t>(f);
    out[n] = f;
    n += static_cast<int>((u(p.x < l0[k]) | u(p.x > h0[k]) | u(p.y < l1[k]) | u(p.y > h1[k]) |
                           u(p.z < l2[k]) | u(p.z > h2[k])) ^
                          1u);
  }
  if constexpr (Side) {
    // Of those, in place: side = dot(p, normal) - offset within [-(2 depth + warp), warp].
    const double *n0 = boxes.normal[0].data(), *n1 = boxes.normal[1].data(),
                 *n2 = boxes.normal[2].data();
    const double *offset = boxes.offset.data(), *warp = boxes.warp.data(),
                 *depth = boxes.depth.data();
    int m = 0;
    for (int i = 0; i < n; ++i) {
      const int f = out[i];
      const auto k = static_cast<std::size_t>(f);
      const double side = dot(p, Vec3{n0[k], n1[k], n2[k]}) - offset[k];
      out[m] = f;
      m += static_cast<int>((u(side > warp[k]) | u(side < -(2 * depth[k] + warp[k]))) ^ 1u);
    }
    n = m;
  }
  return n;
}

} // namespace

bool update_candidate_lists(const std::vector<ContactNodeItem>& nodes,
                            const std::vector<ContactFaceItem>& faces, const FaceBoxes& boxes,
                            const SearchOptions& opt, SearchWorkspace& w) {
  if (nodes.empty() || faces.empty()) {
    w.built = false;
    w.active.clear();
    w.needed.clear();
    return false;
  }
  if (lists_valid(nodes, faces, boxes, w)) return false;
  build_lists(nodes, faces, boxes, opt, w);
  return true;
}

void find_contacts(const std::vector<ContactNodeItem>& nodes,
                   const std::vector<ContactFaceItem>& faces, const SearchOptions& opt,
                   SearchWorkspace& w, std::vector<ContactPair>& pairs) {
  FaceBoxes boxes;
  for (auto& b : w.box) b.resize(faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f) {
    for (int i = 0; i < 3; ++i) {
      w.box[i][f] = faces[f].lo[i];
      w.box[3 + i][f] = faces[f].hi[i];
      w.box[6 + i][f] = faces[f].normal[i];
    }
    w.box[9][f] = faces[f].offset;
    w.box[10][f] = faces[f].warp;
    w.box[11][f] = faces[f].depth;
  }
  for (int i = 0; i < 3; ++i) {
    boxes.lo[i] = w.box[i];
    boxes.hi[i] = w.box[3 + i];
    boxes.normal[i] = w.box[6 + i];
  }
  boxes.offset = w.box[9];
  boxes.warp = w.box[10];
  boxes.depth = w.box[11];
  update_candidate_lists(nodes, faces, boxes, opt, w);
  find_pairs(nodes, faces, boxes, opt, w, pairs);
}

void find_pairs(const std::vector<ContactNodeItem>& nodes,
                const std::vector<ContactFaceItem>& faces, const FaceBoxes& boxes,
                const SearchOptions& opt, SearchWorkspace& w, std::vector<ContactPair>& pairs) {
  if (faces.empty()) {
    pairs.clear();
    return;
  }
  queue_candidates(nodes, boxes, w);
  check_queued(nodes, faces, opt, w, pairs);
}

void queue_candidates(const std::vector<ContactNodeItem>& nodes, const FaceBoxes& boxes,
                      SearchWorkspace& w) {
  w.query_face.clear();
  w.query_start.assign(w.active.size() + 1, 0);
  if (nodes.empty() || boxes.lo[0].empty()) return;

  // Room for the filtered entries of the longest range.
  const auto room = static_cast<std::size_t>(w.longest);
  if (w.cand.size() < room) w.cand.resize(room);
  if (w.own.size() < room) w.own.resize(room);
  int* const cand = w.cand.data();
  int* const own = w.own.data();
  const double *n0 = boxes.normal[0].data(), *n1 = boxes.normal[1].data(),
               *n2 = boxes.normal[2].data();
  // The surfaces face each other when at least one of the node's own faces opposes the
  // candidate (normals at more than about 107 degrees). At a convex edge a node just
  // outside is "behind" the side face, but none of its faces opposes that face; in a
  // closing fold the node at the crease has one face on each side, and one opposes.
  // (Neither the order of the node's faces nor a repeated one changes the answer.)
  auto faces_oppose = [&](int nown, const Vec3& fn) {
    if (nown == 0) return true;
    for (int i = 0; i < nown; ++i) {
      const auto q = static_cast<std::size_t>(own[i]);
      if (n0[q] * fn.x + n1[q] * fn.y + n2[q] * fn.z < -0.3) return true;
    }
    return false;
  };
  // Node by node: the candidates whose capture box holds the node and behind whose mean
  // plane it lies, not deeper than a tracked pair may go; then, if there are any, the
  // node's own faces whose box holds it; of the candidates, those that face the node's
  // surface are queued for the detailed check. (A node just outside a convex edge can be
  // "behind" the side face there while it is in front of the top face.)
  for (std::size_t k = 0; k < w.active.size(); ++k) {
    w.query_start[k] = static_cast<int>(w.query_face.size());
    const auto& nd = nodes[static_cast<std::size_t>(w.active[k])];
    const Vec3 p{nd.x[0], nd.x[1], nd.x[2]};
    const int ncand =
        filter_entries<true>(w.list.data(), w.list_start[k], w.own_start[k], boxes, p, cand);
    if (ncand == 0) continue;
    const int nown =
        filter_entries<false>(w.list.data(), w.own_start[k], w.list_start[k + 1], boxes, p, own);
    for (int i = 0; i < ncand; ++i) {
      const int f = cand[i];
      const auto q = static_cast<std::size_t>(f);
      if (faces_oppose(nown, Vec3{n0[q], n1[q], n2[q]})) w.query_face.push_back(f);
    }
  }
  w.query_start[w.active.size()] = static_cast<int>(w.query_face.size());
}

namespace {

// Ramp of the edge band: 0 where the foot's parent coordinate t lies further than `band`
// inside the face's edge at t = 1, rising to 1 at the edge and staying 1 beyond it (a band
// of 0: a step at the edge).
double edge_ramp(double t, double band) {
  if (!(band > 0)) return t >= 1 ? 1.0 : 0.0;
  return std::clamp((t - (1 - band)) / band, 0.0, 1.0);
}

// Weight of face g in the blended normal and gap of a pair on face f with its foot at q:
// g shares an edge of f (both its nodes) or only a corner, and the weight is the ramp of
// that edge, or the product of the corner's two ramps; the largest of them when several
// apply (a triangle's collapsed edge is a corner shared by every face around it).
double blend_weight(const ContactFaceItem& f, const QuadProjection& q, const ContactFaceItem& g,
                    double band) {
  bool shared[4];
  for (int a = 0; a < 4; ++a)
    shared[a] = g.node[0] == f.node[a] || g.node[1] == f.node[a] || g.node[2] == f.node[a] ||
                g.node[3] == f.node[a];
  // Corner a at ((-1, -1), (1, -1), (1, 1), (-1, 1))[a]; edge a joins corners a and a + 1.
  const double xi_ramp[2] = {edge_ramp(-q.xi, band), edge_ramp(q.xi, band)};
  const double eta_ramp[2] = {edge_ramp(-q.eta, band), edge_ramp(q.eta, band)};
  constexpr int xi_side[4] = {0, 1, 1, 0}, eta_side[4] = {0, 0, 1, 1};
  double w = 0;
  for (int a = 0; a < 4; ++a) {
    if (!shared[a]) continue;
    const int b = (a + 1) % 4;
    const double corner = xi_ramp[xi_side[a]] * eta_ramp[eta_side[a]];
    // Edges 0 and 2 run along xi (eta = -1, 1), edges 1 and 3 along eta (xi = 1, -1).
    const double edge = !shared[b] ? 0 : a % 2 == 0 ? eta_ramp[eta_side[a]] : xi_ramp[xi_side[a]];
    w = std::max(w, std::max(corner, edge));
  }
  return w;
}

} // namespace

void check_queued(const std::vector<ContactNodeItem>& nodes,
                  const std::vector<ContactFaceItem>& faces, const SearchOptions& opt,
                  SearchWorkspace& w, std::vector<ContactPair>& pairs) {
  pairs.clear();
  if (w.query_face.empty()) return;
  const double tol = 1 + opt.parametric_tolerance;
  // Room for the faces around a vertex (a blend takes a handful; reserved once).
  if (w.blend.capacity() < 32) w.blend.reserve(32);
  // Pass 1: the queries, node by node.
  w.queries.clear();
  for (std::size_t k = 0; k < w.active.size(); ++k) {
    const auto& nd = nodes[static_cast<std::size_t>(w.active[k])];
    const Vec3 p{nd.x[0], nd.x[1], nd.x[2]};
    for (int j = w.query_start[k]; j < w.query_start[k + 1]; ++j) {
      const auto& fc = faces[static_cast<std::size_t>(w.query_face[static_cast<std::size_t>(j)])];
      w.queries.push_back(
          {{Vec3{fc.x[0][0], fc.x[0][1], fc.x[0][2]}, Vec3{fc.x[1][0], fc.x[1][1], fc.x[1][2]},
            Vec3{fc.x[2][0], fc.x[2][1], fc.x[2][2]}, Vec3{fc.x[3][0], fc.x[3][1], fc.x[3][2]}},
           p});
    }
  }
  // Pass 2: the feet of the normals, `simd::width` at a time.
  w.feet.resize(w.queries.size());
  project_on_quads(w.queries, w.feet);
  // Pass 3, node by node: the detailed check of its queued faces, in their order.
  for (std::size_t k = 0; k < w.active.size(); ++k) {
    const auto n = static_cast<std::size_t>(w.active[k]);
    const auto& nd = nodes[n];
    ContactPair best, tracked;
    bool found = false, have_tracked = false;
    std::int64_t best_gid = 0;
    int best_j = 0, tracked_j = 0;
    const int jb = w.query_start[k], je = w.query_start[k + 1];
    for (int j = jb; j < je; ++j) {
      const int f = w.query_face[static_cast<std::size_t>(j)];
      const auto& fc = faces[static_cast<std::size_t>(f)];
      const QuadProjection& q = w.feet[static_cast<std::size_t>(j)];
      if (!q.converged || std::abs(q.xi) > tol || std::abs(q.eta) > tol || !(q.gap < 0)) continue;
      if (fc.gid == nd.last_face && -q.gap <= 2 * fc.depth) {
        tracked = {static_cast<int>(n),           f, q.xi, q.eta, q.gap, q.normal,
                   std::min(nd.allowance, -q.gap)};
        tracked_j = j;
        have_tracked = true;
      }
      if (!(-q.gap < fc.depth)) continue;
      // A new pair needs the node to have come through the face this step: at the start
      // of the step (x - dt v for node and face alike) it was in front of the face's mean
      // plane. A node found behind a face it never crossed is on the far side of the same
      // wall, or came round an edge, and is not in contact with this face.
      // (A face erosion has just exposed: the node may have been behind it already, in
      // the element that eroded; it pairs with its depth as allowance.)
      if (opt.dt > 0 && fc.exposed == 0) {
        Vec3 c0, n0 = cross(
                     Vec3{(fc.x[2][0] - opt.dt * fc.v[2][0]) - (fc.x[0][0] - opt.dt * fc.v[0][0]),
                          (fc.x[2][1] - opt.dt * fc.v[2][1]) - (fc.x[0][1] - opt.dt * fc.v[0][1]),
                          (fc.x[2][2] - opt.dt * fc.v[2][2]) - (fc.x[0][2] - opt.dt * fc.v[0][2])},
                     Vec3{(fc.x[3][0] - opt.dt * fc.v[3][0]) - (fc.x[1][0] - opt.dt * fc.v[1][0]),
                          (fc.x[3][1] - opt.dt * fc.v[3][1]) - (fc.x[1][1] - opt.dt * fc.v[1][1]),
                          (fc.x[3][2] - opt.dt * fc.v[3][2]) - (fc.x[1][2] - opt.dt * fc.v[1][2])});
        for (int a = 0; a < 4; ++a)
          for (int i = 0; i < 3; ++i) c0[i] += 0.25 * (fc.x[a][i] - opt.dt * fc.v[a][i]);
        const Vec3 p0{nd.x[0] - opt.dt * nd.v[0], nd.x[1] - opt.dt * nd.v[1],
                      nd.x[2] - opt.dt * nd.v[2]};
        const double len0 = norm(n0);
        if (len0 > 0 && dot(p0 - c0, n0) < -(fc.warp + 1e-3 * fc.depth) * len0) continue;
      }
      // Least penetration wins; equal penetrations go to the lower face id.
      if (!found || q.gap > best.gap || (q.gap == best.gap && fc.gid < best_gid)) {
        best = {static_cast<int>(n), f, q.xi, q.eta, q.gap, q.normal, -q.gap};
        best_gid = fc.gid;
        best_j = j;
        found = true;
      }
    }
    if (!have_tracked && !found) continue;
    ContactPair pair = have_tracked ? tracked : best;
    int pj = have_tracked ? tracked_j : best_j;
    // A tracked pair whose foot has left its face (within the parametric tolerance) moves to
    // the face across the edge it crossed when the foot lies on that face and the node is
    // behind it, no deeper than a tracked pair may go: a node sliding over an interface
    // pairs with the face it is over, whichever face it met first (of several, the least
    // penetrated, then the lower id).
    if (have_tracked && (std::abs(pair.xi) > 1 || std::abs(pair.eta) > 1)) {
      const auto& fc = faces[static_cast<std::size_t>(pair.face)];
      const QuadProjection& qt = w.feet[static_cast<std::size_t>(pj)];
      int to = -1;
      std::int64_t to_gid = 0;
      double to_gap = 0;
      for (int j = jb; j < je; ++j) {
        const int f = w.query_face[static_cast<std::size_t>(j)];
        const auto& g = faces[static_cast<std::size_t>(f)];
        const QuadProjection& q = w.feet[static_cast<std::size_t>(j)];
        if (f == pair.face || !q.converged || std::abs(q.xi) > 1 || std::abs(q.eta) > 1 ||
            !(q.gap < 0) || -q.gap > 2 * g.depth || blend_weight(fc, qt, g, opt.edge_blend) == 0)
          continue;
        if (to < 0 || q.gap > to_gap || (q.gap == to_gap && g.gid < to_gid)) {
          to = j;
          to_gid = g.gid;
          to_gap = q.gap;
        }
      }
      if (to >= 0) {
        const QuadProjection& q = w.feet[static_cast<std::size_t>(to)];
        pair = {static_cast<int>(n),
                w.query_face[static_cast<std::size_t>(to)],
                q.xi,
                q.eta,
                q.gap,
                q.normal,
                std::min(nd.allowance, -q.gap)};
        pj = to;
      }
    }
    // Near an edge or a corner of its face the pair's normal and gap blend with those of
    // the queued faces across it (blend_weight; faces turned less than 90 degrees from
    // this one, their feet found within the tolerance): at the edge or corner itself they
    // are the plain average of the faces that share it. So the normal turns continuously
    // as a node slides from face to face, and does not depend on which of the faces around
    // a vertex the node met first: a node that meets a mesh at one of its nodes (matching
    // meshes) is pushed along the mean normal of the faces there, as its mirror image is.
    if (opt.edge_blend > 0 &&
        std::max(std::abs(pair.xi), std::abs(pair.eta)) > 1 - opt.edge_blend) {
      const auto& fc = faces[static_cast<std::size_t>(pair.face)];
      const QuadProjection& qp = w.feet[static_cast<std::size_t>(pj)];
      w.blend.clear();
      for (int j = jb; j < je; ++j) {
        const int f = w.query_face[static_cast<std::size_t>(j)];
        const QuadProjection& q = w.feet[static_cast<std::size_t>(j)];
        if (f == pair.face || !q.converged || std::abs(q.xi) > tol || std::abs(q.eta) > tol ||
            !(dot(q.normal, qp.normal) > 0))
          continue;
        const auto& g = faces[static_cast<std::size_t>(f)];
        const double b = blend_weight(fc, qp, g, opt.edge_blend);
        if (b > 0) w.blend.push_back({g.gid, j, b});
      }
      if (!w.blend.empty()) {
        // Summed in ascending face id, the pair's own face among them: the same bits
        // whatever order this rank holds the faces in.
        w.blend.push_back({fc.gid, pj, 1.0});
        std::sort(w.blend.begin(), w.blend.end(),
                  [](const auto& a, const auto& b) { return a.gid < b.gid; });
        Vec3 normal;
        double gap = 0, weight = 0;
        for (const auto& e : w.blend) {
          const QuadProjection& q = w.feet[static_cast<std::size_t>(e.query)];
          normal += e.weight * q.normal;
          gap += e.weight * q.gap;
          weight += e.weight;
        }
        const double len = norm(normal);
        if (len > 0) pair.normal = normal * (1 / len);
        pair.gap = gap / weight;
        pair.allowance = std::min(pair.allowance, std::max(0.0, -pair.gap));
      }
    }
    pairs.push_back(pair);
  }
}

} // namespace anvil
