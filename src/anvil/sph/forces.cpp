#include "anvil/sph/forces.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "anvil/core/simd.hpp"
#include "anvil/fe/hex8.hpp"

namespace anvil::sph {

using simd::vdouble;
using simd::width;
namespace stdx = simd::stdx;

namespace {

// kernel_fast for `width` pairs at once (the same operations per lane).
template <KernelType K, int D>
[[gnu::always_inline]] inline void kernel_simd(const vdouble& r, const vdouble& h, vdouble& w,
                                               vdouble& dwr) {
  const vdouble ih = 1.0 / h, q = r * ih;
  const vdouble ihd = D == 1 ? ih : (D == 2 ? ih * ih : ih * ih * ih);
  const vdouble s = kernel_norm<K, D>() * ihd;
  if constexpr (K == KernelType::cubic_spline) {
    const vdouble a = stdx::max(2.0 - q, vdouble(0.0)), b = stdx::max(1.0 - q, vdouble(0.0));
    w = s * (0.25 * a * a * a - b * b * b);
    dwr = s * ih * (3.0 * b * b - 0.75 * a * a) / r;
  } else {
    const vdouble t = stdx::max(1.0 - 0.5 * q, vdouble(0.0)), t3 = t * t * t;
    w = s * t3 * t * (2.0 * q + 1.0);
    dwr = s * ih * ih * (-5.0 * t3);
  }
}

// The kernel at r = 0 (a particle's own term in the summation density): the
// normalisation over h^D times the shape's value 1 (cubic spline) or 1 (Wendland C2).
template <KernelType K, int D>
inline double self_weight(double h) {
  const double ih = 1.0 / h;
  return kernel_norm<K, D>() * (D == 1 ? ih : (D == 2 ? ih * ih : ih * ih * ih));
}

} // namespace

void principal(const double s[6], double lambda[3], double Q[3][3]) {
  double A[3][3] = {{s[0], s[3], s[5]}, {s[3], s[1], s[4]}, {s[5], s[4], s[2]}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) Q[i][j] = i == j ? 1.0 : 0.0;
  constexpr int pq[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  // Jacobi converges quadratically: at most 6 sweeps reach round-off for any 3x3
  // tensor; stop once the off-diagonal part is negligible (a test on this particle's
  // own values, so every rank does the same).
  for (int sweep = 0; sweep < 6; ++sweep) {
    const double off = A[0][1] * A[0][1] + A[0][2] * A[0][2] + A[1][2] * A[1][2];
    const double diag = A[0][0] * A[0][0] + A[1][1] * A[1][1] + A[2][2] * A[2][2];
    if (off <= 1e-30 * diag) break;
    for (const auto& e : pq) {
      const int p = e[0], q = e[1];
      const double apq = A[p][q];
      if (apq == 0.0) continue;
      const double theta = (A[q][q] - A[p][p]) / (2 * apq);
      const double t = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1));
      const double c = 1 / std::sqrt(t * t + 1), sn = t * c;
      for (int k = 0; k < 3; ++k) { // A <- A J
        const double akp = A[k][p], akq = A[k][q];
        A[k][p] = c * akp - sn * akq;
        A[k][q] = sn * akp + c * akq;
      }
      for (int k = 0; k < 3; ++k) { // A <- J^T A
        const double apk = A[p][k], aqk = A[q][k];
        A[p][k] = c * apk - sn * aqk;
        A[q][k] = sn * apk + c * aqk;
      }
      for (int k = 0; k < 3; ++k) { // Q <- Q J
        const double qkp = Q[k][p], qkq = Q[k][q];
        Q[k][p] = c * qkp - sn * qkq;
        Q[k][q] = sn * qkp + c * qkq;
      }
    }
  }
  for (int i = 0; i < 3; ++i) lambda[i] = A[i][i];
}

