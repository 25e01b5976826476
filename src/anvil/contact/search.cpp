#include "anvil/contact/search.hpp"

#include <algorithm>
#include <cmath>

#include "anvil/contact/geometry.hpp"

namespace anvil {

void find_contacts(const std::vector<ContactNodeItem>& nodes,
                   const std::vector<ContactFaceItem>& faces, const SearchOptions& opt,
                   SearchWorkspace& w, std::vector<ContactPair>& pairs) {
  pairs.clear();
  if (nodes.empty() || faces.empty()) return;
  const std::size_t nf = faces.size();

  // Capture boxes: the face's bounding box grown by its contact depth.
  w.box.resize(6 * nf);
  double cell = 0;
  for (std::size_t f = 0; f < nf; ++f) {
    double* b = &w.box[6 * f];
    for (int i = 0; i < 3; ++i) {
      double lo = faces[f].x[0][i], hi = lo;
      for (int a = 1; a < 4; ++a) {
        lo = std::min(lo, faces[f].x[a][i]);
        hi = std::max(hi, faces[f].x[a][i]);
      }
      b[i] = lo - 2 * faces[f].depth;
      b[3 + i] = hi + 2 * faces[f].depth;
      cell = std::max(cell, b[3 + i] - b[i]);
    }
  }
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
  w.cell_faces.resize(static_cast<std::size_t>(w.cell_start[ncell]));
  w.face_cells.assign(w.cell_start.begin(), w.cell_start.end() - 1); // fill cursors
  for (std::size_t f = 0; f < nf; ++f)
    for_cells(f, [&](std::size_t c) {
      w.cell_faces[static_cast<std::size_t>(w.face_cells[c]++)] = static_cast<int>(f);
    });

  const double tol = 1 + opt.parametric_tolerance;
  std::vector<const ContactFaceItem*>& own = w.own;
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    const auto& nd = nodes[n];
    const Vec3 p{nd.x[0], nd.x[1], nd.x[2]};
    const std::size_t c =
        (static_cast<std::size_t>(index(2, p.z)) * dims[1] + index(1, p.y)) * dims[0] +
        index(0, p.x);
    // The node's outward normal: the sum of the area normals of its own faces (all of
    // them are among the candidates: their capture boxes hold the node), taken in
    // ascending face id so that every rank gets the same bits.
    own.clear();
    for (int k = w.cell_start[c]; k < w.cell_start[c + 1]; ++k) {
      const auto& fc = faces[static_cast<std::size_t>(w.cell_faces[static_cast<std::size_t>(k)])];
      if (fc.node[0] == nd.gid || fc.node[1] == nd.gid || fc.node[2] == nd.gid ||
          fc.node[3] == nd.gid)
        own.push_back(&fc);
    }
    std::sort(own.begin(), own.end(),
              [](const ContactFaceItem* a, const ContactFaceItem* b) { return a->gid < b->gid; });
    own.erase(std::unique(own.begin(), own.end(),
                          [](const ContactFaceItem* a, const ContactFaceItem* b) {
                            return a->gid == b->gid;
                          }),
              own.end());
    Vec3 node_normal;
    for (const ContactFaceItem* fc : own) {
      const Vec3 d1{fc->x[2][0] - fc->x[0][0], fc->x[2][1] - fc->x[0][1],
                    fc->x[2][2] - fc->x[0][2]};
      const Vec3 d2{fc->x[3][0] - fc->x[1][0], fc->x[3][1] - fc->x[1][1],
                    fc->x[3][2] - fc->x[1][2]};
      node_normal += cross(d1, d2);
    }

    ContactPair best, tracked;
    bool found = false, have_tracked = false;
    std::int64_t best_gid = 0;
    for (int k = w.cell_start[c]; k < w.cell_start[c + 1]; ++k) {
      const int f = w.cell_faces[static_cast<std::size_t>(k)];
      const auto& fc = faces[static_cast<std::size_t>(f)];
      const double* b = &w.box[6 * static_cast<std::size_t>(f)];
      if (p.x < b[0] || p.x > b[3] || p.y < b[1] || p.y > b[4] || p.z < b[2] || p.z > b[5])
        continue;
      if (fc.node[0] == nd.gid || fc.node[1] == nd.gid || fc.node[2] == nd.gid ||
          fc.node[3] == nd.gid)
        continue;
      const std::array<Vec3, 4> x = {
          Vec3{fc.x[0][0], fc.x[0][1], fc.x[0][2]}, Vec3{fc.x[1][0], fc.x[1][1], fc.x[1][2]},
          Vec3{fc.x[2][0], fc.x[2][1], fc.x[2][2]}, Vec3{fc.x[3][0], fc.x[3][1], fc.x[3][2]}};
      const QuadProjection q = project_on_quad(x, p);
      if (!q.converged || std::abs(q.xi) > tol || std::abs(q.eta) > tol || !(q.gap < 0)) continue;
      // The surfaces must face each other: a node just outside a convex edge can be
      // "behind" the side face there while it is in front of the top face.
      if (!own.empty() && !(dot(node_normal, q.normal) < -0.3 * norm(node_normal))) continue;
      if (fc.gid == nd.last_face && -q.gap <= 2 * fc.depth) {
        tracked = {static_cast<int>(n), f, q.xi, q.eta, q.gap, q.normal};
        have_tracked = true;
      }
      if (-q.gap > fc.depth) continue;
      // Least penetration wins; equal penetrations go to the lower face id.
      if (!found || q.gap > best.gap || (q.gap == best.gap && fc.gid < best_gid)) {
        best = {static_cast<int>(n), f, q.xi, q.eta, q.gap, q.normal};
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
