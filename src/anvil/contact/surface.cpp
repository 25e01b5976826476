#include "anvil/contact/surface.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace anvil {

std::vector<bool> blocks_named(const Mesh& mesh, const std::vector<std::string>& parts) {
  std::vector<bool> selected(mesh.blocks.size(), parts.empty());
  for (const auto& name : parts)
    for (std::size_t b = 0; b < mesh.blocks.size(); ++b)
      if (mesh.blocks[b].name == name) selected[b] = true;
  return selected;
}

ExteriorFaces exterior_faces(const Mesh& mesh, const std::vector<bool>& selected,
                             const std::vector<bool>& erodible) {
  // Sort every face of every element by its key (face_key); a key seen once is exterior.
  // (The faces of wedges, pyramids and tetrahedra that collapsed to an edge or a point
  // are no faces.)
  struct Key {
    FaceKey sorted;
    std::int64_t element;
    int side;
  };
  std::vector<Key> keys;
  keys.reserve(static_cast<std::size_t>(mesh.num_elements()) * 6);
  std::int64_t e = 0;
  for (const auto& b : mesh.blocks)
    for (const auto& h : b.elements) {
      for (int s = 0; s < 6; ++s)
        if (const FaceKey k = face_key(h, s); is_face(k)) keys.push_back({k, e, s});
      ++e;
    }
  std::sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) {
    return a.sorted != b.sorted ? a.sorted < b.sorted : a.element < b.element;
  });
  const auto offsets = mesh.block_offsets();
  auto block_of = [&](std::int64_t el) {
    return static_cast<std::size_t>(std::upper_bound(offsets.begin(), offsets.end(), el) -
                                    offsets.begin() - 1);
  };
  auto can_erode = [&](std::int64_t el) { return !erodible.empty() && erodible[block_of(el)]; };
  struct Found {
    std::int64_t element;
    int side;
    std::int64_t behind;
    bool operator<(const Found& o) const {
      return element != o.element ? element < o.element : side < o.side;
    }
  };
  std::vector<Found> exterior;
  for (std::size_t i = 0; i < keys.size();) {
    std::size_t j = i + 1;
    while (j < keys.size() && keys[j].sorted == keys[i].sorted) ++j;
    if (j == i + 1 && selected[block_of(keys[i].element)])
      exterior.push_back({keys[i].element, keys[i].side, -1});
    if (j == i + 2 && (can_erode(keys[i].element) || can_erode(keys[i + 1].element)))
      for (std::size_t k = i; k < j; ++k)
        if (selected[block_of(keys[k].element)])
          exterior.push_back({keys[k].element, keys[k].side, keys[2 * i + 1 - k].element});
    i = j;
  }
  std::sort(exterior.begin(), exterior.end());

  // Element connectivity by global element id.
  std::vector<const Hex*> hex;
  hex.reserve(static_cast<std::size_t>(mesh.num_elements()));
  for (const auto& b : mesh.blocks)
    for (const auto& h : b.elements) hex.push_back(&h);
  ExteriorFaces out;
  for (const auto& [el, s, behind] : exterior) {
    const Hex& h = *hex[static_cast<std::size_t>(el)];
    out.element.push_back(el);
    out.side.push_back(s);
    out.behind.push_back(behind);
    out.nodes.push_back(face_nodes(h, s));
    for (int a = 0; a < 4; ++a) out.contact_nodes.push_back(out.nodes.back()[a]);
  }
  std::sort(out.contact_nodes.begin(), out.contact_nodes.end());
  out.contact_nodes.erase(std::unique(out.contact_nodes.begin(), out.contact_nodes.end()),
                          out.contact_nodes.end());
  return out;
}

