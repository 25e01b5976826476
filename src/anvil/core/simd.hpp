// The vector type the hot kernels are written in: `width` doubles processed together,
// one lane per element (or particle). Arithmetic is IEEE per lane; every element goes
// through the same vector instructions (arrays are padded to whole vectors), which is
// what keeps results independent of the partition.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <experimental/simd>
#if defined(__AVX__)
#include <immintrin.h>
#endif

namespace anvil::simd {

namespace stdx = std::experimental;

// The target's native vector of doubles (4 with AVX2, 8 with AVX-512): measured faster
// here than two native vectors per value (fixed_size_simd<double, 8>).
using vdouble = stdx::native_simd<double>;
using vmask = stdx::native_simd_mask<double>;
inline constexpr int width = static_cast<int>(vdouble::size());

// Loads lane l from p[idx[l]] (scalar loads and inserts: on this machine AVX2's hardware
// gather measured slower, docs/performance_contact.md).
template <class Index>
inline vdouble gather(const double* p, const Index* idx) {
  return vdouble([&](auto l) { return p[idx[l]]; });
}

// Loads two values per lane from consecutive addresses: first[l] = p[off[l]],
// second[l] = p[off[l] + 1] (an interleaved pair such as a node's x_i and v_i). With AVX:
// four 128-bit loads and two unpacks instead of eight scalar loads and inserts.
inline void gather_pairs(const double* p, const std::ptrdiff_t* off, vdouble& first,
                         vdouble& second) {
#if defined(__AVX__)
  if constexpr (width == 4) {
    const __m256d a = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p + off[0])),
                                           _mm_loadu_pd(p + off[2]), 1); // f0 s0 f2 s2
    const __m256d b = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p + off[1])),
                                           _mm_loadu_pd(p + off[3]), 1); // f1 s1 f3 s3
    first = vdouble(_mm256_unpacklo_pd(a, b));
    second = vdouble(_mm256_unpackhi_pd(a, b));
    return;
  }
#endif
  first = vdouble([&](auto l) { return p[off[l]]; });
  second = vdouble([&](auto l) { return p[off[l] + 1]; });
}

// A compiler barrier: values stored to memory before it are read back from memory after
// it. The kernels use it to end a stage, so that the next one does not keep the previous
// stage's results in registers (and spill them) but reads them as memory operands.
inline void stage_barrier() {
  asm volatile("" ::: "memory");
}

// Unaligned load and store. With AVX, through the intrinsics: the generic copy_from
// sometimes went through a stack temporary (a load, a spill and a reload).
inline vdouble load(const double* p) {
#if defined(__AVX__)
  if constexpr (width == 4) return vdouble(_mm256_loadu_pd(p));
#endif
  return vdouble(p, stdx::element_aligned);
}
inline void store(const vdouble& v, double* p) {
#if defined(__AVX__)
  if constexpr (width == 4) {
    _mm256_storeu_pd(p, static_cast<__m256d>(v));
    return;
  }
#endif
  v.copy_to(p, stdx::element_aligned);
}

// Stores eight vectors as `width` rows of eight: p[8 l + a] = v[a][l] (the element-major
// corner slots: lane l's eight values are contiguous). Moves values, no arithmetic.
// stream: non-temporal stores (p must be 32-byte aligned), for rows that are written
// once and read back only after the whole kernel: they bypass the cache instead of first
// reading every line in; stream_fence() after the last one.
template <bool stream = false>
inline void store_transposed(const vdouble (&v)[8], double* p) {
#if defined(__AVX__)
  if constexpr (width == 4) {
    auto put = [](double* q, __m256d r) {
      if constexpr (stream)
        _mm256_stream_pd(q, r);
      else
        _mm256_storeu_pd(q, r);
    };
    for (int h = 0; h < 2; ++h) { // values 0-3, then 4-7, of every lane
      const __m256d a = static_cast<__m256d>(v[4 * h]), b = static_cast<__m256d>(v[4 * h + 1]);
      const __m256d c = static_cast<__m256d>(v[4 * h + 2]), d = static_cast<__m256d>(v[4 * h + 3]);
      const __m256d ab0 = _mm256_unpacklo_pd(a, b), ab1 = _mm256_unpackhi_pd(a, b);
      const __m256d cd0 = _mm256_unpacklo_pd(c, d), cd1 = _mm256_unpackhi_pd(c, d);
      put(p + 4 * h, _mm256_permute2f128_pd(ab0, cd0, 0x20));
      put(p + 8 + 4 * h, _mm256_permute2f128_pd(ab1, cd1, 0x20));
      put(p + 16 + 4 * h, _mm256_permute2f128_pd(ab0, cd0, 0x31));
      put(p + 24 + 4 * h, _mm256_permute2f128_pd(ab1, cd1, 0x31));
    }
    return;
  }
#endif
  for (int l = 0; l < width; ++l)
    for (int a = 0; a < 8; ++a) p[8 * l + a] = v[a][l];
}