namespace {

// Monaghan's artificial stress of one particle (in stress units, for the
// (sigma_i + sigma_j) / (rho_i rho_j) form): in the principal frame of sigma,
// R'_aa = -epsilon sigma'_aa where sigma'_aa is tensile, else 0; rotated back.
void artificial_stress(const double s[6], double eps, double R[6]) {
  // Gershgorin: no eigenvalue exceeds max_i (s_ii + sum_j |s_ij|); when that is not
  // positive no principal stress is tensile and R = 0 (compressed or fluid particles).
  const double b0 = s[0] + std::abs(s[3]) + std::abs(s[5]);
  const double b1 = s[1] + std::abs(s[3]) + std::abs(s[4]);
  const double b2 = s[2] + std::abs(s[4]) + std::abs(s[5]);
  if (std::max({b0, b1, b2}) <= 0) {
    for (int k = 0; k < 6; ++k) R[k] = 0;
    return;
  }
  double lam[3], Q[3][3];
  principal(s, lam, Q);
  double r[3];
  for (int a = 0; a < 3; ++a) r[a] = lam[a] > 0 ? -eps * lam[a] : 0.0;
  auto comp = [&](int i, int j) {
    return Q[i][0] * r[0] * Q[j][0] + Q[i][1] * r[1] * Q[j][1] + Q[i][2] * r[2] * Q[j][2];
  };
  R[0] = comp(0, 0);
  R[1] = comp(1, 1);
  R[2] = comp(2, 2);
  R[3] = comp(0, 1);
  R[4] = comp(1, 2);
  R[5] = comp(0, 2);
}

// Inverse of a 3x3 matrix; false when it is nearly singular (|det| below tol).
bool invert3(const double B[3][3], double inv[3][3], double tol) {
  const double c00 = B[1][1] * B[2][2] - B[1][2] * B[2][1];
  const double c01 = B[1][2] * B[2][0] - B[1][0] * B[2][2];
  const double c02 = B[1][0] * B[2][1] - B[1][1] * B[2][0];
  const double det = B[0][0] * c00 + B[0][1] * c01 + B[0][2] * c02;
  if (!(std::abs(det) > tol)) return false;
  const double id = 1 / det;
  inv[0][0] = c00 * id;
  inv[1][0] = c01 * id;
  inv[2][0] = c02 * id;
  inv[0][1] = (B[0][2] * B[2][1] - B[0][1] * B[2][2]) * id;
  inv[1][1] = (B[0][0] * B[2][2] - B[0][2] * B[2][0]) * id;
  inv[2][1] = (B[0][1] * B[2][0] - B[0][0] * B[2][1]) * id;
  inv[0][2] = (B[0][1] * B[1][2] - B[0][2] * B[1][1]) * id;
  inv[1][2] = (B[0][2] * B[1][0] - B[0][0] * B[1][2]) * id;
  inv[2][2] = (B[0][0] * B[1][1] - B[0][1] * B[1][0]) * id;
  return true;
}

// The same value of a set parameter for every set (then a pair's mean is that value,
// bit for bit, and needs no per-lane lookup).
template <class F>
bool uniform(std::span<const SetParams> sets, F field) {
  for (const auto& st : sets)
    if (field(st) != field(sets[0])) return false;
  return true;
}

// Calls run.template operator()<K, D>() for the kernel and dimension of the model (the
// passes are instantiated per kernel and dimension; the 1-D Wendland kernel is not there).
template <class Run>
void with_kernel(KernelType kernel, int dim, Run& run) {
  using enum KernelType;
  if (kernel == cubic_spline) {
    if (dim == 1)
      run.template operator()<cubic_spline, 1>();
    else if (dim == 2)
      run.template operator()<cubic_spline, 2>();
    else
      run.template operator()<cubic_spline, 3>();
  } else {
    if (dim == 2)
      run.template operator()<wendland_c2, 2>();
    else
      run.template operator()<wendland_c2, 3>();
  }
}

// Calls run.template operator()<A, B>() with two flags of the model as template arguments
// (the pair loops are instantiated per pair of options, so that neither tests per pair).
template <class Run>
void with_flags(bool a, bool b, Run&& run) {
  if (a && b)
    run.template operator()<true, true>();
  else if (a)
    run.template operator()<true, false>();
  else if (b)
    run.template operator()<false, true>();
  else
    run.template operator()<false, false>();
}

// Zeros a particle's lower sums by vector stores (std::fill copied the value by a call to
// memcpy per particle; a plain loop becomes a memset, which callgrind counts by the byte).
template <std::size_t n>
[[gnu::always_inline]] inline void zero_doubles(double* p) {
  std::size_t k = 0;
  for (; k + width <= n; k += width) simd::store(0.0, p + k);
  for (; k < n; ++k) p[k] = 0.0;
}
[[gnu::always_inline]] inline void zero_lower(LowerSums1& s) {
  zero_doubles<sizeof(s.a) / sizeof(double)>(s.a);
}
[[gnu::always_inline]] inline void zero_lower(LowerSums2& s) {
  static_assert(sizeof(LowerSums2) == 8 * sizeof(double));
  zero_doubles<8>(s.f); // f, e, mu, pad
}

// Lane l: 1 where entry k0 + l is inside the row (k_end its end), else 0.
inline vdouble valid_lanes(std::int64_t k0, std::int64_t k_end) {
  const vdouble lane([](auto l) { return static_cast<double>(l); });
  vdouble v = 0.0;
  stdx::where(lane < static_cast<double>(k_end - k0), v) = 1.0;
  return v;
}

// A pair's kernel value wk and dwr = (1/r) dW/dr at the mean smoothing length hb, from
// r2 = |x_i - x_j|^2 (grad_i W_ij = dwr (x_i - x_j)). Pass 1 evaluates it and keeps dwr
// (and wk for the artificial stress) per entry for pass 2, which forms the gradient from
// its own dx with the same operations.
template <KernelType K, int D>
[[gnu::always_inline]] inline void pair_kernel(const vdouble& r2, const vdouble& hb, vdouble& wk,
                                               vdouble& dwr) {
  const vdouble r = stdx::max(stdx::sqrt(r2), 1e-9 * hb);
  kernel_simd<K, D>(r, hb, wk, dwr);
}

// Monaghan's f_ij^n = (W(r_ij) / W(dp))^n of a pair, 0 where the pair's mean epsilon is
// 0 (sets: the particles' set params; same: every set has the same epsilon, w_spacing
// and exponent).
template <KernelType K, int D>
inline vdouble artificial_factor(const vdouble& wk, const vdouble& hb, const SetParams& si,
                                 std::span<const SetParams> sets, const int* set, const int* idx,
                                 bool same) {
  auto mean = [&](auto field) {
    return same ? vdouble(field(si))
                : 0.5 * (field(si) + vdouble([&](auto l) {
                           return field(sets[static_cast<std::size_t>(set[idx[l]])]);
                         }));
  };
  vdouble fn = 0.0;
  const vdouble eps = mean([](const SetParams& st) { return st.epsilon; });
  if (stdx::any_of(eps > 0.0)) {
    const vdouble ws = mean([](const SetParams& st) { return st.w_spacing; });
    const vdouble ex = mean([](const SetParams& st) { return st.exponent; });
    const vdouble hd = D == 1 ? hb : (D == 2 ? hb * hb : hb * hb * hb);
    const vdouble t = wk * hd / (kernel_norm<K, D>() * ws);
    const vdouble t2 = t * t;
    vdouble f = t2 * t2;
    if (stdx::any_of(ex != 4.0))
      f = vdouble([&](auto l) { return ex[l] == 4.0 ? f[l] : std::pow(t[l], ex[l]); });
    stdx::where(eps > 0.0, fn) = f;
  }
  return fn;
}

// Pass 1's pair loop for one kernel (the kernel is a template parameter so that the
// loop has no per-pair branch on it), over the half lists in ascending gid (forces.hpp):
// each pair's kernel once, for both particles.
// Corr: some set normalises its gradient (the B sums are kept); Sum: some set sums its
// density (the m W sums are kept).
template <KernelType K, int D, bool Corr, bool Sum>
void kinematics_pairs(const SphView& p, std::span<const SetParams> sets, double dt,
                      SphWorkspace& w) {
  const std::size_t n = p.n_local;
  const NeighbourRead1* rd = w.read1.data();
  const double* rdp = rd->x;
  constexpr int stride = sizeof(NeighbourRead1) / sizeof(double);
  const NeighbourList& nl = w.nl;
  // The arrays' addresses in locals (the partners' sums are stored through double
  // pointers, which could alias the vectors' own).
  const int* index = nl.index.data();
  double* dwr_k = w.dwr.data();
  double* wk_k = w.wk.data();
  LowerSums1* low1 = w.low1.data();
  double* g_row = w.g_row.data();
  bool keep_w = false; // W: pass 2's artificial stress, the rows' sums of the summation density
  for (const auto& st : sets) keep_w = keep_w || st.epsilon > 0 || st.summation;
  using S1 = LowerSums1;
  for (std::size_t r = 0; r < nl.row.size(); ++r) {
    const auto i = static_cast<std::size_t>(nl.row[r]);
    const NeighbourRead1& pi = rd[i];
    const SetParams& si = sets[static_cast<std::size_t>(p.set[i])];
    // The row's pairs, `width` at a time (lane l takes the entries k0 + l): each lane sums
    // its entries in list order and the lanes are added in lane order at the end. The
    // lower sums of i are complete (every row of a lower gid has run): read them before
    // the row, whose padding entries (i itself) add their partner terms to them. A
    // padding entry has zero distance, so zero gradient and no contribution to i's own
    // gradient sums (the summation density masks them).
    const S1 lower = low1[i];
    vdouble Lv[3][3], Bv[3][3], sum_mw = 0.0;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) Lv[a][b] = Bv[a][b] = 0.0;
    const vdouble xi[3] = {pi.x[0], pi.x[1], pi.x[2]}, vi[3] = {pi.v[0], pi.v[1], pi.v[2]};
    const vdouble mi = p.mass[i], vol_i = pi.volume;
    const std::int64_t k_begin = nl.start[r], k_end = k_begin + nl.len[r];
    // First the kernel of every pair of the row, stored (pass 2 reads it too): a short
    // loop whose square roots and divisions, independent from one iteration to the next,
    // the processor overlaps. In one loop with the sums, the chain from the square root
    // to dwr held back the dozens of products that wait for it (perf, 32^3 cube: a third
    // of the loop's samples on the instructions after the square root and the division).
    // (KeepW: W is stored, a template parameter so that the loop tests nothing per pair.)
    auto kernels = [&]<bool KeepW>() {
      for (std::int64_t k0 = k_begin; k0 < k_end; k0 += width) {
        vdouble q0[4];
        simd::gather4(rdp, stride, index + k0, q0); // x, h
        vdouble dx[3];
        for (int a = 0; a < 3; ++a) dx[a] = xi[a] - q0[a];
        const vdouble hb = 0.5 * (pi.h + q0[3]);
        vdouble wk, dwr;
        pair_kernel<K, D>(dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2], hb, wk, dwr);
        simd::store(dwr, dwr_k + k0);
        if constexpr (KeepW) simd::store(wk, wk_k + k0);
        for (int a = 0; a < 3; ++a)
          simd::store(dwr * dx[a], g_row + 3 * (k0 - k_begin) + a * width);
      }
    };
    if (keep_w)
      kernels.template operator()<true>();
    else
      kernels.template operator()<false>();
    for (std::int64_t k0 = k_begin; k0 < k_end; k0 += width) {
      const int* idx = index + k0;
      vdouble q1[4];
      simd::gather4(rdp + 4, stride, idx, q1); // v, volume
      const double* gk = g_row + 3 * (k0 - k_begin);
      const vdouble g[3] = {simd::load(gk), simd::load(gk + width), simd::load(gk + 2 * width)};
      const vdouble wk = Sum ? simd::load(wk_k + k0) : vdouble(0.0);
      vdouble dx[3] = {0.0, 0.0, 0.0}; // the B sums only
      if constexpr (Corr) {
        vdouble q0[4];
        simd::gather4(rdp, stride, idx, q0); // x, h
        for (int a = 0; a < 3; ++a) dx[a] = xi[a] - q0[a];
      }
      // Volume weights V_j = m_j / rho_j: consistent across density jumps (a gas
      // interface, particles of different sets). Particle j's terms are i's with V_i for
      // V_j (grad_j W_ji = -grad_i W_ij and v_i - v_j change sign together).
      const vdouble vj = q1[3];
      vdouble dv[3], dvj[3];
      for (int a = 0; a < 3; ++a) {
        const vdouble u = q1[a] - vi[a];
        dv[a] = vj * u;
        dvj[a] = vol_i * u;
      }
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) Lv[a][b] += dv[a] * g[b];
      if (Sum && si.summation)
        sum_mw += valid_lanes(k0, k_end) * vdouble([&](auto l) { return p.mass[idx[l]]; }) * wk;
      if (Corr && si.corrected)
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) Bv[a][b] -= (vj * dx[a]) * g[b];
      const vdouble mw = Sum ? mi * wk : vdouble(0.0);
      double* q[width];
      for (int l = 0; l < width; ++l) q[l] = low1[static_cast<std::size_t>(idx[l])].a;
      const vdouble s0[4] = {dvj[0] * g[0], dvj[0] * g[1], dvj[0] * g[2], dvj[1] * g[0]};
      const vdouble s1[4] = {dvj[1] * g[1], dvj[1] * g[2], dvj[2] * g[0], dvj[2] * g[1]};
      const vdouble xj[3] = {vol_i * dx[0], vol_i * dx[1], vol_i * dx[2]};
      const vdouble s2[4] = {dvj[2] * g[2], mw, Corr ? xj[0] * g[0] : vdouble(0.0),
                             Corr ? xj[0] * g[1] : vdouble(0.0)};
      simd::scatter_add4(q, s0);
      for (auto& ql : q) ql += 4;
      simd::scatter_add4(q, s1);
      for (auto& ql : q) ql += 4;
      simd::scatter_add4(q, s2);
      if constexpr (Corr) {
        const vdouble s3[4] = {xj[0] * g[2], xj[1] * g[0], xj[1] * g[1], xj[1] * g[2]};
        const vdouble s4[4] = {xj[2] * g[0], xj[2] * g[1], xj[2] * g[2], 0.0};
        for (auto& ql : q) ql += 4;
        simd::scatter_add4(q, s3);
        for (auto& ql : q) ql += 4;
        simd::scatter_add4(q, s4);
      }
    }
    // No later row adds to i's lower sums (its partners' rows come after its lower
    // neighbours' and its own padding): zero them here, where they are in cache, for the
    // next step (sph_kinematics).
    zero_lower(low1[i]);
    if (i >= n) continue; // a ghost's row: its partners' terms only
    // The lanes' sums, four vectors at a time: L's nine and sum m W, then B's nine.
    double ls[12], bs[12];
    simd::lane_sums4({Lv[0][0], Lv[0][1], Lv[0][2], Lv[1][0]}, ls);
    simd::lane_sums4({Lv[1][1], Lv[1][2], Lv[2][0], Lv[2][1]}, ls + 4);
    simd::lane_sums4({Lv[2][2], sum_mw, 0.0, 0.0}, ls + 8);
    if (Corr && si.corrected) {
      simd::lane_sums4({Bv[0][0], Bv[0][1], Bv[0][2], Bv[1][0]}, bs);
      simd::lane_sums4({Bv[1][1], Bv[1][2], Bv[2][0], Bv[2][1]}, bs + 4);
      simd::lane_sums4({Bv[2][2], 0.0, 0.0, 0.0}, bs + 8);
    }
    double L[3][3], B[3][3];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        L[a][b] = lower.a[S1::L + 3 * a + b] + ls[3 * a + b];
        B[a][b] = Corr && si.corrected ? bs[3 * a + b] - lower.a[S1::B + 3 * a + b] : 0.0;
      }
    if (Corr && si.corrected) {
      // Normalised gradient L B^-1, B = sum V_j (x_j - x_i) (x) grad W: exact for a
      // linear velocity field also near free surfaces. A particle with too few
      // neighbours (B nearly singular) keeps the plain gradient. Below 3 dimensions B
      // has zero rows for the directions without particles: those take the identity.
      if constexpr (D < 3)
        for (int a = D; a < 3; ++a) B[a][a] = 1;
      double Bi[3][3];
      if (invert3(B, Bi, 1e-3)) {
        double Lc[3][3];
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b)
            Lc[a][b] = L[a][0] * Bi[0][b] + L[a][1] * Bi[1][b] + L[a][2] * Bi[2][b];
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) L[a][b] = Lc[a][b];
      } else {
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) Bi[a][b] = a == b ? 1.0 : 0.0;
      }
      // The momentum equation pairs sigma B^-T (sph_kinematics, after the stress update).
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) w.binv[9 * i + 3 * a + b] = Bi[a][b];
    }
    // The summation density at x(n) (tied to the particles' spacing: across a shock the
    // integrated rate drifts from it, and the pressure with it; docs/sph.md, Sod); the
    // continuity equation's density, and the rest, in kinematics_finish.
    if (si.summation) p.rho[i] = (lower.a[S1::mw] + ls[9]) + p.mass[i] * self_weight<K, D>(pi.h);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) w.lgrad[3 * a + b][i] = L[a][b];
  }
}

