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
// GCC 12's AVX-512 intrinsics start from _mm512_undefined_pd(), which its
// -W(maybe-)uninitialized reports at every inlined use (GCC bug 105593, fixed in GCC 13).
#if defined(__AVX512F__) && defined(__GNUC__) && !defined(__clang__) && __GNUC__ < 13
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

// Which hand-written paths apply: ANVIL_SIMD_AVX512 where native_simd<double> is one
// 512-bit register (8 lanes), ANVIL_SIMD_AVX where it is one 256-bit register (4 lanes).
// The plain loops below each path are the reference: same values, same order.
#if defined(__AVX512F__) && defined(__AVX512DQ__) && defined(__AVX512VL__)
#define ANVIL_SIMD_AVX512 1
#elif defined(__AVX__) && !defined(__AVX512F__)
#define ANVIL_SIMD_AVX 1
#endif

namespace anvil::simd {

namespace stdx = std::experimental;

// The target's native vector of doubles (4 with AVX2, 8 with AVX-512): measured faster
// here than two native vectors per value (fixed_size_simd<double, 8>).
using vdouble = stdx::native_simd<double>;
using vmask = stdx::native_simd_mask<double>;
inline constexpr int width = static_cast<int>(vdouble::size());
#if defined(ANVIL_SIMD_AVX512)
static_assert(width == 8);
#elif defined(ANVIL_SIMD_AVX)
static_assert(width == 4);
#endif

#if defined(__AVX__)
// The 4 x 4 transpose of four 256-bit rows: out[a][l] = in[l][a]. Moves values.
inline void transpose4x4(const __m256d (&in)[4], __m256d (&out)[4]) {
  const __m256d t0 = _mm256_unpacklo_pd(in[0], in[1]), t1 = _mm256_unpackhi_pd(in[0], in[1]);
  const __m256d t2 = _mm256_unpacklo_pd(in[2], in[3]), t3 = _mm256_unpackhi_pd(in[2], in[3]);
  out[0] = _mm256_permute2f128_pd(t0, t2, 0x20);
  out[1] = _mm256_permute2f128_pd(t1, t3, 0x20);
  out[2] = _mm256_permute2f128_pd(t0, t2, 0x31);
  out[3] = _mm256_permute2f128_pd(t1, t3, 0x31);
}
#endif

#if defined(ANVIL_SIMD_AVX512)
// The 8 x 8 transpose of eight 512-bit rows: out[a][l] = in[l][a]. Moves values.
inline void transpose8x8(const __m512d (&in)[8], __m512d (&out)[8]) {
  __m512d t[8], u[8];
  for (int k = 0; k < 4; ++k) { // t[2k]: [i0 j0 | i2 j2 | i4 j4 | i6 j6], t[2k+1]: odd a
    t[2 * k] = _mm512_unpacklo_pd(in[2 * k], in[2 * k + 1]);
    t[2 * k + 1] = _mm512_unpackhi_pd(in[2 * k], in[2 * k + 1]);
  }
  for (int h = 0; h < 2; ++h) // rows 4h..4h+3; u[4h + c]: pairs of a = c' and c' + 4
    for (int c = 0; c < 2; ++c) {
      u[4 * h + 2 * c] = _mm512_shuffle_f64x2(t[4 * h + c], t[4 * h + 2 + c], 0x88);
      u[4 * h + 2 * c + 1] = _mm512_shuffle_f64x2(t[4 * h + c], t[4 * h + 2 + c], 0xDD);
    }
  // u[0]: a = 0 | 4 of rows 0-3 ([a0 : rows 0 1 | a4 : 0 1 | a0 : 2 3 | a4 : 2 3] read as
  // 128-bit pairs), u[1]: a = 2 | 6, u[2]: a = 1 | 5, u[3]: a = 3 | 7; u[4..7] rows 4-7.
  constexpr int first[4] = {0, 2, 1, 3}; // the a held in the low half of u[c]
  for (int c = 0; c < 4; ++c) {
    out[first[c]] = _mm512_shuffle_f64x2(u[c], u[4 + c], 0x88);
    out[first[c] + 4] = _mm512_shuffle_f64x2(u[c], u[4 + c], 0xDD);
  }
}

// The transpose of four 512-bit vectors into eight 256-bit rows: row[l][a] = v[a][l].
inline void transpose4x8(const __m512d (&v)[4], __m256d (&row)[8]) {
  const __m512d t0 = _mm512_unpacklo_pd(v[0], v[1]), t1 = _mm512_unpackhi_pd(v[0], v[1]);
  const __m512d t2 = _mm512_unpacklo_pd(v[2], v[3]), t3 = _mm512_unpackhi_pd(v[2], v[3]);
  // t0 = [a0 b0 | a2 b2 | a4 b4 | a6 b6], t2 the same of c, d; t1, t3 the odd lanes.
  const __m512i lo = _mm512_setr_epi64(0, 1, 8, 9, 2, 3, 10, 11);
  const __m512i hi = _mm512_setr_epi64(4, 5, 12, 13, 6, 7, 14, 15);
  const __m512d r02 = _mm512_permutex2var_pd(t0, lo, t2), r46 = _mm512_permutex2var_pd(t0, hi, t2);
  const __m512d r13 = _mm512_permutex2var_pd(t1, lo, t3), r57 = _mm512_permutex2var_pd(t1, hi, t3);
  row[0] = _mm512_castpd512_pd256(r02);
  row[2] = _mm512_extractf64x4_pd(r02, 1);
  row[1] = _mm512_castpd512_pd256(r13);
  row[3] = _mm512_extractf64x4_pd(r13, 1);
  row[4] = _mm512_castpd512_pd256(r46);
  row[6] = _mm512_extractf64x4_pd(r46, 1);
  row[5] = _mm512_castpd512_pd256(r57);
  row[7] = _mm512_extractf64x4_pd(r57, 1);
}

// The converse: v[a][l] = row[l][a] for eight 256-bit rows of four.
inline void transpose8x4(const __m256d (&row)[8], __m512d (&v)[4]) {
  auto join = [](__m256d a, __m256d b) {
    return _mm512_insertf64x4(_mm512_castpd256_pd512(a), b, 1);
  };
  const __m512d r04 = join(row[0], row[4]), r15 = join(row[1], row[5]);
  const __m512d r26 = join(row[2], row[6]), r37 = join(row[3], row[7]);
  // unpacklo(r04, r15) = [a0 a1 | c0 c1 | a4 a5 | c4 c5], of r26, r37 the lanes 2 3, 6 7.
  const __m512d t0 = _mm512_unpacklo_pd(r04, r15), t1 = _mm512_unpackhi_pd(r04, r15);
  const __m512d t2 = _mm512_unpacklo_pd(r26, r37), t3 = _mm512_unpackhi_pd(r26, r37);
  const __m512i first = _mm512_setr_epi64(0, 1, 8, 9, 4, 5, 12, 13);
  const __m512i second = _mm512_setr_epi64(2, 3, 10, 11, 6, 7, 14, 15);
  v[0] = _mm512_permutex2var_pd(t0, first, t2);
  v[1] = _mm512_permutex2var_pd(t1, first, t3);
  v[2] = _mm512_permutex2var_pd(t0, second, t2);
  v[3] = _mm512_permutex2var_pd(t1, second, t3);
}
#endif

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
#if defined(ANVIL_SIMD_AVX) || defined(ANVIL_SIMD_AVX512)
  // Two lanes' pairs in one 256-bit register: f_i s_i f_j s_j.
  auto pairs = [&](int i, int j) {
    return _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p + off[i])),
                                _mm_loadu_pd(p + off[j]), 1);
  };