// Orders the non-temporal stores before everything after it (they are weakly ordered).
inline void stream_fence() {
#if defined(__SSE__)
  _mm_sfence();
#endif
}

// Gathers four consecutive doubles from `width` records and transposes them:
// out[a][l] = row[l][a], a = 0..3 (each row[l] 32-byte aligned). Moves values, no
// arithmetic. With AVX: four vector loads and eight shuffles instead of sixteen scalar
// loads.
inline void gather4(const double* const* row, vdouble (&out)[4]) {
#if defined(__AVX__)
  if constexpr (width == 4) {
    const __m256d r0 = _mm256_load_pd(row[0]), r1 = _mm256_load_pd(row[1]);
    const __m256d r2 = _mm256_load_pd(row[2]), r3 = _mm256_load_pd(row[3]);
    const __m256d t0 = _mm256_unpacklo_pd(r0, r1), t1 = _mm256_unpackhi_pd(r0, r1);
    const __m256d t2 = _mm256_unpacklo_pd(r2, r3), t3 = _mm256_unpackhi_pd(r2, r3);
    out[0] = vdouble(_mm256_permute2f128_pd(t0, t2, 0x20));
    out[1] = vdouble(_mm256_permute2f128_pd(t1, t3, 0x20));
    out[2] = vdouble(_mm256_permute2f128_pd(t0, t2, 0x31));
    out[3] = vdouble(_mm256_permute2f128_pd(t1, t3, 0x31));
    return;
  }
#endif
  for (int a = 0; a < 4; ++a) out[a] = vdouble([&](auto l) { return row[l][a]; });
}
// The same from the records p + stride idx[l] (stride in doubles).
inline void gather4(const double* p, int stride, const int* idx, vdouble (&out)[4]) {
  const double* row[width];
  for (int l = 0; l < width; ++l) row[l] = p + static_cast<std::ptrdiff_t>(stride) * idx[l];
  gather4(row, out);
}

#if defined(__AVX__)
// The 4 x 4 transpose of four AVX vectors: row[l] holds lane l of v[0], v[1], v[2], v[3].
inline void transpose4(const vdouble (&v)[4], __m256d (&row)[4]) {
  const __m256d a = static_cast<__m256d>(v[0]), b = static_cast<__m256d>(v[1]);
  const __m256d c = static_cast<__m256d>(v[2]), d = static_cast<__m256d>(v[3]);
  const __m256d t0 = _mm256_unpacklo_pd(a, b), t1 = _mm256_unpackhi_pd(a, b);
  const __m256d t2 = _mm256_unpacklo_pd(c, d), t3 = _mm256_unpackhi_pd(c, d);
  row[0] = _mm256_permute2f128_pd(t0, t2, 0x20);
  row[1] = _mm256_permute2f128_pd(t1, t3, 0x20);
  row[2] = _mm256_permute2f128_pd(t0, t2, 0x31);
  row[3] = _mm256_permute2f128_pd(t1, t3, 0x31);
}
#endif

// The converse of gather4: adds lane l of v[0..3] to the four consecutive doubles at
// q[l] (32-byte aligned; the caller forms the `width` record addresses once for all the
// groups it adds: the stores may alias an index array, which would then be read again),
// lane after lane (a record that several lanes name receives their values in lane order).
// With AVX: the 4 x 4 transpose and one vector add per lane instead of sixteen scalar ones.
inline void scatter_add4(double* const* q, const vdouble (&v)[4]) {
#if defined(__AVX__)
  if constexpr (width == 4) {
    __m256d row[4];
    transpose4(v, row);
    for (int l = 0; l < 4; ++l) _mm256_store_pd(q[l], _mm256_add_pd(_mm256_load_pd(q[l]), row[l]));
    return;
  }
#endif
  for (int l = 0; l < width; ++l)
    for (int a = 0; a < 4; ++a) q[l][a] += v[a][l];
}

