#include "anvil/parallel/migration.hpp"

#include <algorithm>
#include <cstring>
#include <string>

namespace anvil {

namespace {
// Tags of the two directions (both directions may be in flight on one communicator in
// consecutive calls; MPI keeps messages of one tag and pair in order).
constexpr int kForwardTag = 7301;
constexpr int kReverseTag = 7302;

// dst[k] = src[idx[k]] (gather) or dst[idx[k]] = src[k] (scatter) for k in [0, n), items
// of `size` bytes. Common sizes get a fixed-size copy the compiler turns into moves.
template <std::size_t S>
void permute_fixed(unsigned char* dst, const unsigned char* src, const std::int64_t* idx,
                   std::int64_t n, bool scatter) {
  if (scatter)
    for (std::int64_t k = 0; k < n; ++k) std::memcpy(dst + idx[k] * S, src + k * S, S);
  else
    for (std::int64_t k = 0; k < n; ++k) std::memcpy(dst + k * S, src + idx[k] * S, S);
}
void permute(unsigned char* dst, const unsigned char* src, const std::int64_t* idx, std::int64_t n,
             std::size_t size, bool scatter) {
  switch (size) {
  case 4:
    return permute_fixed<4>(dst, src, idx, n, scatter);
  case 8:
    return permute_fixed<8>(dst, src, idx, n, scatter);
  case 16:
    return permute_fixed<16>(dst, src, idx, n, scatter);
  case 24:
    return permute_fixed<24>(dst, src, idx, n, scatter);
  case 32:
    return permute_fixed<32>(dst, src, idx, n, scatter);
  default:
    if (scatter)
      for (std::int64_t k = 0; k < n; ++k) std::memcpy(dst + idx[k] * size, src + k * size, size);
    else
      for (std::int64_t k = 0; k < n; ++k) std::memcpy(dst + k * size, src + idx[k] * size, size);
  }
}
} // namespace

void Migration::build(const Comm& comm, std::span<const int> dest) {
  comm_ = &comm;
  rank_ = comm.rank();
  position_.clear();
  const int P = comm.size();
  const auto Pz = static_cast<std::size_t>(P);
  scount_.assign(Pz, 0);
  rcount_.assign(Pz, 0);
  sdispl_.assign(Pz + 1, 0);
  rdispl_.assign(Pz + 1, 0);
  std::int64_t bad = 0;
  for (int d : dest) {
    if (d < 0 || d >= P) {
      bad = 1;
      continue;
    }
    ++scount_[static_cast<std::size_t>(d)];
  }
  // The count exchange doubles as the error check: a bad destination anywhere makes every
  // rank throw (a negative count cannot occur otherwise).
  if (bad) scount_.assign(Pz, -1);
  comm.alltoall_bytes(scount_.data(), sizeof(std::int64_t), rcount_.data());
  finish_build(dest, bad != 0);
}

void Migration::count(int ranks, std::span<const int> dest, std::span<std::int64_t> counts) {
  std::fill(counts.begin(), counts.end(), 0);
  for (int d : dest) {
    if (d < 0 || d >= ranks) {
      std::fill(counts.begin(), counts.end(), -1);
      return;
    }
    ++counts[static_cast<std::size_t>(d)];
  }
}

void Migration::build(const Comm& comm, std::span<const int> dest,
                      std::span<const std::int64_t> recv_counts) {
  comm_ = &comm;
  rank_ = comm.rank();
  position_.clear();
  const auto Pz = static_cast<std::size_t>(comm.size());
  scount_.resize(Pz);
  count(comm.size(), dest, scount_);
  const bool bad = !scount_.empty() && scount_[0] < 0;
  rcount_.assign(recv_counts.begin(), recv_counts.end());
  sdispl_.assign(Pz + 1, 0);
  rdispl_.assign(Pz + 1, 0);
  finish_build(dest, bad);
}

void Migration::finish_build(std::span<const int> dest, bool bad) {
  const auto Pz = rcount_.size();
  const int P = static_cast<int>(Pz);
  // Every rank receives the -1 of a rank with a bad destination: no reduction is needed.
  bool any_bad = bad;
  for (std::int64_t c : rcount_) any_bad |= c < 0;
  if (any_bad)
    throw std::invalid_argument("Migration::build: destination rank out of range on some rank");

  for (std::size_t q = 0; q < Pz; ++q) {
    sdispl_[q + 1] = sdispl_[q] + scount_[q];
    rdispl_[q + 1] = rdispl_[q] + rcount_[q];
  }
  recv_total_ = static_cast<std::size_t>(rdispl_[Pz]);
  // Stable counting sort by destination: within a group, items keep their index order.
  order_.resize(dest.size());
  for (std::size_t q = 0; q < Pz; ++q) scount_[q] = sdispl_[q]; // cursors
  for (std::size_t i = 0; i < dest.size(); ++i)
    order_[static_cast<std::size_t>(scount_[static_cast<std::size_t>(dest[i])]++)] =
        static_cast<std::int64_t>(i);
  for (std::size_t q = 0; q < Pz; ++q) scount_[q] = sdispl_[q + 1] - sdispl_[q];
  peers_.clear();
  for (int q = 0; q < P; ++q)
    if (q != rank_ &&
        (scount_[static_cast<std::size_t>(q)] > 0 || rcount_[static_cast<std::size_t>(q)] > 0))
      peers_.push_back(q);
}

void Migration::build_subset(const Migration& base, std::span<const char> send_keep,
                             std::span<const char> recv_keep) {
  if (!base.comm_) throw std::logic_error("Migration::build_subset: base was not built");
  if (send_keep.size() != base.send_count() || recv_keep.size() != base.recv_count())
    throw std::invalid_argument("Migration::build_subset: marks do not match the base plan");
  comm_ = base.comm_;
  rank_ = base.rank_;
  const std::size_t Pz = base.scount_.size();
  scount_.assign(Pz, 0);
  rcount_.assign(Pz, 0);
  sdispl_.assign(Pz + 1, 0);
  rdispl_.assign(Pz + 1, 0);
  // base's groups filtered: the kept items of each destination, in base's order.
  order_.clear();
  position_.clear();
  order_.reserve(base.order_.size()); // a subset never outgrows its base
  position_.reserve(base.recv_total_);
  for (std::size_t q = 0; q < Pz; ++q) {
    for (std::int64_t k = base.sdispl_[q]; k < base.sdispl_[q + 1]; ++k) {
      const std::int64_t i = base.order_[static_cast<std::size_t>(k)];
      if (send_keep[static_cast<std::size_t>(i)] != 0) order_.push_back(i);
    }
    for (std::int64_t j = base.rdispl_[q]; j < base.rdispl_[q + 1]; ++j)
      if (recv_keep[static_cast<std::size_t>(j)] != 0) position_.push_back(j);
    sdispl_[q + 1] = static_cast<std::int64_t>(order_.size());
    rdispl_[q + 1] = static_cast<std::int64_t>(position_.size());
    scount_[q] = sdispl_[q + 1] - sdispl_[q];
    rcount_[q] = rdispl_[q + 1] - rdispl_[q];
  }
  recv_total_ = position_.size();
  peers_.clear();
  for (int q : base.peers_)
    if (scount_[static_cast<std::size_t>(q)] > 0 || rcount_[static_cast<std::size_t>(q)] > 0)
      peers_.push_back(q);
}

void Migration::post_receives(void* out_v, std::size_t size) {
  if (!comm_) throw std::logic_error("Migration: build() was not called");
  auto* out = static_cast<unsigned char*>(out_v);
  for (int q : peers_) {
    const auto qz = static_cast<std::size_t>(q);
    if (rcount_[qz] > 0)
      comm_->irecv_bytes(out + rdispl_[qz] * size, rcount_[qz] * size, q, kForwardTag, requests_);
  }
}

void Migration::send_group(int q, const void* data, std::size_t size) {
  const auto qz = static_cast<std::size_t>(q);
  comm_->isend_bytes(data, scount_[qz] * size, q, kForwardTag, requests_);
}

void Migration::move_bytes(const void* in_v, void* out_v, std::size_t size, bool reverse) {
  if (!comm_) throw std::logic_error("Migration: build() was not called");
  const auto* in = static_cast<const unsigned char*>(in_v);
  auto* out = static_cast<unsigned char*>(out_v);
  const auto me = static_cast<std::size_t>(rank_);
  // The packed side (forward: what we send; reverse: what we receive) lives in buffer_ in
  // order_'s layout; the other side is the caller's received-layout array itself.
  const std::size_t need = order_.size() * size;
  if (buffer_.size() < need) buffer_.resize(need);
  unsigned char* buf = buffer_.data();
  const int tag = reverse ? kReverseTag : kForwardTag;

  if (!reverse) {
    for (int q : peers_) {
      const auto qz = static_cast<std::size_t>(q);
      if (rcount_[qz] > 0)
        comm_->irecv_bytes(out + rdispl_[qz] * size, rcount_[qz] * size, q, tag, requests_);
    }
    for (int q : peers_) {
      const auto qz = static_cast<std::size_t>(q);
      if (scount_[qz] == 0) continue;
      permute(buf + sdispl_[qz] * size, in, order_.data() + sdispl_[qz], scount_[qz], size, false);
      comm_->isend_bytes(buf + sdispl_[qz] * size, scount_[qz] * size, q, tag, requests_);
    }
    permute(out + rdispl_[me] * size, in, order_.data() + sdispl_[me], scount_[me], size, false);
    requests_.wait();
  } else {
    for (int q : peers_) {
      const auto qz = static_cast<std::size_t>(q);
      if (scount_[qz] > 0)
        comm_->irecv_bytes(buf + sdispl_[qz] * size, scount_[qz] * size, q, tag, requests_);
    }
    for (int q : peers_) {
      const auto qz = static_cast<std::size_t>(q);
      if (rcount_[qz] > 0)
        comm_->isend_bytes(in + rdispl_[qz] * size, rcount_[qz] * size, q, tag, requests_);
    }
    permute(out, in + rdispl_[me] * size, order_.data() + sdispl_[me], scount_[me], size, true);
    requests_.wait();
    for (int q : peers_) {
      const auto qz = static_cast<std::size_t>(q);
      permute(out, buf + sdispl_[qz] * size, order_.data() + sdispl_[qz], scount_[qz], size, true);
    }
  }
}

} // namespace anvil