#endif
#if defined(ANVIL_SIMD_AVX)
  const __m256d a = pairs(0, 2), b = pairs(1, 3);
  first = vdouble(_mm256_unpacklo_pd(a, b));
  second = vdouble(_mm256_unpackhi_pd(a, b));
#elif defined(ANVIL_SIMD_AVX512)
  const __m512d a = _mm512_insertf64x4(_mm512_castpd256_pd512(pairs(0, 2)), pairs(4, 6), 1);
  const __m512d b = _mm512_insertf64x4(_mm512_castpd256_pd512(pairs(1, 3)), pairs(5, 7), 1);
  first = vdouble(_mm512_unpacklo_pd(a, b));
  second = vdouble(_mm512_unpackhi_pd(a, b));
#else
  first = vdouble([&](auto l) { return p[off[l]]; });
  second = vdouble([&](auto l) { return p[off[l] + 1]; });
#endif
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
#if defined(ANVIL_SIMD_AVX)
  return vdouble(_mm256_loadu_pd(p));
#elif defined(ANVIL_SIMD_AVX512)
  return vdouble(_mm512_loadu_pd(p));
#else
  return vdouble(p, stdx::element_aligned);
#endif
}
inline void store(const vdouble& v, double* p) {
#if defined(ANVIL_SIMD_AVX)
  _mm256_storeu_pd(p, static_cast<__m256d>(v));
#elif defined(ANVIL_SIMD_AVX512)
  _mm512_storeu_pd(p, static_cast<__m512d>(v));
#else
  v.copy_to(p, stdx::element_aligned);
#endif
}

