// Migration: a reusable plan that moves items (structure-of-arrays fields) from the ranks
// that hold them to new owners, and results back along the same plan in reverse. Built
// from one destination rank per local item (e.g. Rcb::destinations()); used every cycle
// for FE -> contact -> FE and for SPH particles.
//
// Order. After forward(), the received items are ordered by source rank, then by their
// index on the source (so the layout is deterministic and independent of timing).
// reverse() returns each item to its original rank and original position.
//
// Communication. build() exchanges one count per rank pair (MPI all-to-all of counts;
// or the caller passes them), then every move sends one message per field to each rank that has
// items for it and to no other (sparse). Items that stay on this rank are copied, not sent.
//
// Subsets. build_subset() makes, without communication, a plan that moves only the items
// marked on both sides of a built plan (for example what the receivers still need, the
// marks sent back with reverse()), into a compact layout mapped onto the full one.
//
// Memory. The plan keeps its buffers: once they have grown to the largest field moved,
// build(), forward() and reverse() allocate nothing (rebuilding for new destinations
// reuses them too).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "anvil/parallel/comm.hpp"

namespace anvil {

class Migration {
public:
  Migration() = default;

  // Builds the plan: local item i goes to rank dest[i] (0 <= dest[i] < comm.size()).
  // Collective over comm, which must outlive the plan's use.
  void build(const Comm& comm, std::span<const int> dest);
  // The same without communication, for a caller that already has the counts: recv_counts[q]
  // is the number of items rank q sends here (rank q's count() for this rank), for example
  // from a collective it makes anyway. A -1 there (count() of a bad destination) makes
  // this rank throw, as build() does everywhere.
  void build(const Comm& comm, std::span<const int> dest,
             std::span<const std::int64_t> recv_counts);
  // counts[q] = items of dest going to rank q (ranks entries); every entry -1 when some
  // destination is out of range.
  static void count(int ranks, std::span<const int> dest, std::span<std::int64_t> counts);
  // Builds this plan as the part of `base` that moves only some items: local item i of
  // base when send_keep[i] != 0, arriving at base's received position j when
  // recv_keep[j] != 0. Sender and receiver must mark the same items (for example, the
  // receiver's marks sent back along base.reverse()); nothing is exchanged to check it.
  // forward() then fills a compact layout (source rank, then source index, as base's),
  // whose item j belongs at base's received position base_position(j). Local; base must
  // stay built while this plan is used, and a rebuild of base needs a new subset.
  void build_subset(const Migration& base, std::span<const char> send_keep,
                    std::span<const char> recv_keep);
  // Grows the send buffer to `bytes` now (e.g. a subset's largest move, its base's item
  // count times the item size), so that later moves of up to that size allocate nothing.
  void reserve(std::size_t bytes) {
    if (buffer_.size() < bytes) buffer_.resize(bytes);
  }
  // Subset plans: base's received position of this plan's received item j.
  std::size_t base_position(std::size_t j) const { return static_cast<std::size_t>(position_[j]); }

  std::size_t send_count() const { return order_.size(); } // items held before (dest.size())
  std::size_t recv_count() const { return recv_total_; }   // items held after forward()
  // True when every item stays on this rank and none arrives: forward() and reverse() are
  // then plain copies in the same order, which a caller may skip.
  bool stays() const { return comm_ != nullptr && peers_.empty(); }
  // Items forward() sends to other ranks (send_count() less those that stay here).
  std::size_t sent_elsewhere() const {
    return comm_
               ? order_.size() - static_cast<std::size_t>(scount_[static_cast<std::size_t>(rank_)])
               : 0;
  }
  // Items received from `rank`, and where they start in the received layout.
  std::size_t recv_count(int rank) const { return static_cast<std::size_t>(rcount_[rank]); }
  std::size_t recv_offset(int rank) const { return static_cast<std::size_t>(rdispl_[rank]); }

  // Moves one field to the new owners: in has send_count() items in the original order,
  // out receives recv_count() items (source rank, then source index). Collective.
  template <class T>
  void forward(std::span<const T> in, std::span<T> out) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (in.size() != send_count() || out.size() != recv_count())
      throw std::invalid_argument("Migration::forward: field sizes do not match the plan");
    move_bytes(in.data(), out.data(), sizeof(T), false);
  }
  template <class T>
  void forward(const std::vector<T>& in, std::vector<T>& out) {
    out.resize(recv_count());
    forward(std::span<const T>(in), std::span<T>(out));
  }

