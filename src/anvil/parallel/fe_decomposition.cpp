#include "anvil/parallel/fe_decomposition.hpp"

#include <algorithm>
#include <map>
#include <stdexcept>

#include "anvil/core/simd.hpp"

namespace anvil {

std::int64_t FeDecomposition::num_elements() const {
  std::int64_t n = 0;
  for (const auto& b : blocks) n += static_cast<std::int64_t>(b.gid.size());
  return n;
}

std::int64_t FeDecomposition::num_owned_nodes() const {
  return std::count(node_owned.begin(), node_owned.end(), std::uint8_t{1});
}

FeDecomposition decompose_fe(const Mesh& mesh, const std::vector<int>& owner, int rank, int ranks) {
  FeDecomposition d;
  d.rank = rank;
  d.ranks = ranks;
  const auto nn = mesh.num_nodes();
  const auto ne = mesh.num_elements();
  if (static_cast<std::int64_t>(owner.size()) != ne) throw std::logic_error("owner size mismatch");

  // Global corner lists per node (CSR), in ascending (element gid, corner).
  std::vector<std::int64_t> ptr(static_cast<std::size_t>(nn) + 1, 0);
  std::vector<const Hex*> hex(static_cast<std::size_t>(ne));
  {
    std::int64_t e = 0;
    for (const auto& b : mesh.blocks)
      for (const auto& h : b.elements) {
        hex[e++] = &h;
        for (auto n : h) ++ptr[n + 1];
      }
  }
  for (std::int64_t i = 0; i < nn; ++i) ptr[i + 1] += ptr[i];
  std::vector<std::int64_t> corner(static_cast<std::size_t>(ptr[nn])); // e * 8 + a
  {
    std::vector<std::int64_t> fill(ptr.begin(), ptr.end() - 1);
    for (std::int64_t e = 0; e < ne; ++e)
      for (int a = 0; a < 8; ++a) corner[fill[(*hex[e])[a]]++] = e * 8 + a;
  }

  // Which ranks touch each node: local nodes are those we touch.
  std::vector<int> g2l(static_cast<std::size_t>(nn), -1);
  auto touches = [&](std::int64_t n, int r) {
    for (auto p = ptr[n]; p < ptr[n + 1]; ++p)
      if (owner[corner[p] / 8] == r) return true;
    return false;
  };
  // The holder groups: first one per rank (a node only it holds), then each set of two or
  // more ranks that hold a node, in ascending id of the first node they hold together.
  // Every rank lists every node, so every rank builds the same table.
  d.holder_start.assign(1, 0);
  d.holder_ranks.clear();
  for (int r = 0; r < ranks; ++r) {
    d.holder_ranks.push_back(r);
    d.holder_start.push_back(r + 1);
  }
  std::map<std::vector<int>, int> group_of; // (set-up only)
  std::vector<int> set;
  for (std::int64_t n = 0; n < nn; ++n) {
    set.clear();
    for (auto p = ptr[n]; p < ptr[n + 1]; ++p) set.push_back(owner[corner[p] / 8]);
    std::sort(set.begin(), set.end());
    set.erase(std::unique(set.begin(), set.end()), set.end());
    int group = set.empty() ? -1 : set[0];
    if (set.size() > 1) {
      const auto [it, added] = group_of.emplace(set, static_cast<int>(d.holder_start.size()) - 1);
      if (added) {
        d.holder_ranks.insert(d.holder_ranks.end(), set.begin(), set.end());
        d.holder_start.push_back(static_cast<int>(d.holder_ranks.size()));
      }
      group = it->second;
    }
    if (std::binary_search(set.begin(), set.end(), rank)) { // the ranks that touch it
      g2l[n] = static_cast<int>(d.node_gid.size());
      d.node_gid.push_back(n);
      d.node_owned.push_back(set[0] == rank ? 1 : 0); // the lowest toucher owns it
      d.node_holders.push_back(group);
    }
  }

  // Owned elements per block and their corner slots.
  std::vector<std::int64_t> local_index(static_cast<std::size_t>(ne), -1); // within block
  std::vector<int> block_of(static_cast<std::size_t>(ne), 0);
  {
    std::int64_t e = 0;
    std::size_t base = 0;
    for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
      FeDecomposition::Block lb;
      for (const auto& h : mesh.blocks[b].elements) {
        block_of[e] = static_cast<int>(b);
        if (owner[e] == rank) {
          local_index[e] = static_cast<std::int64_t>(lb.gid.size());
          lb.gid.push_back(e);
          std::array<int, 8> c;
          for (int a = 0; a < 8; ++a) c[a] = g2l[h[a]];
          lb.conn.push_back(c);
        }
        ++e;
      }
      lb.stride = simd::padded_size(static_cast<int>(lb.gid.size()));
      lb.corner_base = base;
      base += static_cast<std::size_t>(lb.stride) * 8;
      d.blocks.push_back(std::move(lb));
    }
    d.local_slots = base;
  }
  auto local_slot = [&](std::int64_t c) -> std::int64_t {
    const auto e = c / 8;
    const auto& b = d.blocks[block_of[e]];
    return static_cast<std::int64_t>(
        b.slot(static_cast<std::size_t>(local_index[e]), static_cast<int>(c % 8)));
  };