// Stores eight vectors as `width` rows of eight: p[8 l + a] = v[a][l] (the element-major
// corner slots: lane l's eight values are contiguous). Moves values, no arithmetic.
// stream: non-temporal stores (p must be 32-byte aligned, 64 with AVX-512), for rows that are
// written once and read back only after the whole kernel: they bypass the cache instead of first
// reading every line in; stream_fence() after the last one.
template <bool stream = false>
inline void store_transposed(const vdouble (&v)[8], double* p) {
#if defined(ANVIL_SIMD_AVX)
  auto put = [](double* q, __m256d r) {
    if constexpr (stream)
      _mm256_stream_pd(q, r);
    else
      _mm256_storeu_pd(q, r);
  };
  for (int h = 0; h < 2; ++h) { // values 0-3, then 4-7, of every lane
    const __m256d in[4] = {static_cast<__m256d>(v[4 * h]), static_cast<__m256d>(v[4 * h + 1]),
                           static_cast<__m256d>(v[4 * h + 2]), static_cast<__m256d>(v[4 * h + 3])};
    __m256d row[4];
    transpose4x4(in, row);
    for (int l = 0; l < 4; ++l) put(p + 8 * l + 4 * h, row[l]);
  }
#elif defined(ANVIL_SIMD_AVX512)
  __m512d in[8], row[8];
  for (int a = 0; a < 8; ++a) in[a] = static_cast<__m512d>(v[a]);
  transpose8x8(in, row);
  for (int l = 0; l < 8; ++l) {
    if constexpr (stream)
      _mm512_stream_pd(p + 8 * l, row[l]);
    else
      _mm512_storeu_pd(p + 8 * l, row[l]);
  }
#else
  for (int l = 0; l < width; ++l)
    for (int a = 0; a < 8; ++a) p[8 * l + a] = v[a][l];
#endif
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
#if defined(ANVIL_SIMD_AVX)
  const __m256d in[4] = {_mm256_load_pd(row[0]), _mm256_load_pd(row[1]), _mm256_load_pd(row[2]),
                         _mm256_load_pd(row[3])};
  __m256d t[4];
  transpose4x4(in, t);
  for (int a = 0; a < 4; ++a) out[a] = vdouble(t[a]);
#elif defined(ANVIL_SIMD_AVX512)
  __m256d in[8];
  for (int l = 0; l < 8; ++l) in[l] = _mm256_load_pd(row[l]);
  __m512d t[4];
  transpose8x4(in, t);
  for (int a = 0; a < 4; ++a) out[a] = vdouble(t[a]);
#else
  for (int a = 0; a < 4; ++a) out[a] = vdouble([&](auto l) { return row[l][a]; });
#endif
}
// The same from the records p + stride idx[l] (stride in doubles).
inline void gather4(const double* p, int stride, const int* idx, vdouble (&out)[4]) {
  const double* row[width];
  for (int l = 0; l < width; ++l) row[l] = p + static_cast<std::ptrdiff_t>(stride) * idx[l];
  gather4(row, out);
}