  // Like forward(), without an input array: pack(i, T& item) writes local item i (0 <= i <
  // send_count()) straight into its place, the send buffer of its rank or, for items that
  // stay, out itself. Each item is written once and moved no further (forward() copies it
  // twice when it stays: into the input, then into out). Collective.
  template <class T, class Pack>
  void forward_packed(std::span<T> out, Pack&& pack) {
    forward_packed(out, pack, [&](std::size_t i, std::size_t j) { pack(i, out[j]); });
  }
  template <class T, class Pack>
  void forward_packed(std::vector<T>& out, Pack&& pack) {
    out.resize(recv_count());
    forward_packed(std::span<T>(out), std::forward<Pack>(pack));
  }
  // Like forward_packed(), but the items that stay on this rank are not written: stay(i, j)
  // is called instead for each, with its local index i and its received position j (its
  // place in out, which stays untouched there), so that the caller can use the item where
  // it is. pack() writes only the items for other ranks. Collective.
  template <class T, class Pack, class Stay>
  void forward_packed(std::span<T> out, Pack&& pack, Stay&& stay) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (out.size() != recv_count())
      throw std::invalid_argument("Migration::forward_packed: out does not match the plan");
    const std::size_t need = order_.size() * sizeof(T);
    if (buffer_.size() < need) buffer_.resize(need);
    T* buf = reinterpret_cast<T*>(buffer_.data());
    post_receives(out.data(), sizeof(T));
    for (int q : peers_) {
      const auto qz = static_cast<std::size_t>(q);
      if (scount_[qz] == 0) continue;
      const std::int64_t* idx = order_.data() + sdispl_[qz];
      T* dst = buf + sdispl_[qz];
      for (std::int64_t k = 0; k < scount_[qz]; ++k) pack(static_cast<std::size_t>(idx[k]), dst[k]);
      send_group(q, dst, sizeof(T));
    }
    const auto me = static_cast<std::size_t>(rank_);
    const std::int64_t* idx = order_.data() + sdispl_[me];
    for (std::int64_t k = 0; k < scount_[me]; ++k)
      stay(static_cast<std::size_t>(idx[k]), static_cast<std::size_t>(rdispl_[me] + k));
    requests_.wait();
  }
  template <class T, class Pack, class Stay>
  void forward_packed(std::vector<T>& out, Pack&& pack, Stay&& stay) {
    out.resize(recv_count());
    forward_packed(std::span<T>(out), std::forward<Pack>(pack), std::forward<Stay>(stay));
  }

  // Moves one field back: in has recv_count() items in the received layout, out gets
  // send_count() items at the original positions. Collective.
  template <class T>
  void reverse(std::span<const T> in, std::span<T> out) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (in.size() != recv_count() || out.size() != send_count())
      throw std::invalid_argument("Migration::reverse: field sizes do not match the plan");
    move_bytes(in.data(), out.data(), sizeof(T), true);
  }
  template <class T>
  void reverse(const std::vector<T>& in, std::vector<T>& out) {
    out.resize(send_count());
    reverse(std::span<const T>(in), std::span<T>(out));
  }

private:
  // Moves items of `size` bytes forward or in reverse (see above).
  void move_bytes(const void* in, void* out, std::size_t size, bool reverse);
  // forward_packed's messages: receives from every peer into out (received layout), and
  // the send of rank q's group, packed at data.
  void post_receives(void* out, std::size_t size);
  void send_group(int q, const void* data, std::size_t size);
  // build()'s part after the counts (scount_, rcount_): the error check, displacements,
  // order and peers.
  void finish_build(std::span<const int> dest, bool bad);

  const Comm* comm_ = nullptr;
  int rank_ = 0;
  std::vector<std::int64_t> order_;    // local item indices grouped by destination rank
  std::vector<std::int64_t> scount_;   // items to each rank
  std::vector<std::int64_t> sdispl_;   // start of each rank's group in order_ (size P + 1)
  std::vector<std::int64_t> rcount_;   // items from each rank
  std::vector<std::int64_t> rdispl_;   // start of each rank's items in the received layout
  std::vector<int> peers_;             // ranks other than this one with items to or from us
  std::size_t recv_total_ = 0;         // items received, this rank included
  std::vector<std::int64_t> position_; // subset plans: base's received position of each item
  std::vector<unsigned char> buffer_;  // packed items for other ranks (grows, never shrinks)
  Requests requests_;                  // reused, so moves allocate nothing
};

} // namespace anvil