// The arrays of kinematics_finish, indexed by own particle: in, the velocity gradient
// (row-major), the old density, stress and energy and (when some set sums its density)
// 1 where the density is the summation's; out, the density, stress, rate of deformation,
// the rotated stress's power and the predicted energy.
struct FinishArrays {
  const double* lgrad[9];
  const double* summed; // null: no set sums its density
  const double* energy;
  double* rho;
  double* stress[6];
  double* d[6];
  double* power_old;
  double* energy_pred;
};

// kinematics_finish for particles i0 .. i0 + width - 1.
[[gnu::always_inline]] inline void finish_vector(const FinishArrays& a, double dt, std::size_t i0) {
  vdouble L[3][3];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) L[r][c] = simd::load(a.lgrad[3 * r + c] + i0);
  vdouble d[6], spin[3];
  hex8::rate_and_spin(L, d, spin);
  // Continuity, time-centred: rho(n) = rho(n-1) (1 - tr D dt/2) / (1 + tr D dt/2).
  const vdouble tr = (d[0] + d[1] + d[2]) * dt;
  const vdouble rho_old = simd::load(a.rho + i0);
  vdouble rho = rho_old * (1 - 0.5 * tr) / (1 + 0.5 * tr);
  if (a.summed) stdx::where(simd::load(a.summed + i0) == 1.0, rho) = rho_old;
  simd::store(rho, a.rho + i0);
  // Objective stress rate: rotate the old stress by Hughes-Winget, as the element does.
  vdouble Q[3][3], s[6];
  hex8::hughes_winget(spin, dt, Q);
  for (int k = 0; k < 6; ++k) s[k] = simd::load(a.stress[k] + i0);
  hex8::rotate_symmetric(Q, s);
  for (int k = 0; k < 6; ++k) {
    simd::store(s[k], a.stress[k] + i0);
    simd::store(d[k], a.d[k] + i0);
  }
  const vdouble power =
      s[0] * d[0] + s[1] * d[1] + s[2] * d[2] + 2 * (s[3] * d[3] + s[4] * d[4] + s[5] * d[5]);
  simd::store(power, a.power_old + i0);
  simd::store(simd::load(a.energy + i0) + power * dt / rho, a.energy_pred + i0);
}