  // Slot of every corner of every local node: local corners directly, remote ones in the
  // order the neighbour sends them: by neighbour rank, then node gid, then corner.
  std::vector<std::int64_t> slot_of(corner.size(), -1);
  for (auto n : d.node_gid)
    for (auto p = ptr[n]; p < ptr[n + 1]; ++p)
      if (owner[corner[p] / 8] == rank) slot_of[p] = local_slot(corner[p]);

  std::vector<int> neighbor_ranks;
  for (auto n : d.node_gid)
    for (auto p = ptr[n]; p < ptr[n + 1]; ++p)
      if (owner[corner[p] / 8] != rank) neighbor_ranks.push_back(owner[corner[p] / 8]);
  std::sort(neighbor_ranks.begin(), neighbor_ranks.end());
  neighbor_ranks.erase(std::unique(neighbor_ranks.begin(), neighbor_ranks.end()),
                       neighbor_ranks.end());

  std::size_t next_remote = d.local_slots;
  for (int q : neighbor_ranks) {
    FeDecomposition::Neighbor nb;
    nb.rank = q;
    nb.recv_base = next_remote;
    for (auto n : d.node_gid) {
      if (!touches(n, q)) continue;
      for (auto p = ptr[n]; p < ptr[n + 1]; ++p) {
        const int o = owner[corner[p] / 8];
        if (o == rank)
          nb.send_slots.push_back(slot_of[p]);
        else if (o == q)
          slot_of[p] = static_cast<std::int64_t>(next_remote++);
      }
    }
    nb.recv_count = next_remote - nb.recv_base;
    for (std::size_t i = 0; i < d.node_gid.size(); ++i)
      if (touches(d.node_gid[i], q)) nb.shared.push_back(static_cast<int>(i));
    d.neighbors.push_back(std::move(nb));
  }
  d.remote_slots = next_remote - d.local_slots;

  d.gather_ptr.assign(d.node_gid.size() + 1, 0);
  for (std::size_t i = 0; i < d.node_gid.size(); ++i) {
    const auto n = d.node_gid[i];
    bool exchanged = false;
    for (auto p = ptr[n]; p < ptr[n + 1]; ++p) {
      d.gather_slot.push_back(slot_of[p]);
      exchanged = exchanged || slot_of[p] >= static_cast<std::int64_t>(d.local_slots);
    }
    d.gather_ptr[i + 1] = static_cast<int>(d.gather_slot.size());
    if (exchanged) d.exchanged_nodes.push_back(static_cast<int>(i));
  }
  std::vector<std::uint8_t> is_exchanged(d.node_gid.size(), 0);
  for (int i : d.exchanged_nodes) is_exchanged[static_cast<std::size_t>(i)] = 1;
  constexpr int W = simd::width;
  for (auto& b : d.blocks) {
    b.exchanged_vectors.assign(static_cast<std::size_t>(b.stride / W), 0);
    for (std::size_t e = 0; e < b.conn.size(); ++e)
      for (int k : b.conn[e])
        if (is_exchanged[static_cast<std::size_t>(k)]) b.exchanged_vectors[e / W] = 1;
  }
  return d;
}

CornerExchange::CornerExchange(const FeDecomposition& d, const Comm& comm, int components)
    : d_(d), comm_(comm), components_(static_cast<std::size_t>(components)) {
  std::size_t ns = 0;
  for (const auto& nb : d.neighbors) ns += nb.send_slots.size();
  send_.resize(ns * components_);
  recv_.resize(d.remote_slots * components_);
}