// q[a][c] += f[c][a] for a = 0..3, c = 0..2, record after record (q[a] 32-byte aligned
// records of four; a record that several q[a] name receives their values in order of a;
// q[a][3] receives +0.0). Three component rows of four in, one vector add per record out:
// the bits of the scalar adds.
inline void add_columns4(double* const (&q)[4], const double* f0, const double* f1,
                         const double* f2) {
#if defined(__AVX__)
  const __m256d a = _mm256_loadu_pd(f0), b = _mm256_loadu_pd(f1), c = _mm256_loadu_pd(f2);
  const __m256d d = _mm256_setzero_pd();
  const __m256d t0 = _mm256_unpacklo_pd(a, b), t1 = _mm256_unpackhi_pd(a, b);
  const __m256d t2 = _mm256_unpacklo_pd(c, d), t3 = _mm256_unpackhi_pd(c, d);
  const __m256d r[4] = {_mm256_permute2f128_pd(t0, t2, 0x20), _mm256_permute2f128_pd(t1, t3, 0x20),
                        _mm256_permute2f128_pd(t0, t2, 0x31), _mm256_permute2f128_pd(t1, t3, 0x31)};
  for (int k = 0; k < 4; ++k) _mm256_store_pd(q[k], _mm256_add_pd(_mm256_load_pd(q[k]), r[k]));
#else
  for (int k = 0; k < 4; ++k) {
    q[k][0] += f0[k];
    q[k][1] += f1[k];
    q[k][2] += f2[k];
    q[k][3] += 0.0;
  }
#endif
}

// The converse of gather4 without the addition: q[l][a] = v[a][l], a = 0..3 (each q[l]
// 32-byte aligned). Moves values, no arithmetic.
inline void scatter4(double* const* q, const vdouble (&v)[4]) {
#if defined(__AVX__)
  if constexpr (width == 4) {
    __m256d row[4];
    transpose4(v, row);
    for (int l = 0; l < 4; ++l) _mm256_store_pd(q[l], row[l]);
    return;
  }
#endif
  for (int l = 0; l < width; ++l)
    for (int a = 0; a < 4; ++a) q[l][a] = v[a][l];
}

// out[a] = v[a][0] + v[a][1] + ... + v[a][width - 1], added in lane order (the bits of
// summing each vector's lanes one after the other). With AVX: one 4 x 4 transpose and
// three vector adds for the four sums instead of twelve scalar extracts and adds.
inline void lane_sums4(const vdouble (&v)[4], double* out) {
#if defined(__AVX__)
  if constexpr (width == 4) {
    __m256d row[4];
    transpose4(v, row);
    _mm256_storeu_pd(out,
                     _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(row[0], row[1]), row[2]), row[3]));
    return;
  }
#endif
  for (int a = 0; a < 4; ++a) {
    double s = v[a][0];
    for (int l = 1; l < width; ++l) s += v[a][l];
    out[a] = s;
  }
}

// q[l][0] = std::max(q[l][0], v[l]) for every lane, lane after lane (the bits of
// std::max, NaNs included: maxsd(x, m) is m < x ? x : m).
inline void scatter_max(double* const* q, const vdouble& v) {
#if defined(__AVX__)
  if constexpr (width == 4) {
    const __m256d x = static_cast<__m256d>(v);
    const __m128d lo = _mm256_castpd256_pd128(x), hi = _mm256_extractf128_pd(x, 1);
    const __m128d lane[4] = {lo, _mm_unpackhi_pd(lo, lo), hi, _mm_unpackhi_pd(hi, hi)};
    for (int l = 0; l < 4; ++l) _mm_store_sd(q[l], _mm_max_sd(lane[l], _mm_load_sd(q[l])));
    return;
  }
#endif
  for (int l = 0; l < width; ++l) q[l][0] = std::max(q[l][0], static_cast<double>(v[l]));
}