// The rest of pass 1 for own particles [0, n) from their velocity gradients (w.lgrad),
// `width` particles at a time: rate of deformation and spin, continuity (sets without
// the summation density, whose density the rows have set), the old stress rotated by
// Hughes-Winget as the element does, and its power. The same operations per particle as
// one at a time (hex8's templates are the element's, for double and vdouble).
// any_summation: some set sums its density.
void kinematics_finish(const SphView& p, std::span<const SetParams> sets, double dt,
                       bool any_summation, SphWorkspace& w) {
  const std::size_t n = p.n_local;
  if (any_summation) {
    w.summed.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      w.summed[i] = sets[static_cast<std::size_t>(p.set[i])].summation ? 1.0 : 0.0;
  }
  FinishArrays a;
  for (int k = 0; k < 9; ++k) a.lgrad[k] = w.lgrad[k].data();
  a.summed = any_summation ? w.summed.data() : nullptr;
  a.energy = p.energy;
  a.rho = p.rho;
  for (int k = 0; k < 6; ++k) {
    a.stress[k] = p.stress[k];
    a.d[k] = w.d[k].data();
  }
  a.power_old = w.power_old.data();
  a.energy_pred = w.energy_pred.data();
  std::size_t i0 = 0;
  for (; i0 + width <= n; i0 += width) finish_vector(a, dt, i0);
  if (i0 == n) return;
  // The last particles through a vector's worth of copies (the last one repeated).
  constexpr int nin = 9 + 1 + 1 + 1 + 6, nout = 1 + 6 + 6 + 2;
  alignas(32) double in[nin][width], out[nout][width];
  const double* src[nin] = {a.lgrad[0],  a.lgrad[1],  a.lgrad[2],  a.lgrad[3],  a.lgrad[4],
                            a.lgrad[5],  a.lgrad[6],  a.lgrad[7],  a.lgrad[8],  a.summed,
                            a.energy,    a.rho,       a.stress[0], a.stress[1], a.stress[2],
                            a.stress[3], a.stress[4], a.stress[5]};
  for (int k = 0; k < nin; ++k)
    for (int l = 0; l < width; ++l)
      in[k][l] = src[k] ? src[k][std::min(i0 + static_cast<std::size_t>(l), n - 1)] : 0.0;
  FinishArrays t;
  for (int k = 0; k < 9; ++k) t.lgrad[k] = in[k];
  t.summed = a.summed ? in[9] : nullptr;
  t.energy = in[10];
  t.rho = in[11];
  for (int k = 0; k < 6; ++k) {
    t.stress[k] = in[12 + k];
    t.d[k] = out[1 + k];
  }
  t.power_old = out[13];
  t.energy_pred = out[14];
  finish_vector(t, dt, 0);
  double* dst[nout] = {a.rho,       a.stress[0], a.stress[1], a.stress[2], a.stress[3],
                       a.stress[4], a.stress[5], a.d[0],      a.d[1],      a.d[2],
                       a.d[3],      a.d[4],      a.d[5],      a.power_old, a.energy_pred};
  const double* res[nout] = {in[11], in[12], in[13], in[14], in[15], in[16],  in[17], out[1],
                             out[2], out[3], out[4], out[5], out[6], out[13], out[14]};
  for (int k = 0; k < nout; ++k)
    for (std::size_t l = 0; i0 + l < n; ++l) dst[k][i0 + l] = res[k][l];
}

} // namespace

