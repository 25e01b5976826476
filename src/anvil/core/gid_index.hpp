// Local index of a global id: an open-addressing hash table (linear probing, Fibonacci
// hashing), built once, for lookups in hot loops where a binary search over a sorted id
// list costs a dozen dependent, unpredictable steps.
#pragma once

#include <bit>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace anvil {

class GidIndex {
public:
  GidIndex() = default;
  // ids[k] -> k; the ids must be distinct.
  explicit GidIndex(std::span<const std::int64_t> ids) {
    const std::size_t size = std::bit_ceil(std::max<std::size_t>(2 * ids.size(), 16));
    shift_ = 64 - std::countr_zero(size);
    mask_ = size - 1;
    slots_.assign(size, Slot{});
    for (std::size_t k = 0; k < ids.size(); ++k) {
      std::size_t s = home(ids[k]);
      while (slots_[s].id != empty) s = (s + 1) & mask_;
      slots_[s] = {ids[k], static_cast<int>(k)};
    }
  }
  // The index of id, or -1 when it is not in the table.
  int find(std::int64_t id) const {
    if (slots_.empty()) return -1;
    for (std::size_t s = home(id);; s = (s + 1) & mask_) {
      if (slots_[s].id == id) return slots_[s].index;
      if (slots_[s].id == empty) return -1;
    }
  }

private:
  static constexpr std::int64_t empty = std::numeric_limits<std::int64_t>::min();
  struct Slot {
    std::int64_t id = empty;
    int index = -1;
  };
  std::size_t home(std::int64_t id) const {
    return static_cast<std::size_t>((static_cast<std::uint64_t>(id) * 0x9E3779B97F4A7C15ull) >>
                                    shift_);
  }
  std::vector<Slot> slots_;
  int shift_ = 64;
  std::size_t mask_ = 0;
};

} // namespace anvil