std::vector<std::array<std::int64_t, 2>> links_between_bodies(const Mesh& mesh,
                                                              const ExteriorFaces& faces) {
  std::vector<std::array<std::int64_t, 2>> links;
  const std::size_t nf = faces.size();
  if (nf == 0) return links;
  // Bodies: union-find over the nodes, each element joining its nodes.
  std::vector<std::int64_t> root(static_cast<std::size_t>(mesh.num_nodes()));
  std::iota(root.begin(), root.end(), 0);
  auto find = [&](std::int64_t a) {
    while (root[static_cast<std::size_t>(a)] != a)
      a = root[static_cast<std::size_t>(a)] =
          root[static_cast<std::size_t>(root[static_cast<std::size_t>(a)])];
    return a;
  };
  for (const auto& b : mesh.blocks)
    for (const auto& h : b.elements)
      for (int a = 1; a < 8; ++a) {
        const std::int64_t r0 = find(h[0]), r1 = find(h[a]);
        if (r0 != r1) root[static_cast<std::size_t>(std::max(r0, r1))] = std::min(r0, r1);
      }
  // Each face's box, its size (the square root of the mean of its sides' squares) and
  // body; one body alone links nothing.
  std::vector<Box3> box(nf);
  std::vector<double> size(nf);
  std::vector<std::int64_t> body(nf);
  for (std::size_t f = 0; f < nf; ++f) {
    const auto& q = faces.nodes[f];
    double s2 = 0;
    for (int a = 0; a < 4; ++a) {
      const Vec3& x = mesh.nodes[static_cast<std::size_t>(q[a])];
      for (int i = 0; i < 3; ++i) {
        box[f].lo[i] = a == 0 ? x[i] : std::min(box[f].lo[i], x[i]);
        box[f].hi[i] = a == 0 ? x[i] : std::max(box[f].hi[i], x[i]);
      }
      const Vec3 d = mesh.nodes[static_cast<std::size_t>(q[(a + 1) % 4])] - x;
      s2 += dot(d, d);
    }
    size[f] = std::sqrt(0.25 * s2);
    body[f] = find(q[0]);
  }
  if (std::all_of(body.begin(), body.end(), [&](std::int64_t b) { return b == body[0]; }))
    return links;
  // A uniform grid of cells of the median reach (box side plus size); each face is entered
  // in every cell its box, enlarged by its size, touches; faces that share a cell are tested.
  std::vector<double> reach(nf);
  Box3 all = box[0];
  for (std::size_t f = 0; f < nf; ++f) {
    double side = 0;
    for (int i = 0; i < 3; ++i) {
      side = std::max(side, box[f].hi[i] - box[f].lo[i]);
      all.lo[i] = std::min(all.lo[i], box[f].lo[i] - size[f]);
      all.hi[i] = std::max(all.hi[i], box[f].hi[i] + size[f]);
    }
    reach[f] = side + 2 * size[f];
  }
  std::vector<double> sorted = reach;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(nf / 2),
                   sorted.end());
  double h = std::max(sorted[nf / 2], 1e-300);
  int n[3];
  // At most about 8 cells per face: a mesh whose faces differ much in size gets coarser cells.
  for (;;) {
    double cells = 1;
    for (int i = 0; i < 3; ++i) {
      n[i] = std::max(1, static_cast<int>(std::ceil((all.hi[i] - all.lo[i]) / h)));
      cells *= n[i];
    }
    if (cells <= 8.0 * static_cast<double>(nf) + 64) break;
    h *= 2;
  }
  auto cell_range = [&](double lo, double hi, int i, int& c0, int& c1) {
    c0 = std::clamp(static_cast<int>((lo - all.lo[i]) / h), 0, n[i] - 1);
    c1 = std::clamp(static_cast<int>((hi - all.lo[i]) / h), 0, n[i] - 1);
  };
  std::vector<std::array<std::int64_t, 2>> entries; // (cell, face)
  for (std::size_t f = 0; f < nf; ++f) {
    int c0[3], c1[3];
    for (int i = 0; i < 3; ++i)
      cell_range(box[f].lo[i] - size[f], box[f].hi[i] + size[f], i, c0[i], c1[i]);
    for (int k = c0[2]; k <= c1[2]; ++k)
      for (int j = c0[1]; j <= c1[1]; ++j)
        for (int i = c0[0]; i <= c1[0]; ++i)
          entries.push_back(
              {(static_cast<std::int64_t>(k) * n[1] + j) * n[0] + i, static_cast<std::int64_t>(f)});
  }
  std::sort(entries.begin(), entries.end());
  // Two faces of different bodies are close when their boxes are within the larger size.
  auto close = [&](std::size_t f, std::size_t g) {
    const double d = std::max(size[f], size[g]);
    for (int i = 0; i < 3; ++i)
      if (box[f].lo[i] > box[g].hi[i] + d || box[g].lo[i] > box[f].hi[i] + d) return false;
    return true;
  };
  // Each face links to the nearest (by centre; the lower index on a tie) of the faces of
  // other bodies close to it: about one link per face of an interface, so that the links
  // between two bodies weigh about as much as the faces along the interface would.
  std::vector<Vec3> centre(nf);
  for (std::size_t f = 0; f < nf; ++f)
    for (int a = 0; a < 4; ++a)
      centre[f] = centre[f] + 0.25 * mesh.nodes[static_cast<std::size_t>(faces.nodes[f][a])];
  std::vector<std::int64_t> nearest(nf, -1);
  std::vector<double> nearest_d2(nf, 0);
  auto offer = [&](std::size_t f, std::size_t g) {
    const Vec3 d = centre[g] - centre[f];
    const double d2 = dot(d, d);
    const auto gi = static_cast<std::int64_t>(g);
    if (nearest[f] < 0 || d2 < nearest_d2[f] || (d2 == nearest_d2[f] && gi < nearest[f])) {
      nearest[f] = gi;
      nearest_d2[f] = d2;
    }
  };
  for (std::size_t b = 0; b < entries.size();) {
    std::size_t e = b;
    while (e < entries.size() && entries[e][0] == entries[b][0]) ++e;
    for (std::size_t i = b; i < e; ++i)
      for (std::size_t j = i + 1; j < e; ++j) {
        const auto f = static_cast<std::size_t>(entries[i][1]),
                   g = static_cast<std::size_t>(entries[j][1]);
        if (body[f] == body[g] || !close(f, g)) continue;
        offer(f, g);
        offer(g, f);
      }
    b = e;
  }
  for (std::size_t f = 0; f < nf; ++f)
    if (nearest[f] >= 0) {
      const std::int64_t a = faces.element[f],
                         c = faces.element[static_cast<std::size_t>(nearest[f])];
      links.push_back({std::min(a, c), std::max(a, c)});
    }
  std::sort(links.begin(), links.end());
  links.erase(std::unique(links.begin(), links.end()), links.end());
  return links;
}

} // namespace anvil