void sph_kinematics(const SphView& p, std::span<const SetParams> sets, KernelType kernel,
                    const NeighbourList& candidates, double dt, SphWorkspace& w) {
  const std::size_t n = p.n_local;
  for (auto& d : w.d) d.resize(n);
  for (auto& l : w.lgrad) l.resize(n);
  w.power_old.resize(n);
  w.energy_pred.resize(n);
  bool any_corrected = false;
  for (const auto& st : sets) any_corrected = any_corrected || st.corrected;
  if (any_corrected) w.binv.resize(9 * n);
  // Pass 1's records, and their copy into the first two groups of pass 2's (x, h; v and
  // a volume that c replaces after the material update).
  using R2 = NeighbourRead2;
  static_assert(sizeof(NeighbourRead1) == 8 * sizeof(double) && R2::v == R2::x + 4);
  w.read1.resize(p.n_all);
  w.read2.resize(p.n_all);
  std::size_t k0 = 0;
  for (; k0 + width <= p.n_all; k0 += width) { // `width` records per 4 x 4 transpose
    auto ld = [&](const double* a) { return simd::load(a + k0); };
    double *q1[width], *q2[width];
    for (int l = 0; l < width; ++l) {
      q1[l] = reinterpret_cast<double*>(&w.read1[k0 + static_cast<std::size_t>(l)]);
      q2[l] = w.read2[k0 + static_cast<std::size_t>(l)].a;
    }
    const vdouble xh[4] = {ld(p.x[0]), ld(p.x[1]), ld(p.x[2]), ld(p.h)};
    const vdouble vv[4] = {ld(p.v[0]), ld(p.v[1]), ld(p.v[2]), ld(p.mass) / ld(p.rho)};
    simd::scatter4(q1, xh);
    simd::scatter4(q2, xh);
    for (int l = 0; l < width; ++l) {
      q1[l] += 4;
      q2[l] += R2::v;
    }
    simd::scatter4(q1, vv);
    simd::scatter4(q2, vv);
  }
  for (std::size_t i = k0; i < p.n_all; ++i) {
    NeighbourRead1& r = w.read1[i];
    double* r2 = w.read2[i].a;
    for (int a = 0; a < 3; ++a) {
      r2[R2::x + a] = r.x[a] = p.x[a][i];
      r2[R2::v + a] = r.v[a] = p.v[a][i];
    }
    r2[R2::h] = r.h = p.h[i];
    r2[R2::c] = r.volume = p.mass[i] / p.rho[i];
  }
  filter_neighbours(w.read1.data()->x, sizeof(NeighbourRead1) / sizeof(double), candidates, w.nl);
  w.dwr.resize(static_cast<std::size_t>(w.nl.start.back()));
  std::int64_t longest = 0;
  for (const int len : w.nl.len) longest = std::max<std::int64_t>(longest, len);
  w.g_row.resize(3 * static_cast<std::size_t>(simd::padded_size(static_cast<int>(longest))));
  // The lower sums start at zero: each row zeroes its particle's after reading them, so
  // after a pass with a row for every particle they are all zero (and stay so through a
  // resize or a reordering); otherwise (the first step) by a sweep.
  w.low1.resize(p.n_all);
  if (!w.low1_zero)
    for (LowerSums1& ls : w.low1) zero_lower(ls);
  w.low1_zero = false;
  bool any_epsilon = false;
  for (const auto& st : sets) any_epsilon = any_epsilon || st.epsilon > 0;
  bool any_summation = false;
  for (const auto& st : sets) any_summation = any_summation || st.summation;
  if (any_epsilon || any_summation) w.wk.resize(w.dwr.size());
  const int dim = sets.empty() ? 3 : sets[0].dimensions;
  auto run = [&]<KernelType K, int D>() {
    with_flags(any_corrected, any_summation,
               [&]<bool Corr, bool Sum>() { kinematics_pairs<K, D, Corr, Sum>(p, sets, dt, w); });
  };
  with_kernel(kernel, dim, run);
  w.low1_zero = w.nl.row.size() == p.n_all; // one row per particle (neighbours.hpp)
  kinematics_finish(p, sets, dt, any_summation, w);

  // Constitutive update through the batch interface, one run of a set's particles at a
  // time (own particles are in ascending gid, so each set is one contiguous run).
  constexpr std::size_t chunk = 64;
  for (std::size_t i0 = 0; i0 < n;) {
    const int set = p.set[i0];
    std::size_t i1 = i0 + 1;
    while (i1 < n && i1 - i0 < chunk && p.set[i1] == set) ++i1;
    MaterialBatch b;
    b.n = static_cast<int>(i1 - i0);
    b.dt = dt;
    for (int k = 0; k < 6; ++k) {
      b.d[k] = w.d[k].data() + i0;
      b.stress[k] = p.stress[k] + i0;
    }
    b.density = p.rho + i0;
    b.plastic_strain = p.plastic_strain + i0;
    b.temperature = p.temperature + i0;
    b.wave_speed = p.wave_speed + i0;
    b.energy = w.energy_pred.data() + i0;
    sets[static_cast<std::size_t>(set)].material->update(b);
    i0 = i1;
  }

  // The energy, time-centred, and pass 2's stress P and artificial stress R: `width`
  // particles at a time where none normalises its gradient or has an artificial stress
  // (P = sigma, R = 0: the same operations per particle), else one at a time. Where no
  // set does, pass 2 reads neither R nor S6-S8 (the shear again): they are not written.
  // P's first six components, the new density, the mass and the wave speed go straight
  // into pass 2's records (the exchange sends them from there).
  const bool all_plain = !any_corrected && !any_epsilon;
  auto plain = [&](std::size_t i) {
    const SetParams& st = sets[static_cast<std::size_t>(p.set[i])];
    return !st.corrected && !(st.epsilon > 0);
  };
  for (std::size_t i = 0; i < n;) {
    bool vector = i + width <= n;
    for (int l = 0; l < width && vector; ++l) vector = plain(i + static_cast<std::size_t>(l));
    if (vector) {
      vdouble s[6], d[6];
      for (int k = 0; k < 6; ++k) {
        s[k] = simd::load(p.stress[k] + i);
        d[k] = simd::load(w.d[k].data() + i);
      }
      const vdouble power =
          s[0] * d[0] + s[1] * d[1] + s[2] * d[2] + 2 * (s[3] * d[3] + s[4] * d[4] + s[5] * d[5]);
      const vdouble rho = simd::load(p.rho + i);
      simd::store(simd::load(p.energy + i) +
                      0.5 * (simd::load(w.power_old.data() + i) + power) * dt / rho,
                  p.energy + i);
      double* q[width];
      for (int l = 0; l < width; ++l) q[l] = w.read2[i + static_cast<std::size_t>(l)].a + R2::S;
      simd::scatter4(q, {s[0], s[1], s[2], s[3]});
      for (auto& ql : q) ql += R2::S45 - R2::S;
      simd::scatter4(q, {s[4], s[5], rho, simd::load(p.mass + i)});
      for (int l = 0; l < width; ++l)
        q[l][R2::c - R2::S45] = p.wave_speed[i + static_cast<std::size_t>(l)];
      if (!all_plain) {
        for (int k = 0; k < 6; ++k) simd::store(0.0, p.R[k] + i);
        for (int k = 0; k < 3; ++k) simd::store(s[k + 3], p.S678[k] + i);
      }
      i += width;
      continue;
    }
    const SetParams& si = sets[static_cast<std::size_t>(p.set[i])];
    double s[6];
    for (int k = 0; k < 6; ++k) s[k] = p.stress[k][i];
    const double power = s[0] * w.d[0][i] + s[1] * w.d[1][i] + s[2] * w.d[2][i] +
                         2 * (s[3] * w.d[3][i] + s[4] * w.d[4][i] + s[5] * w.d[5][i]);
    const double rho = p.rho[i];
    p.energy[i] += 0.5 * (w.power_old[i] + power) * dt / rho;
    double* r = w.read2[i].a;
    if (si.corrected) {
      // P = sigma B^-T: P_ab = sigma_ac Bi_bc (pass 2's stress for this particle).
      const double* bi = &w.binv[9 * i];
      const double sg[3][3] = {{s[0], s[3], s[5]}, {s[3], s[1], s[4]}, {s[5], s[4], s[2]}};
      double P[3][3];
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          P[a][b] = sg[a][0] * bi[3 * b] + sg[a][1] * bi[3 * b + 1] + sg[a][2] * bi[3 * b + 2];
      const double pk[9] = {P[0][0], P[1][1], P[2][2], P[0][1], P[1][2],
                            P[0][2], P[1][0], P[2][1], P[2][0]};
      for (int k = 0; k < 6; ++k) r[R2::S + k] = pk[k];
      for (int k = 0; k < 3; ++k) p.S678[k][i] = pk[k + 6];
    } else {
      for (int k = 0; k < 6; ++k) r[R2::S + k] = s[k];
      for (int k = 0; k < 3; ++k) p.S678[k][i] = s[k + 3];
    }
    r[R2::c] = p.wave_speed[i];
    r[R2::rho] = rho;
    r[R2::mass] = p.mass[i];
    double R[6] = {0, 0, 0, 0, 0, 0};
    if (si.epsilon > 0) artificial_stress(s, si.epsilon, R);
    for (int k = 0; k < 6; ++k) p.R[k][i] = R[k];
    ++i;
  }
}