void CornerExchange::exchange(std::initializer_list<double*> list) {
  start(list);
  finish(list);
}

void CornerExchange::start(std::initializer_list<double*> list) {
  if (d_.neighbors.empty()) return;
  const std::size_t k = list.size();
  if (k > components_) throw std::logic_error("CornerExchange: more arrays than it was built for");
  double* const* arrays = list.begin();
  Requests& req = requests_;
  for (const auto& nb : d_.neighbors) {
    double* r = recv_.data() + (nb.recv_base - d_.local_slots) * k;
    comm_.irecv(std::span<double>(r, nb.recv_count * k), nb.rank, 11, req);
  }
  std::size_t off = 0;
  for (const auto& nb : d_.neighbors) {
    double* s = send_.data() + off;
    for (std::size_t j = 0; j < nb.send_slots.size(); ++j)
      for (std::size_t c = 0; c < k; ++c) s[j * k + c] = arrays[c][nb.send_slots[j]];
    comm_.isend(std::span<const double>(s, nb.send_slots.size() * k), nb.rank, 11, req);
    off += nb.send_slots.size() * k;
  }
}

void CornerExchange::finish(std::initializer_list<double*> list) {
  if (d_.neighbors.empty()) return;
  const std::size_t k = list.size();
  double* const* arrays = list.begin();
  requests_.wait();
  for (std::size_t j = 0; j < d_.remote_slots; ++j)
    for (std::size_t c = 0; c < k; ++c) arrays[c][d_.local_slots + j] = recv_[j * k + c];
}

namespace {

// The gather for K components at once: the slot list is read once per node, and each
// component is summed in slot order (the same bits as K separate passes). The nodes are
// list[0..count) or, with all, every local node.
template <int K>
void gather_components(const FeDecomposition& d, const double* const* corner, double* const* out,
                       bool all, const int* list, std::size_t count) {
  const std::size_t nn = all ? d.node_gid.size() : count;
  const int* ptr = d.gather_ptr.data();
  const std::int64_t* slot = d.gather_slot.data();
  const double* src[K];
  double* dst[K];
  for (int c = 0; c < K; ++c) {
    src[c] = corner[c];
    dst[c] = out[c];
  }
  for (std::size_t j = 0; j < nn; ++j) {
    const std::size_t n = all ? j : static_cast<std::size_t>(list[j]);
    double s[K] = {};
    const int p0 = ptr[n], p1 = ptr[n + 1];
    if (p1 - p0 == 8) { // a node inside a hexahedral mesh: unrolled, the same order
      const std::int64_t* k = slot + p0;
      for (int c = 0; c < K; ++c)
        s[c] = 0.0 + src[c][k[0]] + src[c][k[1]] + src[c][k[2]] + src[c][k[3]] + src[c][k[4]] +
               src[c][k[5]] + src[c][k[6]] + src[c][k[7]]; // (0 + f0) + f1 ... as the loop
    } else {
      for (int p = p0; p < p1; ++p) {
        const std::int64_t k = slot[p];
        for (int c = 0; c < K; ++c) s[c] += src[c][k];
      }
    }
    for (int c = 0; c < K; ++c) dst[c][n] = s[c];
  }
}

} // namespace

namespace {

void gather_list(const FeDecomposition& d, std::initializer_list<const double*> corner,
                 std::initializer_list<double*> out, bool all, const int* list, std::size_t count) {
  if (corner.size() != out.size())
    throw std::invalid_argument("gather_corners: corner and out lists differ in length");
  std::size_t c = 0;
  for (; c + 3 <= corner.size(); c += 3)
    gather_components<3>(d, corner.begin() + c, out.begin() + c, all, list, count);
  for (; c < corner.size(); ++c)
    gather_components<1>(d, corner.begin() + c, out.begin() + c, all, list, count);
}

} // namespace

void gather_corners(const FeDecomposition& d, std::initializer_list<const double*> corner,
                    std::initializer_list<double*> out) {
  gather_list(d, corner, out, true, nullptr, 0);
}

void gather_corners(const FeDecomposition& d, std::initializer_list<const double*> corner,
                    std::initializer_list<double*> out, std::span<const int> nodes) {
  gather_list(d, corner, out, false, nodes.data(), nodes.size());
}

} // namespace anvil
