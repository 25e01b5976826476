#include "anvil/parallel/graph_partition.hpp"

#include <metis.h>

#include <algorithm>
#include <map>
#include <numeric>
#include <stdexcept>

namespace anvil {

std::vector<int> partition_elements(const Mesh& mesh, int parts, std::span<const int> block_weight,
                                    std::span<const std::array<std::int64_t, 2>> links) {
  const auto ne = mesh.num_elements();
  std::vector<int> out(static_cast<std::size_t>(ne), 0);
  if (parts <= 1 || ne == 0) return out;
  if (ne <= parts) {
    std::iota(out.begin(), out.end(), 0);
    return out;
  }
  if (!block_weight.empty() && block_weight.size() != mesh.blocks.size())
    throw std::invalid_argument("partition_elements: one weight per block expected");
  std::vector<idx_t> eptr(static_cast<std::size_t>(ne) + 1), eind, vwgt;
  eind.reserve(static_cast<std::size_t>(ne) * 8);
  if (!block_weight.empty()) vwgt.reserve(static_cast<std::size_t>(ne));
  // Each element's distinct nodes: wedges, pyramids and tetrahedra (hexahedra whose
  // nodes repeat) share triangles, 3 nodes, with their neighbours; two elements that
  // share 3 nodes share a face, since hexahedra share 4 or at most 2.
  bool triangles = false;
  std::size_t e = 0;
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b)
    for (const auto& h : mesh.blocks[b].elements) {
      eptr[e++] = static_cast<idx_t>(eind.size());
      for (int a = 0; a < 8; ++a)
        if (std::find(h.begin(), h.begin() + a, h[a]) == h.begin() + a)
          eind.push_back(static_cast<idx_t>(h[a]));
        else
          triangles = true;
      if (!block_weight.empty()) vwgt.push_back(static_cast<idx_t>(std::max(1, block_weight[b])));
    }
  eptr[e] = static_cast<idx_t>(eind.size());
  idx_t n_el = static_cast<idx_t>(ne), n_nodes = static_cast<idx_t>(mesh.num_nodes());
  idx_t ncommon = triangles ? 3 : 4, nparts = parts, objval = 0;
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_NUMBERING] = 0;
  options[METIS_OPTION_SEED] = 12345;
  // Parts within 0.5% of the mean weight (METIS's default for k-way is 3%: on 2 ranks one
  // could wait 6% of the FE phase for the other); the cut barely grows.
  options[METIS_OPTION_UFACTOR] = 5;
  std::vector<idx_t> epart(static_cast<std::size_t>(ne));
  // The dual graph (what METIS_PartMeshDual partitions), then the links added to it.
  idx_t numflag = 0, *xadj = nullptr, *adjncy = nullptr;
  if (METIS_MeshToDual(&n_el, &n_nodes, eptr.data(), eind.data(), &ncommon, &numflag, &xadj,
                       &adjncy) != METIS_OK)
    throw std::runtime_error("METIS_MeshToDual failed");
  std::vector<idx_t> ptr(xadj, xadj + n_el + 1), adj(adjncy, adjncy + xadj[n_el]);
  METIS_Free(xadj);
  METIS_Free(adjncy);
  // With links (about one per face of an interface), a face between elements weighs 20
  // and a link 1: METIS is to cut along an interface, through its links, before it cuts
  // through a body, through its faces (QA round 35: with every close pair linked and
  // equal weights, two bodies stacked face to face were cut across both, 6-10 times the
  // cut, and stacks side by side were split). A body that meets another only through
  // links still goes with it: cutting them all costs more than cutting none.
  constexpr idx_t face_weight = 20, link_weight = 1;
  std::vector<idx_t> wgt;
  if (!links.empty()) {
    std::vector<std::vector<idx_t>> extra(static_cast<std::size_t>(ne));
    for (const auto& [a, b] : links) {
      if (a == b || a < 0 || b < 0 || a >= ne || b >= ne) continue;
      extra[static_cast<std::size_t>(a)].push_back(static_cast<idx_t>(b));
      extra[static_cast<std::size_t>(b)].push_back(static_cast<idx_t>(a));
    }
    // (A link joins elements of different bodies, which share no node: never two elements
    // with a face between them.)
    std::vector<idx_t> ptr2(ptr.size()), adj2;
    adj2.reserve(adj.size() + 2 * links.size());
    wgt.reserve(adj.size() + 2 * links.size());
    for (std::size_t e = 0; e < static_cast<std::size_t>(ne); ++e) {
      ptr2[e] = static_cast<idx_t>(adj2.size());
      adj2.insert(adj2.end(), adj.begin() + ptr[e], adj.begin() + ptr[e + 1]);
      wgt.insert(wgt.end(), static_cast<std::size_t>(ptr[e + 1] - ptr[e]), face_weight);
      std::sort(extra[e].begin(), extra[e].end());
      extra[e].erase(std::unique(extra[e].begin(), extra[e].end()), extra[e].end());
      adj2.insert(adj2.end(), extra[e].begin(), extra[e].end());
      wgt.insert(wgt.end(), extra[e].size(), link_weight);
    }
    ptr2[static_cast<std::size_t>(ne)] = static_cast<idx_t>(adj2.size());
    ptr.swap(ptr2);
    adj.swap(adj2);
  }
  idx_t ncon = 1;
  const int rc = METIS_PartGraphKway(&n_el, &ncon, ptr.data(), adj.data(),
                                     vwgt.empty() ? nullptr : vwgt.data(), nullptr,
                                     wgt.empty() ? nullptr : wgt.data(), &nparts, nullptr, nullptr,
                                     options, &objval, epart.data());
  if (rc != METIS_OK) throw std::runtime_error("METIS_PartGraphKway failed");
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<int>(epart[i]);
  return out;
}

long long partition_cut(const Mesh& mesh, const std::vector<int>& part) {
  // Faces by face_key; a face seen twice joins two elements.
  std::map<FaceKey, std::int64_t> faces;
  long long cut = 0;
  std::int64_t e = 0;
  for (const auto& b : mesh.blocks)
    for (const auto& h : b.elements) {
      for (int f = 0; f < 6; ++f) {
        const FaceKey k = face_key(h, f);
        if (!is_face(k)) continue;
        auto [it, fresh] = faces.emplace(k, e);
        if (!fresh && part[it->second] != part[e]) ++cut;
      }
      ++e;
    }
  return cut;
}

} // namespace anvil
