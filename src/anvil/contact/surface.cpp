#include "anvil/contact/surface.hpp"

#include <algorithm>

namespace anvil {

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

} // namespace anvil