#if defined(ANVIL_SIMD_AVX) || defined(ANVIL_SIMD_AVX512)
// Four vectors as `width` rows of four: row[l] holds lane l of v[0], v[1], v[2], v[3].
inline void transpose4(const vdouble (&v)[4], __m256d (&row)[width]) {
#if defined(ANVIL_SIMD_AVX)
  const __m256d in[4] = {static_cast<__m256d>(v[0]), static_cast<__m256d>(v[1]),
                         static_cast<__m256d>(v[2]), static_cast<__m256d>(v[3])};
  transpose4x4(in, row);
#else
  const __m512d in[4] = {static_cast<__m512d>(v[0]), static_cast<__m512d>(v[1]),
                         static_cast<__m512d>(v[2]), static_cast<__m512d>(v[3])};
  transpose4x8(in, row);
#endif
}
#endif

// The converse of gather4: adds lane l of v[0..3] to the four consecutive doubles at
// q[l] (32-byte aligned; the caller forms the `width` record addresses once for all the
// groups it adds: the stores may alias an index array, which would then be read again),
// lane after lane (a record that several lanes name receives their values in lane order).
// With AVX: the 4 x 4 transpose and one vector add per lane instead of sixteen scalar ones.
inline void scatter_add4(double* const* q, const vdouble (&v)[4]) {
#if defined(ANVIL_SIMD_AVX) || defined(ANVIL_SIMD_AVX512)
  __m256d row[width];
  transpose4(v, row);
  for (int l = 0; l < width; ++l)
    _mm256_store_pd(q[l], _mm256_add_pd(_mm256_load_pd(q[l]), row[l]));
#else
  for (int l = 0; l < width; ++l)
    for (int a = 0; a < 4; ++a) q[l][a] += v[a][l];
#endif
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
  const __m256d in[4] = {a, b, c, d};
  __m256d r[4];
  transpose4x4(in, r);
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
#if defined(ANVIL_SIMD_AVX) || defined(ANVIL_SIMD_AVX512)
  __m256d row[width];
  transpose4(v, row);
  for (int l = 0; l < width; ++l) _mm256_store_pd(q[l], row[l]);
#else
  for (int l = 0; l < width; ++l)
    for (int a = 0; a < 4; ++a) q[l][a] = v[a][l];
#endif
}

// out[a] = v[a][0] + v[a][1] + ... + v[a][width - 1], added in lane order (the bits of
// summing each vector's lanes one after the other). With AVX: one 4 x 4 transpose and
// three vector adds for the four sums instead of twelve scalar extracts and adds.
inline void lane_sums4(const vdouble (&v)[4], double* out) {
#if defined(ANVIL_SIMD_AVX) || defined(ANVIL_SIMD_AVX512)
  __m256d row[width];
  transpose4(v, row);
  __m256d s = row[0];
  for (int l = 1; l < width; ++l) s = _mm256_add_pd(s, row[l]);
  _mm256_storeu_pd(out, s);
#else
  for (int a = 0; a < 4; ++a) {
    double s = v[a][0];
    for (int l = 1; l < width; ++l) s += v[a][l];
    out[a] = s;
  }
#endif
}

// q[l][0] = std::max(q[l][0], v[l]) for every lane, lane after lane (the bits of
// std::max, NaNs included: maxsd(x, m) is m < x ? x : m).
inline void scatter_max(double* const* q, const vdouble& v) {
#if defined(ANVIL_SIMD_AVX) || defined(ANVIL_SIMD_AVX512)
  auto put = [&](int l, __m256d x) { // lanes l..l+3 from the 256-bit x
    const __m128d lo = _mm256_castpd256_pd128(x), hi = _mm256_extractf128_pd(x, 1);
    const __m128d lane[4] = {lo, _mm_unpackhi_pd(lo, lo), hi, _mm_unpackhi_pd(hi, hi)};
    for (int k = 0; k < 4; ++k) _mm_store_sd(q[l + k], _mm_max_sd(lane[k], _mm_load_sd(q[l + k])));
  };
#if defined(ANVIL_SIMD_AVX)
  put(0, static_cast<__m256d>(v));
#else
  const __m512d x = static_cast<__m512d>(v);
  put(0, _mm512_castpd512_pd256(x));
  put(4, _mm512_extractf64x4_pd(x, 1));
#endif
#else
  for (int l = 0; l < width; ++l) q[l][0] = std::max(q[l][0], static_cast<double>(v[l]));
#endif
}