namespace {

// Pass 2's pair loop. Corr: some set normalises its gradient (P is not symmetric); AS: some
// set has an artificial stress. Both are template parameters so that the common loop
// (neither) keeps no value live for them: the velocity difference dies after the
// viscosity and dv . g, before the stress groups are loaded (GCC kept it, and spilled).
// SameVisc: every set has the same viscosity coefficients (a template parameter too: as a
// run-time test in the loop, GCC kept the partners' indices on the stack for the other
// branch's gather, four stores per four pairs and a test).
template <KernelType K, int D, bool Corr, bool AS, bool SameVisc>
void forces_pairs(const SphView& p, std::span<const SetParams> sets, SphWorkspace& w,
                  SphResult& res) {
  using R2 = NeighbourRead2;
  using R2r = NeighbourRead2Rest;
  const std::size_t n = p.n_local;
  const NeighbourList& nl = w.nl;
  const R2* rd = w.read2.data();
  const R2r* rdr = w.read2r.data();
  const double* rdrp = rdr->a;
  constexpr int stride_r = sizeof(R2r) / sizeof(double);
  static_assert(sizeof(R2) == 2 * sizeof(LowerSums2));
  // The arrays' addresses in locals: the partners' sums are stored through double
  // pointers, which could otherwise alias the vectors' own pointers (reloaded every time).
  const int* index = nl.index.data();
  const double* dwr_k = w.dwr.data();
  const double* wk_k = w.wk.data();
  LowerSums2* low2 = w.low2.data();
  const bool same_as = uniform(sets, [](const SetParams& st) {
    return std::array<double, 3>{st.epsilon, st.w_spacing, st.exponent};
  });
  for (std::size_t r = 0; r < nl.row.size(); ++r) {
    const auto i = static_cast<std::size_t>(nl.row[r]);
    const double* pi = rd[i].a;
    const double* pir = rdr[i].a;
    const SetParams& si = sets[static_cast<std::size_t>(p.set[i])];
    // The row's pairs `width` at a time, lanes summed in lane order at the end, after the
    // lower sums (see pass 1). Entries past the row's end (i itself) have zero gradients
    // and no approach: they add nothing to i's sums (their partner terms go to i's lower
    // sums, already read).
    const LowerSums2 lower = low2[i];
    const double mu_lower = lower.mu;
    const vdouble mi = pi[R2::mass];
    // The row particle's values that the loop reads, as vectors in memory: operands of the
    // arithmetic there instead of broadcasts again in every iteration (GCC has no
    // registers to keep them in; the empty asm makes the array's address escape, so that
    // it stays in memory).
    // pb[rest + k] holds the value at offset k of NeighbourRead2Rest (S6-S8); then i's
    // alpha, beta (its set's) and 1/rho (divided here, the same bits as a stored one), and
    // the pair's -(alpha_i + alpha_j) and beta_i + beta_j where every set has the same
    // viscosity (the loop's sums, once per row: the same bits).
    constexpr int rest = sizeof(R2) / sizeof(double);
    constexpr int alpha_i = rest + 3, beta_i = alpha_i + 1, inv_rho = beta_i + 1;
    constexpr int visc_a = inv_rho + 1, visc_b = visc_a + 1;
    vdouble pb[visc_b + 1];
    for (int k = R2::x; k <= R2::rho; ++k) pb[k] = pi[k];
    if constexpr (Corr)
      for (int k = R2r::S6; k < R2r::S6 + 3; ++k) pb[rest + k] = pir[k];
    pb[alpha_i] = si.alpha;
    pb[beta_i] = si.beta;
    pb[inv_rho] = 1 / pi[R2::rho];
    pb[visc_a] = -(pb[alpha_i] + pb[alpha_i]);
    pb[visc_b] = pb[beta_i] + pb[beta_i];
    asm volatile("" : : "r"(pb) : "memory");
    vdouble accv[4] = {0.0, 0.0, 0.0, 0.0}, mumv = 0.0; // force sums, energy rate
    const std::int64_t k_begin = nl.start[r], k_end = k_begin + nl.len[r];
    for (std::int64_t k0 = k_begin; k0 < k_end; k0 += width) {
      const int* idx = index + k0;
      // The partners' records and lower sums from one byte offset per partner (the record
      // is twice the lower sums: an address mode's scale instead of a second shift).
      double* q[width];        // the partners' lower sums: f, e at q[l], mu at q[l] + 4
      const double* qd[width]; // and their records
      for (int l = 0; l < width; ++l) {
        const std::ptrdiff_t o = static_cast<std::ptrdiff_t>(idx[l]) * sizeof(LowerSums2);
        q[l] = reinterpret_cast<LowerSums2*>(reinterpret_cast<char*>(low2) + o)->f;
        qd[l] = reinterpret_cast<const R2*>(reinterpret_cast<const char*>(rd) + 2 * o)->a;
      }
      auto gather = [&](int offset, vdouble(&out)[4]) {
        const double* row[width];
        for (int l = 0; l < width; ++l) row[l] = qd[l] + offset;
        simd::gather4(row, out);
      };
      // In stages, so that fewer values are live at once: the gradient from x, h; the
      // viscosity's approach and dv . g from v, c; the viscosity from S4, S5, rho, m;
      // then the stress groups and the pair's T.
      vdouble qx[4], qv[4], qr[4];
      gather(R2::x, qx); // x, h
      vdouble dx[3];
      for (int a = 0; a < 3; ++a) dx[a] = pb[R2::x + a] - qx[a];
      const vdouble hb = 0.5 * (pb[R2::h] + qx[3]);
      const vdouble r2 = dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2];
      const vdouble dwr = simd::load(dwr_k + k0);
      const vdouble g[3] = {dwr * dx[0], dwr * dx[1], dwr * dx[2]};
      gather(R2::v, qv); // v, c
      vdouble dv[3];
      for (int a = 0; a < 3; ++a) dv[a] = pb[R2::v + a] - qv[a];
      const vdouble vr = dv[0] * dx[0] + dv[1] * dx[1] + dv[2] * dx[2];
      const vdouble dvg = dv[0] * g[0] + dv[1] * g[1] + dv[2] * g[2];
      vdouble fn = 0.0;
      if constexpr (AS)
        fn = artificial_factor<K, D>(simd::load(wk_k + k0), hb, si, sets, p.set, idx, same_as);
      gather(R2::S45, qr); // S4, S5, rho, m
      vdouble visc = 0.0;
      const auto approaching = vr < 0.0;
      if (stdx::any_of(approaching)) {
        const vdouble mu = hb * vr / (r2 + 0.01 * hb * hb);
        const vdouble cb = 0.5 * (pb[R2::c] + qv[3]);
        // Pi_ij = (-alpha c mu + beta mu^2) / rho_ij with rho_ij = (rho_i + rho_j) / 2.
        vdouble pv;
        if constexpr (SameVisc) {
          pv = (pb[visc_a] * cb * mu + pb[visc_b] * mu * mu) / (pb[R2::rho] + qr[2]);
        } else {
          vdouble qa[4];
          simd::gather4(rdrp + R2r::R45, stride_r, idx, qa); // R4, R5, alpha, beta
          pv = (-(pb[alpha_i] + qa[2]) * cb * mu + (pb[beta_i] + qa[3]) * mu * mu) /
               (pb[R2::rho] + qr[2]);
        }
        stdx::where(approaching, visc) = pv;
        // The largest approach of the pair for both particles' stable steps.
        vdouble muj = 0.0;
        stdx::where(approaching, muj) = -mu;
        mumv = stdx::max(mumv, muj);
        double* qm[width];
        for (int l = 0; l < width; ++l) qm[l] = q[l] + 4;
        simd::scatter_max(qm, muj);
      }
      // Half the viscous dissipation of the pair heats each particle.
      const vdouble half_visc = 0.5 * visc * dvg;
      const vdouble irr = pb[inv_rho] * (1.0 / qr[2]);
      vdouble qs[4], qu[4] = {0.0, 0.0, 0.0, 0.0};
      gather(R2::S, qs);                                                    // S0..S3
      if constexpr (Corr) simd::gather4(rdrp + R2r::S6, stride_r, idx, qu); // S6..S8, has_r
      // T = (P_i + P_j + f^n (R_i + R_j)) / (rho_i rho_j) - Pi I; T[6..8] (yx zy zx)
      // differ from T[3..5] only where a gradient is normalised (Corr).
      constexpr int nt = Corr ? 9 : 6;
      const vdouble Sj[9] = {qs[0], qs[1], qs[2], qs[3], qr[0], qr[1], qu[0], qu[1], qu[2]};
      vdouble T[nt];
      for (int c = 0; c < nt; ++c)
        T[c] = (pb[c < 6 ? R2::S + c : rest + R2r::S6 + c - 6] + Sj[c]) * irr;
      vdouble rg = 0.0, rgj = 0.0;
      if (AS && stdx::any_of(fn > 0.0)) {
        if constexpr (!Corr) simd::gather4(rdrp + R2r::S6, stride_r, idx, qu); // has_r
        if (pir[R2r::has_r] != 0.0 || stdx::any_of(qu[3] > 0.0)) {
          vdouble qR[4], qR45[4];
          simd::gather4(rdrp + R2r::R, stride_r, idx, qR);
          simd::gather4(rdrp + R2r::R45, stride_r, idx, qR45);
          const vdouble Rj[6] = {qR[0], qR[1], qR[2], qR[3], qR45[0], qR45[1]};
          const double Ri[6] = {pir[R2r::R],     pir[R2r::R + 1], pir[R2r::R + 2],
                                pir[R2r::R + 3], pir[R2r::R45],   pir[R2r::R45 + 1]};
          const vdouble fi = fn * irr;
          for (int c = 0; c < 6; ++c) T[c] += fi * (Ri[c] + Rj[c]);
          if constexpr (Corr)
            for (int c = 6; c < 9; ++c) T[c] += fi * (Ri[c - 3] + Rj[c - 3]);
          // The artificial stress's own work on particle i (the stress's is in pass 1).
          rg = fi * (dv[0] * (Ri[0] * g[0] + Ri[3] * g[1] + Ri[5] * g[2]) +
                     dv[1] * (Ri[3] * g[0] + Ri[1] * g[1] + Ri[4] * g[2]) +
                     dv[2] * (Ri[5] * g[0] + Ri[4] * g[1] + Ri[2] * g[2]));
          // And on particle j (v_ji and grad_j W_ji reverse together).
          rgj = fi * (dv[0] * (Rj[0] * g[0] + Rj[3] * g[1] + Rj[5] * g[2]) +
                      dv[1] * (Rj[3] * g[0] + Rj[1] * g[1] + Rj[4] * g[2]) +
                      dv[2] * (Rj[5] * g[0] + Rj[4] * g[1] + Rj[2] * g[2]));
        }
      }
      T[0] -= visc;
      T[1] -= visc;
      T[2] -= visc;
      const vdouble mj = qr[3];
      const int yx = Corr ? 6 : 3, zy = Corr ? 7 : 4, zx = Corr ? 8 : 5;
      const vdouble tg[3] = {T[0] * g[0] + T[3] * g[1] + T[5] * g[2],
                             T[yx] * g[0] + T[1] * g[1] + T[4] * g[2],
                             T[zx] * g[0] + T[zy] * g[1] + T[2] * g[2]};
      for (int a = 0; a < 3; ++a) accv[a] += mj * tg[a];
      // Without an artificial stress rg = rgj = 0 and x - 0 is x: the same bits.
      const vdouble ei = AS ? half_visc - rg : half_visc, ej = AS ? half_visc - rgj : half_visc;
      accv[3] += mj * ei;
      // Particle j's terms: the same T with grad_j W_ji = -g (its force sum is reversed).
      simd::scatter_add4(q, {mi * tg[0], mi * tg[1], mi * tg[2], mi * ej});
    }
    zero_lower(low2[i]); // for the next step, as in pass 1
    double sums[4];
    simd::lane_sums4(accv, sums);
    const double acc[3] = {sums[0] - lower.f[0], sums[1] - lower.f[1], sums[2] - lower.f[2]};
    const double de = lower.e + sums[3];
    if (i >= n) continue; // a ghost's row: its partners' terms only
    double mu_max = mu_lower;
    for (int l = 0; l < width; ++l) mu_max = std::max(mu_max, static_cast<double>(mumv[l]));
    for (int a = 0; a < 3; ++a) p.force[a][i] = pi[R2::mass] * acc[a];
    p.energy_rate[i] = de;
    const double ci = pi[R2::c];
    double dt = courant * pi[R2::h] / (ci + 1.2 * (si.alpha * ci + si.beta * mu_max));
    const double v2 =
        pi[R2::v] * pi[R2::v] + pi[R2::v + 1] * pi[R2::v + 1] + pi[R2::v + 2] * pi[R2::v + 2];
    if (v2 > 0) dt = std::min(dt, max_move * pi[R2::h] / std::sqrt(v2));
    if (dt < res.dt_stable || (dt == res.dt_stable && p.gid[i] < res.stable_gid)) {
      res.dt_stable = dt;
      res.stable_gid = p.gid[i];
    }
    const bool finite = std::isfinite(acc[0]) && std::isfinite(acc[1]) && std::isfinite(acc[2]) &&
                        std::isfinite(p.stress[0][i]) && std::isfinite(pi[R2::rho]);
    if (!finite && (res.nonfinite_gid < 0 || p.gid[i] < res.nonfinite_gid))
      res.nonfinite_gid = p.gid[i];
  }
}

} // namespace

