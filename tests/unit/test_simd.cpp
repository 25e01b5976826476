// simd::cube_root (the smoothing length's h0 (rho0 / rho)^(1/3)) against exact references,
// and the data-movement helpers of simd.hpp (the hand-written AVX and AVX-512 transposes)
// against their definitions written as plain loops: the same values in the same places,
// and for the sums the same bits as adding lane after lane (exact comparisons).
// Tolerances: within 1 ulp of the exact cube root for every input (the computed root and
// its neighbours are cubed in exact integer arithmetic); perfect cubes and 2^(3k) exact;
// within 4 ulps of std::cbrt (glibc's cbrt is itself up to 3 ulps from the correctly
// rounded root: measured here on the same inputs).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "anvil/core/simd.hpp"

namespace {

using anvil::simd::cube_root;
using anvil::simd::vdouble;
using anvil::simd::width;
using u128 = unsigned __int128;

// A 192-bit unsigned integer, limbs least significant first.
struct U192 {
  std::uint64_t w[3] = {0, 0, 0};
};

int compare(const U192& a, const U192& b) {
  for (int k = 2; k >= 0; --k)
    if (a.w[k] != b.w[k]) return a.w[k] < b.w[k] ? -1 : 1;
  return 0;
}

// m^3 for m < 2^55.
U192 cube(std::uint64_t m) {
  const u128 s = static_cast<u128>(m) * m; // < 2^110
  const u128 lo = static_cast<u128>(static_cast<std::uint64_t>(s)) * m;
  const u128 hi = static_cast<u128>(static_cast<std::uint64_t>(s >> 64)) * m;
  U192 r;
  r.w[0] = static_cast<std::uint64_t>(lo);
  const u128 mid = (lo >> 64) + static_cast<std::uint64_t>(hi);
  r.w[1] = static_cast<std::uint64_t>(mid);
  r.w[2] = static_cast<std::uint64_t>(hi >> 64) + static_cast<std::uint64_t>(mid >> 64);
  return r;
}

// v 2^s for v < 2^64, 0 <= s < 128.
U192 shifted(std::uint64_t v, int s) {
  U192 r;
  const int limb = s / 64, bit = s % 64;
  r.w[limb] = v << bit;
  if (bit > 0 && limb + 1 < 3) r.w[limb + 1] = v >> (64 - bit);
  return r;
}

// The sign of (m 2^p)^3 - x exactly, for m < 2^55 and a positive finite x.
int cube_vs(std::uint64_t m, int p, double x) {
  int ex = 0;
  const double fx = std::frexp(x, &ex);
  const auto X = static_cast<std::uint64_t>(std::ldexp(fx, 53)); // x = X 2^(ex - 53)
  // Compare m^3 2^(3p) with X 2^(ex - 53): shift the smaller exponent's side.
  const int s = (ex - 53) - 3 * p;
  const U192 c = cube(m); // < 2^165
  if (s >= 0) {
    if (s >= 113) return -1; // X 2^s >= 2^165
    return compare(c, shifted(X, s));
  }
  // m^3 2^t against X < 2^53 (t = -s): m^3 >= 1, so from t = 53 on the cube is larger.
  const int t = -s;
  if (t >= 53) return 1;
  if ((c.w[2] >> (64 - t)) != 0) return 1; // beyond 192 bits: far larger
  U192 cs;
  for (int k = 2; k >= 0; --k) {
    cs.w[k] = c.w[k] << t;
    if (k > 0) cs.w[k] |= c.w[k - 1] >> (64 - t);
  }
  return compare(cs, shifted(X, 0));
}

// y = M 2^P with M a 53-bit integer (y positive and normal).
void split(double y, std::uint64_t& M, int& P) {
  int e = 0;
  const double f = std::frexp(y, &e);
  M = static_cast<std::uint64_t>(std::ldexp(f, 53));
  P = e - 53;
}

// 0: y is the correctly rounded cube root of x; 1: within 1 ulp (the root strictly
// between y's neighbours); 2: farther.
int root_error(double y, double x) {
  std::uint64_t M = 0;
  int P = 0;
  split(y, M, P);
  // Neighbours and midpoints at twice the resolution: y = 2M 2^(P-1).
  const std::uint64_t m2 = 2 * M;
  // Below y: at a power of two the next lower double is half as far.
  const bool binade = M == (1ull << 52);
  const int pl = binade ? P - 2 : P - 1;
  const std::uint64_t ml = binade ? 4 * M : m2;
  const bool below_mid = cube_vs(ml - 1, pl, x) <= 0;    // (y - ulp_below / 2)^3 <= x
  const bool above_mid = cube_vs(m2 + 1, P - 1, x) >= 0; // (y + ulp / 2)^3 >= x
  if (below_mid && above_mid) return 0;
  const bool below = cube_vs(binade ? 2 * M - 1 : M - 1, binade ? P - 1 : P, x) < 0;
  const bool above = cube_vs(M + 1, P, x) > 0;
  return below && above ? 1 : 2;
}

std::int64_t ulps(double a, double b) {
  const auto ia = std::bit_cast<std::int64_t>(a), ib = std::bit_cast<std::int64_t>(b);
  return ia > ib ? ia - ib : ib - ia;
}

std::vector<double> inputs() {
  std::mt19937_64 gen(20240611);
  std::uniform_real_distribution<double> expo(-1074.0, 1024.0), near(0.1, 10.0), dens(0.5, 2.0);
  std::vector<double> xs;
  auto push = [&](double x) { // positive and finite
    if (x > 0 && std::isfinite(x)) xs.push_back(x);
  };
  for (int k = 0; k < 400000; ++k) {
    push(std::exp2(expo(gen))); // every binade, subnormals included
    push(near(gen));
    push(dens(gen)); // rho0 / rho of a particle
  }
  for (int e = -1074; e < 1024; ++e) { // powers of two and their neighbours
    const double p = std::ldexp(1.0, e);
    push(p);
    push(std::nextafter(p, 0.0));
    push(std::nextafter(p, 2 * p));
  }
  push(std::numeric_limits<double>::max());
  return xs;
}

TEST(SimdCubeRoot, WithinOneUlpOfTheExactRoot) {
  const std::vector<double> xs = inputs();
  std::int64_t exact = 0, libm_exact = 0, libm_worst = 0, worst_vs_libm = 0;
  for (std::size_t k = 0; k < xs.size(); k += width) {
    const vdouble x([&](auto l) { return xs[std::min(k + l, xs.size() - 1)]; });
    const vdouble y = cube_root(x);
    for (int l = 0; l < width && k + l < xs.size(); ++l) {
      const double xi = x[l], yi = y[l];
      ASSERT_GT(yi, 0.0) << xi;
      const int e = root_error(yi, xi);
      ASSERT_LE(e, 1) << "cube_root(" << xi << ") = " << yi;
      exact += e == 0;
      const double c = std::cbrt(xi);
      // glibc's error in ulps: steps from c to the correctly rounded root.
      std::uint64_t M = 0;
      int P = 0;
      split(c, M, P);
      const double dir = cube_vs(M, P, xi) < 0 ? 2 * c : 0.0;
      double r = c;
      std::int64_t steps = 0;
      while (root_error(r, xi) != 0 && steps < 16) {
        r = std::nextafter(r, dir);
        ++steps;
      }
      libm_exact += steps == 0;
      libm_worst = std::max(libm_worst, steps);
      worst_vs_libm = std::max(worst_vs_libm, ulps(yi, c));
      ASSERT_LE(ulps(yi, c), 4) << xi;
      ASSERT_EQ(cube_root(-xi), -yi); // odd
      ASSERT_EQ(cube_root(xi), yi);   // the scalar call: the same bits
    }
  }
  std::printf("cube_root: %zu inputs, %.1f%% correctly rounded, the rest within 1 ulp; "
              "std::cbrt %.1f%% correctly rounded, up to %lld ulps off; largest difference from "
              "std::cbrt %lld ulps\n",
              xs.size(), 100.0 * static_cast<double>(exact) / static_cast<double>(xs.size()),
              100.0 * static_cast<double>(libm_exact) / static_cast<double>(xs.size()),
              static_cast<long long>(libm_worst), static_cast<long long>(worst_vs_libm));
}

TEST(SimdCubeRoot, PerfectCubesAndSpecialValues) {
  for (std::int64_t k = 1; k <= 200000; ++k) {
    const auto d = static_cast<double>(k);
    ASSERT_EQ(cube_root(d * d * d), d) << k;
  }
  for (int j = -358; j <= 341; ++j)
    ASSERT_EQ(cube_root(std::ldexp(1.0, 3 * j)), std::ldexp(1.0, j));
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(cube_root(inf), inf);
  EXPECT_EQ(cube_root(-inf), -inf);
  EXPECT_TRUE(std::isnan(cube_root(std::numeric_limits<double>::quiet_NaN())));
  EXPECT_EQ(cube_root(0.0), 0.0);
  EXPECT_FALSE(std::signbit(cube_root(0.0)));
  EXPECT_TRUE(std::signbit(cube_root(-0.0)));
  EXPECT_EQ(cube_root(-27.0), -3.0);
}

// Values that are distinct and tell lane and index apart: v(l, a) = 100 l + a + 0.25.
double tag(int l, int a) {
  return 100.0 * l + a + 0.25;
}

vdouble tagged(int a) {
  return vdouble([&](auto l) { return tag(static_cast<int>(l), a); });
}

TEST(SimdMoves, LoadStoreAndPairs) {
  alignas(64) double buf[2 * 8 * 16] = {};
  for (int k = 0; k < 2 * 8 * 16; ++k) buf[k] = 0.5 * k;
  const vdouble v = anvil::simd::load(buf + 3); // unaligned
  for (int l = 0; l < width; ++l) EXPECT_EQ(v[l], buf[3 + l]);
  double out[16] = {};
  anvil::simd::store(v, out + 1);
  for (int l = 0; l < width; ++l) EXPECT_EQ(out[1 + l], buf[3 + l]);
  std::ptrdiff_t off[8] = {7, 0, 31, 12, 5, 40, 2, 19};
  vdouble first, second;
  anvil::simd::gather_pairs(buf, off, first, second);
  for (int l = 0; l < width; ++l) {
    EXPECT_EQ(first[l], buf[off[l]]) << l;
    EXPECT_EQ(second[l], buf[off[l] + 1]) << l;
  }
}

TEST(SimdMoves, StoreTransposed) {
  vdouble v[8];
  for (int a = 0; a < 8; ++a) v[a] = tagged(a);
  alignas(64) double plain[8 * 8] = {}, streamed[8 * 8] = {};
  anvil::simd::store_transposed(v, plain);
  anvil::simd::store_transposed<true>(v, streamed);
  anvil::simd::stream_fence();
  for (int l = 0; l < width; ++l)
    for (int a = 0; a < 8; ++a) {
      EXPECT_EQ(plain[8 * l + a], tag(l, a)) << l << " " << a;
      EXPECT_EQ(streamed[8 * l + a], tag(l, a)) << l << " " << a;
    }
}

TEST(SimdMoves, GatherScatterFour) {
  alignas(32) double rec[10][4];
  for (int r = 0; r < 10; ++r)
    for (int a = 0; a < 4; ++a) rec[r][a] = 10.0 * r + a;
  const int idx[8] = {3, 9, 0, 4, 7, 1, 8, 2};
  vdouble g[4];
  anvil::simd::gather4(&rec[0][0], 4, idx, g);
  for (int l = 0; l < width; ++l)
    for (int a = 0; a < 4; ++a) EXPECT_EQ(g[a][l], rec[idx[l]][a]) << l << " " << a;

  const vdouble v[4] = {tagged(0), tagged(1), tagged(2), tagged(3)};
  double* q[8];
  for (int l = 0; l < width; ++l) q[l] = rec[idx[l]];
  anvil::simd::scatter4(q, v);
  for (int l = 0; l < width; ++l)
    for (int a = 0; a < 4; ++a) EXPECT_EQ(rec[idx[l]][a], tag(l, a));

  // Added lane after lane, also where lanes name the same record.
  alignas(32) double acc[2][4] = {{1e16, 1, 2, 3}, {4, 5, 6, 7}};
  double ref[2][4];
  std::copy(&acc[0][0], &acc[0][0] + 8, &ref[0][0]);
  for (int l = 0; l < width; ++l) q[l] = acc[l % 3 == 1 ? 1 : 0];
  anvil::simd::scatter_add4(q, v);
  for (int l = 0; l < width; ++l)
    for (int a = 0; a < 4; ++a) ref[l % 3 == 1 ? 1 : 0][a] += tag(l, a);
  for (int r = 0; r < 2; ++r)
    for (int a = 0; a < 4; ++a) EXPECT_EQ(acc[r][a], ref[r][a]) << r << " " << a;

  alignas(32) double col[3][4] = {{1, 2, 3, 4}, {5, 6, 7, 8}, {9, 10, 11, 12}};
  const double f[3][4] = {{0.5, 1.5, 2.5, 3.5}, {4.5, 5.5, 6.5, 7.5}, {8.5, 9.5, 10.5, 11.5}};
  double* const qc[4] = {col[0], col[2], col[0], col[1]};
  double refc[3][4];
  std::copy(&col[0][0], &col[0][0] + 12, &refc[0][0]);
  const int which[4] = {0, 2, 0, 1};
  for (int k = 0; k < 4; ++k) {
    for (int c = 0; c < 3; ++c) refc[which[k]][c] += f[c][k];
    refc[which[k]][3] += 0.0;
  }
  anvil::simd::add_columns4(qc, f[0], f[1], f[2]);
  for (int r = 0; r < 3; ++r)
    for (int a = 0; a < 4; ++a) EXPECT_EQ(col[r][a], refc[r][a]) << r << " " << a;
}

TEST(SimdMoves, LaneSumsInLaneOrder) {
  // Values whose sum depends on the order: a large value first, small ones after.
  const vdouble v[4] = {
      vdouble([](auto l) { return l == 0 ? 1e16 : 1.0 + 0.1 * static_cast<double>(l); }), tagged(1),
      vdouble([](auto l) { return l % 2 ? -1e-17 : 3e-1; }), tagged(3)};
  double out[4];
  anvil::simd::lane_sums4(v, out);
  for (int a = 0; a < 4; ++a) {
    double s = v[a][0];
    for (int l = 1; l < width; ++l) s += v[a][l];
    EXPECT_EQ(out[a], s) << a;
  }
}

TEST(SimdMoves, MaxNegativeLanesCompress) {
  alignas(32) double rec[8][4] = {};
  double* q[8];
  for (int l = 0; l < 8; ++l) {
    rec[l][0] = l % 2 ? 1e9 : -1e9;
    q[l] = rec[l];
  }
  const vdouble v = tagged(0);
  anvil::simd::scatter_max(q, v);
  for (int l = 0; l < width; ++l) EXPECT_EQ(rec[l][0], l % 2 ? 1e9 : tag(l, 0)) << l;

  const vdouble s([](auto l) { return l % 3 == 0 ? -1.0 : (l == 1 ? -0.0 : 2.0); });
  unsigned want = 0;
  for (int l = 0; l < width; ++l)
    if (std::signbit(static_cast<double>(s[l]))) want |= 1u << l;
  EXPECT_EQ(anvil::simd::negative_lanes(s), want);

  const int idx[8] = {11, 12, 13, 14, 15, 16, 17, 18};
  for (unsigned bits = 0; bits < (1u << width); ++bits) {
    int dst[8] = {};
    const int c = anvil::simd::compress_store(bits, idx, dst);
    int k = 0;
    for (int l = 0; l < width; ++l)
      if (bits >> l & 1u) {
        ASSERT_LT(k, c);
        EXPECT_EQ(dst[k++], idx[l]) << bits;
      }
    EXPECT_EQ(c, k) << bits;
  }
}

TEST(SimdMoves, OutsideLanes) {
  // Per lane: below, at the low side, inside, at the high side, above, a NaN point, a NaN
  // low side, a NaN high side (a NaN never counts as outside).
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double x[8] = {-2, -1, 0, 1, 2, nan, -5, 5};
  const double lo[8] = {-1, -1, -1, -1, -1, -1, nan, -1};
  const double hi[8] = {1, 1, 1, 1, 1, 1, 1, nan};
  const bool out[8] = {true, false, false, false, true, false, false, false};
  for (int shift = 0; shift + width <= 8; shift += width) {
    unsigned want = 0;
    for (int l = 0; l < width; ++l) want |= out[shift + l] ? 1u << l : 0u;
    EXPECT_EQ(anvil::simd::outside_lanes(anvil::simd::load(x + shift),
                                         anvil::simd::load(lo + shift),
                                         anvil::simd::load(hi + shift)),
              want)
        << shift;
  }
}

} // namespace
