// Migration: a reusable plan that moves items (structure-of-arrays fields) from the ranks
// that hold them to new owners, and results back along the same plan in reverse. Built
// from one destination rank per local item (e.g. Rcb::destinations()); used every cycle
// for FE -> contact -> FE and for SPH particles.
//
// Order. After forward(), the received items are ordered by source rank, then by their
// index on the source (so the layout is deterministic and independent of timing).
// reverse() returns each item to its original rank and original position.
//
// Communication. build() exchanges one count per rank pair (MPI all-to-all of counts),
// then every move sends one message per field to each rank that has items for it and to
// no other (sparse). Items that stay on this rank are copied, not sent.
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
#include <vector>

#include "anvil/parallel/comm.hpp"

namespace anvil {

class Migration {
public:
  Migration() = default;

  // Builds the plan: local item i goes to rank dest[i] (0 <= dest[i] < comm.size()).
  // Collective over comm, which must outlive the plan's use.
  void build(const Comm& comm, std::span<const int> dest);

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

  const Comm* comm_ = nullptr;
  int rank_ = 0;
  std::vector<std::int64_t> order_;   // local item indices grouped by destination rank
  std::vector<std::int64_t> scount_;  // items to each rank
  std::vector<std::int64_t> sdispl_;  // start of each rank's group in order_ (size P + 1)
  std::vector<std::int64_t> rcount_;  // items from each rank
  std::vector<std::int64_t> rdispl_;  // start of each rank's items in the received layout
  std::vector<int> peers_;            // ranks other than this one with items to or from us
  std::size_t recv_total_ = 0;        // items received, this rank included
  std::vector<unsigned char> buffer_; // packed items for other ranks (grows, never shrinks)
  Requests requests_;                 // reused, so moves allocate nothing
};

} // namespace anvil
