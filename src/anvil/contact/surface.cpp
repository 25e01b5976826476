#include "anvil/contact/surface.hpp"

#include <algorithm>

namespace anvil {

ExteriorFaces exterior_faces(const Mesh& mesh, const std::vector<bool>& selected) {
  // Sort every face of every element by its sorted node ids; a key seen once is exterior.
  struct Key {
    std::array<std::int64_t, 4> sorted;
    std::int64_t element;
    int side;
  };
  std::vector<Key> keys;
  keys.reserve(static_cast<std::size_t>(mesh.num_elements()) * 6);
  std::int64_t e = 0;
  for (const auto& b : mesh.blocks)
    for (const auto& h : b.elements) {
      for (int s = 0; s < 6; ++s) {
        Key k{
            {h[hex_faces[s][0]], h[hex_faces[s][1]], h[hex_faces[s][2]], h[hex_faces[s][3]]}, e, s};
        std::sort(k.sorted.begin(), k.sorted.end());
        keys.push_back(k);
      }
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
  std::vector<std::pair<std::int64_t, int>> exterior;
  for (std::size_t i = 0; i < keys.size();) {
    std::size_t j = i + 1;
    while (j < keys.size() && keys[j].sorted == keys[i].sorted) ++j;
    if (j == i + 1 && selected[block_of(keys[i].element)])
      exterior.emplace_back(keys[i].element, keys[i].side);
    i = j;
  }
  std::sort(exterior.begin(), exterior.end());

  // Element connectivity by global element id.
  std::vector<const Hex*> hex;
  hex.reserve(static_cast<std::size_t>(mesh.num_elements()));
  for (const auto& b : mesh.blocks)
    for (const auto& h : b.elements) hex.push_back(&h);
  ExteriorFaces out;
  for (const auto& [el, s] : exterior) {
    const Hex& h = *hex[el];
    out.element.push_back(el);
    out.side.push_back(s);
    out.nodes.push_back(
        {h[hex_faces[s][0]], h[hex_faces[s][1]], h[hex_faces[s][2]], h[hex_faces[s][3]]});
    for (int a = 0; a < 4; ++a) out.contact_nodes.push_back(out.nodes.back()[a]);
  }
  std::sort(out.contact_nodes.begin(), out.contact_nodes.end());
  out.contact_nodes.erase(std::unique(out.contact_nodes.begin(), out.contact_nodes.end()),
                          out.contact_nodes.end());
  return out;
}

} // namespace anvil