void smoothing_lengths(std::span<const SetParams> sets, const int* set, const double* rho,
                       std::size_t n, double* h) {
  if (n == 0) return;
  const int dim = sets[0].dimensions;
  // h0 (rho0 / rho)^(1/d) within [h_min, h_max] of the particles' sets; `at(l)` is the
  // particle of lane l.
  auto lengths = [&](auto at, const vdouble& rho_v) {
    auto of = [&](double SetParams::*field) {
      return vdouble([&](auto l) { return sets[static_cast<std::size_t>(set[at(l)])].*field; });
    };
    const vdouble r = of(&SetParams::rho0) / rho_v;
    const vdouble scaled =
        of(&SetParams::h0) * (dim == 3 ? simd::cube_root(r) : (dim == 2 ? stdx::sqrt(r) : r));
    return stdx::min(stdx::max(scaled, of(&SetParams::h_min)), of(&SetParams::h_max));
  };
  std::size_t i0 = 0;
  for (; i0 + width <= n; i0 += width) {
    const auto at = [i0](auto l) { return i0 + static_cast<std::size_t>(l); };
    simd::store(lengths(at, simd::load(rho + i0)), h + i0);
  }
  if (i0 < n) { // the last particles, repeated in the unused lanes
    const auto at = [&](auto l) { return std::min(i0 + static_cast<std::size_t>(l), n - 1); };
    const vdouble hv = lengths(at, vdouble([&](auto l) { return rho[at(l)]; }));
    for (std::size_t l = 0; i0 + l < n; ++l) h[i0 + l] = hv[l];
  }
}

