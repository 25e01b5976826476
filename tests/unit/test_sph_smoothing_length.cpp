// The particles' smoothing length h = h0 (rho0 / rho)^(1/3) takes its cube root from
// simd::cbrt (src/anvil/core/simd.hpp): glibc's algorithm written out, so that four
// particles go together with the same bits as one (sph::smoothing_lengths). Reference:
// the scalar form (the vector form must equal it bit for bit, on positive normal inputs
// and on every special value) and the C library's std::cbrt (within one ulp: glibc's
// documented bound; equal bits where the libm is glibc 2.36's, whose algorithm this is).
// Tolerance: exact equality, one ulp against std::cbrt.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "anvil/core/simd.hpp"
#include "anvil/sph/forces.hpp"

namespace {

using anvil::simd::vdouble;
using anvil::simd::width;

std::uint64_t bits(double x) {
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

// Checks the vector form against the scalar form on xs (taken `width` at a time) and the
// scalar form against std::cbrt; returns how many differed from std::cbrt in the last bit.
int check(const std::vector<double>& xs) {
  int off_by_one = 0;
  for (std::size_t k = 0; k + width <= xs.size(); k += width) {
    const vdouble x([&](auto l) { return xs[k + l]; });
    const vdouble y = anvil::simd::cbrt(x);
    for (int l = 0; l < width; ++l) {
      const double s = anvil::simd::cbrt(xs[k + l]);
      EXPECT_EQ(bits(static_cast<double>(y[l])), bits(s)) << "x = " << xs[k + l];
      const double ref = std::cbrt(xs[k + l]);
      if (std::isnan(ref)) {
        EXPECT_TRUE(std::isnan(s));
        continue;
      }
      const auto d = static_cast<std::int64_t>(bits(s) - bits(ref));
      EXPECT_LE(std::abs(d), 1) << "x = " << xs[k + l];
      off_by_one += d != 0;
    }
  }
  return off_by_one;
}

TEST(SphSmoothingLength, CubeRootNearOne) {
  // Densities within a factor 10 of the reference (every particle of the tests), densely.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.1, 10.0);
  std::vector<double> xs(4'000'000);
  for (auto& x : xs) x = u(rng);
  EXPECT_EQ(check(xs), 0);
}

TEST(SphSmoothingLength, CubeRootEveryExponent) {
  // Random mantissas at every binade of the normal range, and around the powers of two.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> m(1.0, 2.0);
  std::vector<double> xs;
  for (int e = -1022; e <= 1023; ++e) {
    for (int k = 0; k < 200; ++k) xs.push_back(std::ldexp(m(rng), e));
    const double p = std::ldexp(1.0, e);
    xs.push_back(p);
    xs.push_back(std::nextafter(p, 0.0));
    xs.push_back(std::nextafter(p, 1e300));
    xs.push_back(-p);
  }
  while (xs.size() % width != 0) xs.push_back(1.0);
  EXPECT_EQ(check(xs), 0);
}

TEST(SphSmoothingLength, CubeRootSpecialValues) {
  // Zero, subnormal, infinite, NaN and negative lanes among normal ones take the scalar
  // path; the result is the scalar form's and, for these, the library's.
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double tiny = std::numeric_limits<double>::denorm_min();
  std::vector<double> xs = {0.0,  -0.0,     8.0,  27.0, inf,    -inf, nan,     1.0,
                            tiny, 3 * tiny, -8.0, 2.0,  1e-310, 0.5,  -1e-310, 1e300};
  EXPECT_EQ(check(xs), 0);
  EXPECT_EQ(anvil::simd::cbrt(8.0), 2.0);
  EXPECT_EQ(anvil::simd::cbrt(-0.0), -0.0);
  EXPECT_TRUE(std::signbit(anvil::simd::cbrt(-0.0)));
}

TEST(SphSmoothingLength, FourAtATimeEqualsOneAtATime) {
  // sph::smoothing_lengths against sph::smoothing_length per particle, with 3-D sets and a
  // 2-D set among them (its particles break the groups of four) and a count that leaves a
  // remainder.
  std::vector<anvil::sph::SetParams> sets(3);
  sets[0].rho0 = 7850;
  sets[0].h0 = 1.3e-3;
  sets[1].rho0 = 1000;
  sets[1].h0 = 2e-4;
  sets[2].rho0 = 2700;
  sets[2].h0 = 5e-4;
  sets[2].dimensions = 2;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> f(0.5, 2.0);
  const std::size_t n = 1003;
  std::vector<int> set(n);
  std::vector<double> rho(n), h(n);
  for (std::size_t i = 0; i < n; ++i) {
    set[i] = i < 400 ? 0 : (i < 900 ? 1 : (i % 7 == 0 ? 2 : 1));
    rho[i] = sets[static_cast<std::size_t>(set[i])].rho0 * f(rng);
  }
  anvil::sph::smoothing_lengths(sets, set.data(), rho.data(), h.data(), n);
  for (std::size_t i = 0; i < n; ++i)
    EXPECT_EQ(bits(h[i]),
              bits(anvil::sph::smoothing_length(sets[static_cast<std::size_t>(set[i])], rho[i])))
        << "particle " << i;
}

} // namespace
