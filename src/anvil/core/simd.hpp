// The vector type the hot kernels are written in: `width` doubles processed together,
// one lane per element (or particle). Arithmetic is IEEE per lane; every element goes
// through the same vector instructions (arrays are padded to whole vectors), which is
// what keeps results independent of the partition.
#pragma once

#include <experimental/simd>

namespace anvil::simd {

namespace stdx = std::experimental;

// The target's native vector of doubles (4 with AVX2, 8 with AVX-512): measured faster
// here than two native vectors per value (fixed_size_simd<double, 8>).
using vdouble = stdx::native_simd<double>;
using vmask = stdx::native_simd_mask<double>;
inline constexpr int width = static_cast<int>(vdouble::size());

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

// v <- (m ? v : other) per lane; the scalar overload lets one template serve a vector
// body and its scalar remainder.
inline void keep_where(const vmask& m, vdouble& v, double other) {
  stdx::where(!m, v) = other;
}
inline void keep_where(bool m, double& v, double other) {
  if (!m) v = other;
}

} // namespace anvil::simd

namespace anvil::simd {
// Arrays of per-element data are padded to whole vectors so that kernels never need a
// scalar tail: the padding repeats the last element.
inline constexpr int padded_size(int n) {
  return (n + width - 1) / width * width;
}
} // namespace anvil::simd
