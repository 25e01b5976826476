// An allocator for large scratch arrays that asks the kernel for transparent huge pages
// (2 MB, by madvise: honoured where the system's setting is `madvise` or `always`): arrays
// read at scattered places over megabytes (the SPH passes' neighbour records) then need
// far fewer TLB entries. Arrays under 2 MB come from operator new as usual (64-byte
// aligned). No state: any two instances are interchangeable.
#pragma once

#include <cstddef>
#include <new>
#include <vector>

#include <sys/mman.h>

namespace anvil {

template <class T>
struct HugePageAllocator {
  using value_type = T;
  static constexpr std::size_t huge = std::size_t(1) << 21;
  static constexpr std::align_val_t align{alignof(T) > 64 ? alignof(T) : 64};

  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
    if (bytes < huge) return static_cast<T*>(::operator new(bytes, align));
    // Through the aligned operator new (not aligned_alloc directly), so that a replaced
    // operator new sees it too (tests/mpi/allocation_counter.hpp).
    const std::size_t rounded = (bytes + huge - 1) / huge * huge;
    void* p = ::operator new (rounded, std::align_val_t{huge});
#ifdef MADV_HUGEPAGE
    madvise(p, rounded, MADV_HUGEPAGE); // advice only: its failure changes nothing
#endif
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) noexcept {
    if (n * sizeof(T) < huge)
      ::operator delete(p, align);
    else
      ::operator delete (p, std::align_val_t{huge});
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
};

// A vector whose storage, from 2 MB up, lies on huge pages.
template <class T>
using HugePageVector = std::vector<T, HugePageAllocator<T>>;

} // namespace anvil
