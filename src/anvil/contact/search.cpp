#include "anvil/contact/search.hpp"

#include <algorithm>
#include <cmath>

#include "anvil/contact/geometry.hpp"

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
  Box3 b{{1e300, 1e300, 1e300}, {-1e300, -1e300, -1e300}};
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) {
      const double v = f.x[a][i];
      b.lo[i] = std::min({b.lo[i], v, v + back[i]});
      b.hi[i] = std::max({b.hi[i], v, v + back[i]});
    }
  for (int i = 0; i < 3; ++i) {
    b.lo[i] -= pad;
    b.hi[i] += pad;
  }
  return b;
}

void find_contacts(const std::vector<ContactNodeItem>& nodes,
                   const std::vector<ContactFaceItem>& faces, const SearchOptions& opt,
                   SearchWorkspace& w, std::vector<ContactPair>& pairs) {
  pairs.clear();
  if (nodes.empty() || faces.empty()) return;
  const std::size_t nf = faces.size();

  w.box.resize(6 * nf);
  w.extent.resize(nf);
  w.plane.resize(5 * nf);
  for (std::size_t f = 0; f < nf; ++f) {
    // Mean plane (unit normal from the diagonals) and how far the warped face strays from
    // it: cheap tests that discard most candidates before the projection.
    const FacePlane fp = face_plane(faces[f]);
    const Box3 cb = capture_box(faces[f], fp);
    double* b = &w.box[6 * f];
    for (int i = 0; i < 3; ++i) {
      b[i] = cb.lo[i];
      b[3 + i] = cb.hi[i];
    }
    w.extent[f] = std::max({b[3] - b[0], b[4] - b[1], b[5] - b[2]});
    double* pl = &w.plane[5 * f];
    pl[0] = fp.normal.x;
    pl[1] = fp.normal.y;
    pl[2] = fp.normal.z;
    pl[3] = dot(fp.centre, fp.normal);
    pl[4] = fp.warp;
  }
  // Cells the size of the median capture box: a typical face lands in at most 2 x 2 x 2
  // cells, the few large ones (a crushing block's) in more, and a node's cell lists only
  // the faces near it.
  std::nth_element(w.extent.begin(), w.extent.begin() + static_cast<std::ptrdiff_t>(nf / 2),
                   w.extent.end());
  double cell = 1.0 * w.extent[nf / 2];
  // Grid over the nodes' bounding box; cells no smaller than the largest capture box, so
  // a face lands in at most 2 x 2 x 2 cells, and never more cells than 8 per item.
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
  auto index = [&](int i, double v) {
    return std::clamp(static_cast<int>(std::floor((v - lo[i]) / cell)), 0, dims[i] - 1);
  };
  const std::size_t ncell = static_cast<std::size_t>(dims[0]) * dims[1] * dims[2];
  w.cell_start.assign(ncell + 1, 0);
  // Two passes (count, fill) over the cells each face's box covers, clipped to the grid;
  // faces entirely outside the nodes' box are skipped.
  auto for_cells = [&](std::size_t f, auto&& fn) {
    const double* b = &w.box[6 * f];
    for (int i = 0; i < 3; ++i)
      if (b[3 + i] < lo[i] || b[i] > hi[i]) return;
    const int i0 = index(0, b[0]), i1 = index(0, b[3]), j0 = index(1, b[1]), j1 = index(1, b[4]);
    const int k0 = index(2, b[2]), k1 = index(2, b[5]);
    for (int k = k0; k <= k1; ++k)
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i)
          fn((static_cast<std::size_t>(k) * dims[1] + j) * dims[0] + i);
  };
  for (std::size_t f = 0; f < nf; ++f) for_cells(f, [&](std::size_t c) { ++w.cell_start[c + 1]; });
  for (std::size_t c = 0; c < ncell; ++c) w.cell_start[c + 1] += w.cell_start[c];
  w.entries.resize(static_cast<std::size_t>(w.cell_start[ncell]));
  w.cursor.assign(w.cell_start.begin(), w.cell_start.end() - 1);
  for (std::size_t f = 0; f < nf; ++f)
    for_cells(f, [&](std::size_t c) {
      // Each entry carries its face's box, so the scan of a cell is one contiguous stream.
      auto& en = w.entries[static_cast<std::size_t>(w.cursor[c]++)];
      const double* b = &w.box[6 * f];
      for (int i = 0; i < 3; ++i) {
        en.lo[i] = b[i];
        en.hi[i] = b[3 + i];
      }
      en.face = static_cast<int>(f);
    });

  const double tol = 1 + opt.parametric_tolerance;
  // Node ids of every face and its element's other nodes, packed for the hot loop.
  w.ids.resize(8 * nf);
  for (std::size_t f = 0; f < nf; ++f)
    for (int a = 0; a < 4; ++a) {
      w.ids[8 * f + a] = faces[f].node[a];
      w.ids[8 * f + 4 + a] = faces[f].opposite[a];
    }
  std::vector<int>& own = w.own;
  std::vector<int>& cand = w.cand;
  auto by_gid = [&](int a, int b) {
    return faces[static_cast<std::size_t>(a)].gid < faces[static_cast<std::size_t>(b)].gid;
  };
  auto same_gid = [&](int a, int b) {
    return faces[static_cast<std::size_t>(a)].gid == faces[static_cast<std::size_t>(b)].gid;
  };
  // The surfaces face each other when at least one of the node's own faces opposes the
  // candidate (normals at more than about 107 degrees). At a convex edge a node just
  // outside is "behind" the side face, but none of its faces opposes that face; in a
  // closing fold the node at the crease has one face on each side, and one opposes.
  auto faces_oppose = [&](const std::vector<int>& mine, const Vec3& fn) {
    if (mine.empty()) return true;
    for (int g : mine) {
      const double* q = &w.plane[5 * static_cast<std::size_t>(g)];
      if (q[0] * fn.x + q[1] * fn.y + q[2] * fn.z < -0.3) return true;
    }
    return false;
  };
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    const auto& nd = nodes[n];
    const Vec3 p{nd.x[0], nd.x[1], nd.x[2]};
    const std::size_t c =
        (static_cast<std::size_t>(index(2, p.z)) * dims[1] + index(1, p.y)) * dims[0] +
        index(0, p.x);
    // Pass 1: the faces of the node's cell whose capture box holds it, split into its own
    // faces and the others (minus those of elements the node belongs to).
    own.clear();
    cand.clear();
    for (int k = w.cell_start[c]; k < w.cell_start[c + 1]; ++k) {
      const auto& en = w.entries[static_cast<std::size_t>(k)];
      const bool outside = (p.x < en.lo[0]) | (p.x > en.hi[0]) | (p.y < en.lo[1]) |
                           (p.y > en.hi[1]) | (p.z < en.lo[2]) | (p.z > en.hi[2]);
      if (outside) continue;
      const int f = en.face;
      const std::int64_t* id = &w.ids[8 * static_cast<std::size_t>(f)];
      if (id[0] == nd.gid || id[1] == nd.gid || id[2] == nd.gid || id[3] == nd.gid)
        own.push_back(f);
      else if (id[4] != nd.gid && id[5] != nd.gid && id[6] != nd.gid && id[7] != nd.gid)
        cand.push_back(f);
    }
    if (cand.empty()) continue;
    // The node's own faces (all of them are here: their capture boxes hold the node),
    // deduplicated (a face can sit in several cells? no: one cell per node, but ghosts of
    // the same face never coexist on a rank; kept for safety).
    std::sort(own.begin(), own.end(), by_gid);
    own.erase(std::unique(own.begin(), own.end(), same_gid), own.end());
    // Pass 2: the detailed check of the candidates.
    ContactPair best, tracked;
    bool found = false, have_tracked = false;
    std::int64_t best_gid = 0;
    for (int f : cand) {
      const auto& fc = faces[static_cast<std::size_t>(f)];
      // The surfaces must face each other (a node just outside a convex edge can be
      // "behind" the side face there while it is in front of the top face), and the node
      // must be behind the face's mean plane, not deeper than a tracked pair may go.
      const double* pl = &w.plane[5 * static_cast<std::size_t>(f)];
      const Vec3 fn{pl[0], pl[1], pl[2]};
      if (!faces_oppose(own, fn)) continue;
      const double side = dot(p, fn) - pl[3];
      if (side > pl[4] || side < -(2 * fc.depth + pl[4])) continue;
      const std::array<Vec3, 4> x = {
          Vec3{fc.x[0][0], fc.x[0][1], fc.x[0][2]}, Vec3{fc.x[1][0], fc.x[1][1], fc.x[1][2]},
          Vec3{fc.x[2][0], fc.x[2][1], fc.x[2][2]}, Vec3{fc.x[3][0], fc.x[3][1], fc.x[3][2]}};
      const QuadProjection q = project_on_quad(x, p);
      if (!q.converged || std::abs(q.xi) > tol || std::abs(q.eta) > tol || !(q.gap < 0)) continue;
      if (fc.gid == nd.last_face && -q.gap <= 2 * fc.depth) {
        tracked = {static_cast<int>(n),           f, q.xi, q.eta, q.gap, q.normal,
                   std::min(nd.allowance, -q.gap)};
        have_tracked = true;
      }
      if (!(-q.gap < fc.depth)) continue;
      // A new pair needs the node to have come through the face this step: at the start
      // of the step (x - dt v for node and face alike) it was in front of the face's mean
      // plane. A node found behind a face it never crossed is on the far side of the same
      // wall, or came round an edge, and is not in contact with this face.
      if (opt.dt > 0) {
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
        if (len0 > 0 && dot(p0 - c0, n0) < -(pl[4] + 1e-3 * fc.depth) * len0) continue;
      }
      // Least penetration wins; equal penetrations go to the lower face id.
      if (!found || q.gap > best.gap || (q.gap == best.gap && fc.gid < best_gid)) {
        best = {static_cast<int>(n), f, q.xi, q.eta, q.gap, q.normal, -q.gap};
        best_gid = fc.gid;
        found = true;
      }
    }
    if (have_tracked)
      pairs.push_back(tracked);
    else if (found)
      pairs.push_back(best);
  }
}

} // namespace anvil
