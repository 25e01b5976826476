// Counts the C++ allocations of a test executable (MPI's own mallocs are not counted):
// replaces the global operator new and delete, plain and aligned. Include it in exactly one source
// file of an executable; tests read g_allocations before and after the code they measure.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>

std::size_t g_allocations = 0;

void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
// Over-aligned types (alignas(64) records, huge-page arrays) come through these.
void* operator new(std::size_t n, std::align_val_t a) {
  ++g_allocations;
  const auto al = static_cast<std::size_t>(a);
  if (void* p = std::aligned_alloc(al, (n + al - 1) / al * al)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