// Bit l set when lane l's sign bit is set (x < y exactly when x - y is negative, for
// finite values).
inline unsigned negative_lanes(const vdouble& v) {
#if defined(__AVX__)
  if constexpr (width == 4)
    return static_cast<unsigned>(_mm256_movemask_pd(static_cast<__m256d>(v)));
#endif
  unsigned bits = 0;
  for (int l = 0; l < width; ++l) bits |= std::signbit(static_cast<double>(v[l])) ? 1u << l : 0u;
  return bits;
}

// Appends the entries idx[l] whose bit l is set to dst, in lane order, and returns how
// many (dst must have room for `width` entries: all are written).
inline int compress_store(unsigned bits, const int* idx, int* dst) {
#if defined(__AVX__)
  if constexpr (width == 4) {
    // One byte shuffle per mask value: the selected 32-bit lanes moved to the front.
    alignas(16) static constexpr unsigned char lut[16][16] = {
        {0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3},
        {0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3},
        {4, 5, 6, 7, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3},
        {0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 3, 0, 1, 2, 3},
        {8, 9, 10, 11, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3},
        {0, 1, 2, 3, 8, 9, 10, 11, 0, 1, 2, 3, 0, 1, 2, 3},
        {4, 5, 6, 7, 8, 9, 10, 11, 0, 1, 2, 3, 0, 1, 2, 3},
        {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 0, 1, 2, 3},
        {12, 13, 14, 15, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3},
        {0, 1, 2, 3, 12, 13, 14, 15, 0, 1, 2, 3, 0, 1, 2, 3},
        {4, 5, 6, 7, 12, 13, 14, 15, 0, 1, 2, 3, 0, 1, 2, 3},
        {0, 1, 2, 3, 4, 5, 6, 7, 12, 13, 14, 15, 0, 1, 2, 3},
        {8, 9, 10, 11, 12, 13, 14, 15, 0, 1, 2, 3, 0, 1, 2, 3},
        {0, 1, 2, 3, 8, 9, 10, 11, 12, 13, 14, 15, 0, 1, 2, 3},
        {4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 0, 1, 2, 3},
        {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15}};
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(idx));
    const __m128i s = _mm_load_si128(reinterpret_cast<const __m128i*>(lut[bits & 15u]));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(dst), _mm_shuffle_epi8(v, s));
    return __builtin_popcount(bits & 15u);
  }
#endif
  int c = 0;
  for (int l = 0; l < width; ++l) {
    dst[c] = idx[l];
    c += (bits >> l) & 1u;
  }
  return c;
}

// v <- (m ? v : other) per lane; the scalar overload lets one template serve a vector
// body and its scalar remainder.
inline void keep_where(const vmask& m, vdouble& v, double other) {
  stdx::where(!m, v) = other;
}
inline void keep_where(bool m, double& v, double other) {
  if (!m) v = other;
}
// m ? a : b, lane by lane.
inline vdouble select(const vmask& m, const vdouble& a, const vdouble& b) {
  vdouble r = b;
  stdx::where(m, r) = a;
  return r;
}
inline double select(bool m, double a, double b) {
  return m ? a : b;
}