// Bit l set when lane l's sign bit is set (x < y exactly when x - y is negative, for
// finite values).
inline unsigned negative_lanes(const vdouble& v) {
#if defined(ANVIL_SIMD_AVX)
  return static_cast<unsigned>(_mm256_movemask_pd(static_cast<__m256d>(v)));
#elif defined(ANVIL_SIMD_AVX512)
  return static_cast<unsigned>(_mm512_movepi64_mask(_mm512_castpd_si512(static_cast<__m512d>(v))));
#else
  unsigned bits = 0;
  for (int l = 0; l < width; ++l) bits |= std::signbit(static_cast<double>(v[l])) ? 1u << l : 0u;
  return bits;
#endif
}

// Bit l set when x[l] < lo[l] or x[l] > hi[l]: x outside [lo, hi] in that lane (never
// where a NaN is compared, so a box with a NaN side holds every point).
inline unsigned outside_lanes(const vdouble& x, const vdouble& lo, const vdouble& hi) {
#if defined(ANVIL_SIMD_AVX)
  const __m256d a = static_cast<__m256d>(x);
  return static_cast<unsigned>(
      _mm256_movemask_pd(_mm256_or_pd(_mm256_cmp_pd(a, static_cast<__m256d>(lo), _CMP_LT_OQ),
                                      _mm256_cmp_pd(a, static_cast<__m256d>(hi), _CMP_GT_OQ))));
#elif defined(ANVIL_SIMD_AVX512)
  const __m512d a = static_cast<__m512d>(x);
  return static_cast<unsigned>(_mm512_cmp_pd_mask(a, static_cast<__m512d>(lo), _CMP_LT_OQ) |
                               _mm512_cmp_pd_mask(a, static_cast<__m512d>(hi), _CMP_GT_OQ));
#else
  unsigned bits = 0;
  for (int l = 0; l < width; ++l) bits |= (x[l] < lo[l] || x[l] > hi[l]) ? 1u << l : 0u;
  return bits;
#endif
}

// Appends the entries idx[l] whose bit l is set to dst, in lane order, and returns how
// many (dst must have room for `width` entries: all are written).
inline int compress_store(unsigned bits, const int* idx, int* dst) {
#if defined(ANVIL_SIMD_AVX512)
  const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(idx));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(dst),
                      _mm256_maskz_compress_epi32(static_cast<__mmask8>(bits), v));
  return __builtin_popcount(bits & 255u);
#elif defined(ANVIL_SIMD_AVX)
  {
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
#else
  int c = 0;
  for (int l = 0; l < width; ++l) {
    dst[c] = idx[l];
    c += (bits >> l) & 1u;
  }
  return c;
#endif
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
#if defined(ANVIL_SIMD_AVX) && defined(__AVX2__)
  {
    const __m256i hi = _mm256_srli_epi64(_mm256_castpd_si256(static_cast<__m256d>(xs)), 32);
    const __m256i third =
        _mm256_srli_epi64(_mm256_mul_epu32(hi, _mm256_set1_epi64x(0xAAAAAAAB)), 33);
    const __m256i g = _mm256_sub_epi64(_mm256_set1_epi64x(static_cast<long long>(g0)), third);
    z = vdouble(_mm256_castsi256_pd(_mm256_slli_epi64(g, 32)));
  }
#elif defined(ANVIL_SIMD_AVX512)
  {
    const __m512i hi = _mm512_srli_epi64(_mm512_castpd_si512(static_cast<__m512d>(xs)), 32);
    const __m512i third =
        _mm512_srli_epi64(_mm512_mul_epu32(hi, _mm512_set1_epi64(0xAAAAAAAB)), 33);
    const __m512i g = _mm512_sub_epi64(_mm512_set1_epi64(static_cast<long long>(g0)), third);
    z = vdouble(_mm512_castsi512_pd(_mm512_slli_epi64(g, 32)));
  }
#else
  {
    z = vdouble([&](auto l) {
      const std::uint64_t hi = std::bit_cast<std::uint64_t>(static_cast<double>(xs[l])) >> 32;
      return std::bit_cast<double>((g0 - hi / 3) << 32);
    });
  }
#endif
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
