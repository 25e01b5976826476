// The vector type the hot kernels are written in: `width` doubles processed together,
// one lane per element (or particle). std::experimental::simd lowers it to AVX2/AVX-512
// as available; arithmetic is IEEE per lane, so vector and scalar code give the same bits
// (no FMA contraction: see the top-level CMakeLists).
#pragma once

#include <experimental/simd>

namespace anvil::simd {

namespace stdx = std::experimental;

inline constexpr int width = 8;
using vdouble = stdx::fixed_size_simd<double, width>;
using vmask = stdx::fixed_size_simd_mask<double, width>;

// Loads lane l from p[idx[l]].
template <class Index>
inline vdouble gather(const double* p, const Index* idx) {
  return vdouble([&](auto l) { return p[idx[l]]; });
}

inline vdouble load(const double* p) {
  return vdouble(p, stdx::element_aligned);
}
inline void store(const vdouble& v, double* p) {
  v.copy_to(p, stdx::element_aligned);
}

} // namespace anvil::simd

namespace anvil::simd {
// Arrays of per-element data are padded to whole vectors so that kernels never need a
// scalar tail: the padding repeats the last element.
inline constexpr int padded_size(int n) {
  return (n + width - 1) / width * width;
}
} // namespace anvil::simd