void sph_forces(const SphView& p, std::span<const SetParams> sets, KernelType kernel,
                SphWorkspace& w, SphResult& res) {
  using R2r = NeighbourRead2Rest;
  bool any_corrected = false, any_epsilon = false;
  for (const auto& st : sets) {
    any_corrected = any_corrected || st.corrected;
    any_epsilon = any_epsilon || st.epsilon > 0;
  }
  // The records hold what the common path reads (pass 1 and the exchange filled them).
  // The rest records are read only by a normalised gradient, an artificial stress (its
  // groups S6-S8 and has_r, R0-R3, R4, R5) and sets of different viscosity (alpha, beta):
  // without those they are not written (forces_pairs reads them under the same conditions).
  const bool same_visc = uniform(sets, [](const SetParams& st) {
    return std::array<double, 2>{st.alpha, st.beta};
  });
  const bool stress_rest = any_corrected || any_epsilon;
  const bool any_rest = stress_rest || !same_visc;
  w.read2r.resize(p.n_all);
  w.low2.resize(p.n_all); // zeros as pass 1's (sph_kinematics)
  if (!w.low2_zero) std::fill(w.low2.begin(), w.low2.end(), LowerSums2{});
  w.low2_zero = false;
  // `width` records at a time: four fields of every record per 4 x 4 transpose.
  std::size_t i0 = 0;
  for (; any_rest && i0 + width <= p.n_all; i0 += width) {
    double* qr[width];
    for (int l = 0; l < width; ++l) qr[l] = w.read2r[i0 + static_cast<std::size_t>(l)].a;
    auto put_r = [&](int offset, const vdouble& a, const vdouble& b, const vdouble& c,
                     const vdouble& d) {
      double* qo[width];
      for (int l = 0; l < width; ++l) qo[l] = qr[l] + offset;
      simd::scatter4(qo, {a, b, c, d});
    };
    auto ld = [&](const double* a) { return simd::load(a + i0); };
    auto per_set = [&](auto field) {
      return vdouble([&](auto l) { return field(sets[static_cast<std::size_t>(p.set[i0 + l])]); });
    };
    vdouble R4 = 0.0, R5 = 0.0; // R is zero without an artificial stress
    if (stress_rest) {
      vdouble R[4];
      for (int c = 0; c < 4; ++c) R[c] = ld(p.R[c]);
      R4 = ld(p.R[4]);
      R5 = ld(p.R[5]);
      const auto any =
          R[0] != 0.0 || R[1] != 0.0 || R[2] != 0.0 || R[3] != 0.0 || R4 != 0.0 || R5 != 0.0;
      vdouble has_r = 0.0;
      stdx::where(any, has_r) = 1.0;
      put_r(R2r::S6, ld(p.S678[0]), ld(p.S678[1]), ld(p.S678[2]), has_r);
      put_r(R2r::R, R[0], R[1], R[2], R[3]);
    }
    put_r(R2r::R45, R4, R5, per_set([](const SetParams& st) { return st.alpha; }),
          per_set([](const SetParams& st) { return st.beta; }));
  }
  for (std::size_t i = i0; any_rest && i < p.n_all; ++i) {
    double* rr = w.read2r[i].a;
    const SetParams& si = sets[static_cast<std::size_t>(p.set[i])];
    double R[6] = {0, 0, 0, 0, 0, 0};
    if (stress_rest) {
      int any = 0;
      for (int c = 0; c < 6; ++c) {
        R[c] = p.R[c][i];
        any |= R[c] != 0.0;
      }
      for (int c = 0; c < 3; ++c) rr[R2r::S6 + c] = p.S678[c][i];
      rr[R2r::has_r] = any ? 1.0 : 0.0;
      for (int c = 0; c < 4; ++c) rr[R2r::R + c] = R[c];
    }
    rr[R2r::R45] = R[4];
    rr[R2r::R45 + 1] = R[5];
    rr[R2r::alpha] = si.alpha;
    rr[R2r::beta] = si.beta;
  }
  const int dim = sets.empty() ? 3 : sets[0].dimensions;
  auto run = [&]<KernelType K, int D>() {
    with_flags(any_corrected, any_epsilon, [&]<bool Corr, bool Eps>() {
      if (same_visc)
        forces_pairs<K, D, Corr, Eps, true>(p, sets, w, res);
      else
        forces_pairs<K, D, Corr, Eps, false>(p, sets, w, res);
    });
  };
  with_kernel(kernel, dim, run);
  w.low2_zero = w.nl.row.size() == p.n_all;
}

} // namespace anvil::sph