// The cube root of x, per lane: within 1 ulp of the correctly rounded root (measured
// against exact references in tests/unit/test_simd.cpp; perfect cubes come out exact). A
// pure function of x by the same instructions for every lane (no table, no libm call), so
// results built on it do not depend on the rank count. Zeros, infinities and NaNs are
// returned as they are; the sign is kept; a subnormal x is scaled by 2^54 (exact) and its
// root by 2^-18, an x above 2^1000 by 2^-54 and its root by 2^18.
//
// The method, for x > 0 (derived for this code): the reciprocal root z = x^(-1/3) first,
// without divisions, then y = x z^2 and one Newton correction of y.
// 1. A first z from the bits. Read as an unsigned integer, the high 32 bits of x,
//    H = 2^20 (e + 1023 + m) for x = 2^e (1 + m), follow 2^20 (log2 x + 1023) up to the
//    log-linear error log2(1 + m) - m in [0, 0.086]. log2 z = -(1/3) log2 x then gives the
//    high word of z, G = 2^20 (1023 + 1023/3) - H/3 = 1364 * 2^20 - H/3, less a shift
//    that balances that error: 69,390 (0.0662 * 2^20), the value that minimises the
//    largest relative error of z over the mantissas and the three exponent residues
//    (scanned numerically): 3.42%. H/3 is an exact unsigned division (a multiplication by
//    0xAAAAAAAB and a shift by 33 with AVX2); z's low word is zero.
// 2. Two steps of third order for z, without divisions: with t = 1 - x z^3, the true root
//    is z (1 - t)^(-1/3) = z (1 + t/3 + 2 t^2 / 9 + 14 t^3 / 81 + ...); the step keeps the
//    first three terms. For a relative error e of z (t ~ -3 e) the error left is about
//    (14 / 81) 27 e^3 = 4.7 e^3: 3.4e-2 -> 1.9e-4 -> 3e-11.
// 3. y = x z^2 (relative error ~6e-11 and two roundings), then one Newton step for
//    y^3 = x with z^2 / 3 for 1 / (3 y^2): y - (y^3 - x) z^2 / 3. Its truncation error is
//    of second order (~1e-20); what is left is rounding: y^3 (two products, up to 2^-52
//    relative, i.e. 2/3 ulp of y after the division by 3 y^2; x - y^3 itself is exact,
//    Sterbenz) and the final subtraction (1/2 ulp).
inline vdouble cube_root(const vdouble& x) {
  constexpr std::uint64_t shift = 69390; // of G, see 1.
  constexpr std::uint64_t g0 = 1364ull * (1ull << 20) - shift;
  const vdouble ax = stdx::abs(x);
  // Subnormals and the largest values scaled by 2^(-+54) (their roots by 2^(+-18)), so that
  // neither 1/x (~ z^3) nor y^3 leaves the normal range.
  vdouble scale_in = 1.0, scale_out = 1.0;
  stdx::where(ax < 0x1p-1022, scale_in) = 0x1p54;
  stdx::where(ax < 0x1p-1022, scale_out) = 0x1p-18;
  stdx::where(ax > 0x1p1000, scale_in) = 0x1p-54;
  stdx::where(ax > 0x1p1000, scale_out) = 0x1p18;
  const vdouble xs = ax * scale_in;
  vdouble z;
#if defined(__AVX2__)
  if constexpr (width == 4) {
    const __m256i hi = _mm256_srli_epi64(_mm256_castpd_si256(static_cast<__m256d>(xs)), 32);
    const __m256i third =
        _mm256_srli_epi64(_mm256_mul_epu32(hi, _mm256_set1_epi64x(0xAAAAAAAB)), 33);
    const __m256i g = _mm256_sub_epi64(_mm256_set1_epi64x(static_cast<long long>(g0)), third);
    z = vdouble(_mm256_castsi256_pd(_mm256_slli_epi64(g, 32)));
  } else
#endif
  {
    z = vdouble([&](auto l) {
      const std::uint64_t hi = std::bit_cast<std::uint64_t>(static_cast<double>(xs[l])) >> 32;
      return std::bit_cast<double>((g0 - hi / 3) << 32);
    });
  }
  for (int k = 0; k < 2; ++k) {
    const vdouble t = 1.0 - xs * (z * z * z);
    z = z + z * (t * (1.0 / 3.0 + t * (2.0 / 9.0)));
  }
  const vdouble z2 = z * z;
  const vdouble y0 = xs * z2;
  vdouble y = (y0 - (y0 * y0 * y0 - xs) * z2 * (1.0 / 3.0)) * scale_out;
  stdx::where(ax == 0.0 || !(ax <= 0x1.fffffffffffffp1023), y) = ax; // 0, inf, NaN
  return stdx::copysign(y, x);
}

// The scalar cube root with the same operations and bits as the vector one.
inline double cube_root(double x) {
  return cube_root(vdouble(x))[0];
}

} // namespace anvil::simd

namespace anvil::simd {
// Arrays of per-element data are padded to whole vectors so that kernels never need a
// scalar tail: the padding repeats the last element.
inline constexpr int padded_size(int n) {
  return (n + width - 1) / width * width;
}
} // namespace anvil::simd
