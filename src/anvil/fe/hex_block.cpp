#include "anvil/fe/hex_block.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "anvil/core/simd.hpp"
#include "anvil/fe/hex8.hpp"

namespace anvil {

static_assert(ThickShell::max_points == hex8::thick_shell_max_points);

using simd::vdouble;
using simd::width;
namespace stdx = simd::stdx;

namespace {

using simd::padded_size;

// Chunk scratch inside HexWorkspace: one array of `chunk` values per entry, slot_stride
// apart.
enum Slot : int {
  s_d0,
  s_d1,
  s_d2,
  s_d3,
  s_d4,
  s_d5, // rate of deformation
  s_density,
  s_wave_speed,
  s_power_old, // old (rotated) stress : D
  s_volume_mid,
  s_q0,
  s_flow = s_q0, // flow stress (assumed strain; s_q* hold the stiffness form's rotation,
                 // s_q1 a thick shell's wave speed at each point after the first)
  s_q1,
  s_q2,
  s_q3,
  s_q4,
  s_q5,
  s_q6,
  s_q7,
  s_q8,
  s_x0,              // 24 gathered positions (3 a + i)
  s_v0 = s_x0 + 24,  // 24 gathered velocities
  s_pd0 = s_v0 + 24, // thick shell: the rate of deformation at each point (6 p + k)
  s_count = s_pd0 + 6 * hex8::thick_shell_max_points
};

// Stage scratch of one vector of elements, after the chunk scratch: `width` values per
// entry. A stage writes here and the next reads it back after simd::stage_barrier(), as
// memory operands, instead of keeping everything live (x, v and B alone are 72 vectors
// against 16 registers).
enum Tmp : int {
  t_edge0 = 0,          // 36 edge sums (3 edge + i)
  t_b0 = t_edge0 + 36,  // 24 gradient entries 12 B_ia (3 a + i), stage C
  t_xm0 = t_b0 + 24,    // mid-step coordinates (8 i + a: x for all forms, y and z for the
                        // thick shell), stage A
  t_rows0 = t_xm0 + 24, // corner forces as in the corner slots, 8 per lane, component i
                        // at (t_rows0 + 8 i) width: nodal assembly without the slots
  t_count = t_rows0 + 24
};

constexpr int prefetch_ahead = 32; // elements

// Distance between the chunk scratch's arrays, in doubles: a chunk plus half a cache line,
// so that no two arrays' entries of one lane share their address's low 12 bits. With a
// distance of exactly one chunk (512 bytes) every eighth array's did, and a load whose
// address matches an earlier store's in those bits can wait for it ("4K aliasing"; with
// this stride the thick shell's FE phase measured 7% faster, the viscous element's 3%:
// docs/performance.md, "The chunk scratch's stride").
constexpr int slot_stride = HexWorkspace::chunk + 4;

// Nodal positions and velocities packed per node (x0 v0 x1 v1 x2 v2, padded to a cache
// line), so that a corner's six values come from one line in three 128-bit loads.
constexpr int node_stride = 8;

// Packs nodes [lo, hi) of the nodal arrays into p (node k at p + node_stride k).
// A template only so that each of detail::block_forces' instantiations has its own
// copy, called once and inlined as when hex_forces was the only caller (as gather below).
template <int Form>
void pack_nodes(const NodalView& n, int lo, int hi, double* __restrict p) {
  const double* __restrict x0 = n.x[0];
  const double* __restrict x1 = n.x[1];
  const double* __restrict x2 = n.x[2];
  const double* __restrict v0 = n.v[0];
  const double* __restrict v1 = n.v[1];
  const double* __restrict v2 = n.v[2];
  int k = lo;
#if defined(__AVX__)
  // four nodes at a time: six loads, six unpacks, twelve stores
  for (; k + 4 <= hi; k += 4) {
    double* q = p + node_stride * static_cast<std::size_t>(k);
    const __m256d x[3] = {_mm256_loadu_pd(x0 + k), _mm256_loadu_pd(x1 + k),
                          _mm256_loadu_pd(x2 + k)};
    const __m256d v[3] = {_mm256_loadu_pd(v0 + k), _mm256_loadu_pd(v1 + k),
                          _mm256_loadu_pd(v2 + k)};
    for (int i = 0; i < 3; ++i) {
      const __m256d lo_pairs = _mm256_unpacklo_pd(x[i], v[i]); // nodes 0 and 2
      const __m256d hi_pairs = _mm256_unpackhi_pd(x[i], v[i]); // nodes 1 and 3
      _mm_storeu_pd(q + 2 * i, _mm256_castpd256_pd128(lo_pairs));
      _mm_storeu_pd(q + node_stride + 2 * i, _mm256_castpd256_pd128(hi_pairs));
      _mm_storeu_pd(q + 2 * node_stride + 2 * i, _mm256_extractf128_pd(lo_pairs, 1));
      _mm_storeu_pd(q + 3 * node_stride + 2 * i, _mm256_extractf128_pd(hi_pairs, 1));
    }
  }
#endif
  for (; k < hi; ++k) {
    double* q = p + node_stride * static_cast<std::size_t>(k);
    q[0] = x0[k];
    q[1] = v0[k];
    q[2] = x1[k];
    q[3] = v1[k];
    q[4] = x2[k];
    q[5] = v2[k];
  }
}

// Stage A1: loads the corner positions and velocities of elements e..e+width-1 from the
// packed nodes, keeps them in the chunk scratch (xs, vs: lane offset included) for stage
// C, and writes the edge sums of the mid-step positions x - h v (and their x
// coordinates, all three for the thick shell) to the stage scratch t. conn: the block's eight
// corner index arrays; ahead: the element to prefetch for.
template <int Form>
void gather(const int* const (&conn)[8], const double* packed, int e, int ahead, double h,
            double* __restrict xs, double* __restrict vs, double* __restrict t) {
  constexpr int S = slot_stride;
  constexpr int W = width;
  vdouble xm[8][3];
  _Pragma("GCC unroll 8") for (int a = 0; a < 8; ++a) {
    const int* idx = conn[a] + e;
    std::ptrdiff_t off[W];
    _Pragma("GCC unroll 8") for (int k = 0; k < W; ++k) off[k] =
        node_stride * static_cast<std::ptrdiff_t>(idx[k]);
    // Prefetch the corner's nodes some elements ahead (one line per node and lane).
    _Pragma("GCC unroll 8") for (int k = 0; k < W; ++k)
        __builtin_prefetch(packed + node_stride * static_cast<std::ptrdiff_t>(conn[a][ahead + k]));
    _Pragma("GCC unroll 3") for (int i = 0; i < 3; ++i) {
      vdouble x, v;
      simd::gather_pairs(packed + 2 * i, off, x, v);
      // Positions relative to the element's first corner: the kinematics depend on
      // differences only, and the gradient's products of absolute coordinates lost
      // (D / h)^2 of the volume's digits for a model at distance D from the origin (QA
      // round 22: a 1 cm cube 1 km away had 25% too much mass). The first corner's
      // absolute position waits in its slot (a memory operand, no register held through
      // the loop: the thick shell's kernel was 6% slower with three), zeroed below.
      if (a == 0) {
        simd::store(x, xs + i * S);
        xm[a][i] = vdouble(0.0) - h * v;
      } else {
        x -= simd::load(xs + i * S);
        simd::store(x, xs + (3 * a + i) * S);
        xm[a][i] = x - h * v;
      }
      simd::store(v, vs + (3 * a + i) * S);
    }
    simd::store(xm[a][0], t + (t_xm0 + a) * W);
    if constexpr (Form == 2) {
      simd::store(xm[a][1], t + (t_xm0 + 8 + a) * W);
      simd::store(xm[a][2], t + (t_xm0 + 16 + a) * W);
    }
  }
  _Pragma("GCC unroll 3") for (int i = 0; i < 3; ++i) simd::store(vdouble(0.0), xs + i * S);
  vdouble s[12][3];
  hex8::edge_sums(xm, s);
  _Pragma("GCC unroll 12") for (int k = 0; k < 12; ++k)
      _Pragma("GCC unroll 3") for (int i = 0; i < 3; ++i)
          simd::store(s[k][i], t + (t_edge0 + 3 * k + i) * W);
}

// Edge sums of the positions in the chunk scratch (stage C; xs at the lane offset), one
// direction at a time (eight positions live, each loaded once).
void edge_sums(const double* __restrict xs, double* __restrict t) {
  constexpr int S = slot_stride;
  _Pragma("GCC unroll 3") for (int i = 0; i < 3; ++i) {
    vdouble x[8];
    _Pragma("GCC unroll 8") for (int a = 0; a < 8; ++a) x[a] = simd::load(xs + (3 * a + i) * S);
    _Pragma("GCC unroll 12") for (int k = 0; k < 12; ++k) simd::store(
        x[hex8::edge_nodes[k][0]] + x[hex8::edge_nodes[k][1]], t + (t_edge0 + 3 * k + i) * width);
    simd::stage_barrier();
  }
}

// The gradient 12 B from the edge sums in t, one direction i at a time: the twelve
// edge sums of direction i + 2 in registers, those of i + 1 as memory operands. Calls
// use(a, i, 12 B_ia) for each entry as soon as it is formed.
template <class Use>
[[gnu::always_inline]] inline void gradient_by_direction(const double* t, Use&& use) {
  constexpr int W = width;
  _Pragma("GCC unroll 12") for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    vdouble sk[12];
    _Pragma("GCC unroll 12") for (int m = 0; m < 12; ++m) sk[m] =
        simd::load(t + (t_edge0 + 3 * m + k) * W);
    _Pragma("GCC unroll 12") for (int a = 0; a < 8; ++a)
        use(a, i,
            hex8::gradient12<vdouble>(
                a, [&](int m) { return simd::load(t + (t_edge0 + 3 * m + j) * W); },
                [&](int m) -> const vdouble& { return sk[m]; }));
  }
}

// Thick shell, stage A: the points' rates of deformation D_p = D + zeta_p A - c_p e_z e_z
// for elements e..e+width-1 (chunk lane l), written to pd (6 p + k chunk arrays), their
// old stresses rotated by Q, and their stress power sum_p w_p / 2 sigma_p : D_p returned.
// A is the bending rate per unit zeta at the mid-step, from the zeta group's hourglass
// velocities in the co-rotational frame (curvature rates k_xx = q_x,xi zeta / len0,
// k_yy = q_y,eta zeta / len1, twist k_xy = q_x,eta zeta / len1 + q_y,xi zeta / len0)
// with the plane-stress thickness rate -nu_ps (k_xx + k_yy); c_p drives each point's
// thickness stress towards the element's average (docs/element.md, "Thick shell").
// L is the mid-step velocity gradient, d its symmetric part; xm the mid-step positions in the
// stage scratch (8 i + a), vs the velocities in the chunk scratch.
[[gnu::always_inline]] inline vdouble
shell_point_rates(double* const (&ps)[hex8::thick_shell_max_points][6], int e, int l, double dt,
                  const vdouble (&L)[3][3], const vdouble (&d)[6], const vdouble (&Q)[3][3], int np,
                  const double* zeta_p, const double* w_p, double nu_ps, double M, const double* xm,
                  const double* vs, double* pd) {
  constexpr int S = slot_stride;
  vdouble J[3][3], gx[3][4], qz[3][2];
  _Pragma("GCC unroll 3") for (int i = 0; i < 3; ++i) {
    vdouble col[8], gv[4];
    _Pragma("GCC unroll 8") for (int a = 0; a < 8; ++a) col[a] =
        simd::load(xm + (8 * i + a) * width);
    hex8::gamma_sums(col, gx[i]);
    hex8::natural_sums(col, J[i]);
    _Pragma("GCC unroll 8") for (int a = 0; a < 8; ++a) col[a] =
        simd::load(vs + (3 * a + i) * S + l);
    hex8::gamma_sums(col, gv);
    qz[i][0] = gv[0];
    qz[i][1] = gv[1];
  }
  _Pragma("GCC unroll 2") for (int al = 0; al < 2; ++al)
      _Pragma("GCC unroll 3") for (int i = 0; i < 3; ++i) qz[i][al] -=
      L[i][0] * gx[0][al] + L[i][1] * gx[1][al] + L[i][2] * gx[2][al];
  vdouble ax[3][3], ext[3];
  hex8::corotational_frame(J, ax, ext);
  auto local = [&](int dd, int al) {
    return ax[dd][0] * qz[0][al] + ax[dd][1] * qz[1][al] + ax[dd][2] * qz[2][al];
  };
  const vdouble il0 = 1.0 / ext[0], il1 = 1.0 / ext[1];
  const vdouble kxx = local(0, 1) * il0, kyy = local(1, 0) * il1;
  const vdouble kxy = local(0, 0) * il1 + local(1, 1) * il0;
  const vdouble kzz = -nu_ps * (kxx + kyy);
  const int ij[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};
  vdouble A[6], Z[6];
  _Pragma("GCC unroll 6") for (int k = 0; k < 6; ++k) {
    const int i = ij[k][0], j = ij[k][1];
    Z[k] = ax[2][i] * ax[2][j];
    A[k] = ax[0][i] * ax[0][j] * kxx + ax[1][i] * ax[1][j] * kyy +
           (0.5 * kxy) * (ax[0][i] * ax[1][j] + ax[1][i] * ax[0][j]) + Z[k] * kzz;
  }
  // The points' old stresses into the new frame, and their thickness stresses.
  vdouble szz[hex8::thick_shell_max_points], mean = 0.0;
  for (int p = 0; p < np; ++p) {
    vdouble sp[6];
    _Pragma("GCC unroll 6") for (int k = 0; k < 6; ++k) sp[k] = simd::load(ps[p][k] + e);
    hex8::rotate_symmetric(Q, sp);
    _Pragma("GCC unroll 6") for (int k = 0; k < 6; ++k) simd::store(sp[k], ps[p][k] + e);
    szz[p] = Z[0] * sp[0] + Z[1] * sp[1] + Z[2] * sp[2] +
             2.0 * (Z[3] * sp[3] + Z[4] * sp[4] + Z[5] * sp[5]);
    mean += (0.5 * w_p[p]) * szz[p];
  }
  const double icorr = dt > 0 ? 1.0 / (M * dt) : 0.0;
  vdouble power = 0.0;
  for (int p = 0; p < np; ++p) {
    const vdouble c = (szz[p] - mean) * icorr;
    vdouble dp[6], sp[6];
    _Pragma("GCC unroll 6") for (int k = 0; k < 6; ++k) {
      dp[k] = d[k] + zeta_p[p] * A[k] - c * Z[k];
      simd::store(dp[k], pd + (6 * p + k) * S + l);
      sp[k] = simd::load(ps[p][k] + e);
    }
    power += (0.5 * w_p[p]) * (sp[0] * dp[0] + sp[1] * dp[1] + sp[2] * dp[2] +
                               2.0 * (sp[3] * dp[3] + sp[4] * dp[4] + sp[5] * dp[5]));
  }
  return power;
}

// Thick shell, stage C: from the points' new stresses (each loaded once), the element's
// stress, their Gauss average sum_p w_p / 2 sigma_p (for the membrane forces and the
// outputs); their new stress power sum_p w_p / 2 sigma_p : D_p; and their first moments
// m = sum_p w_p zeta_p sigma_p (for shell_bending_forces).
[[gnu::always_inline]] inline vdouble
shell_point_sums(double* const (&ps)[hex8::thick_shell_max_points][6], int e, int l, int np,
                 const double* zeta_p, const double* w_p, const double* pd, vdouble (&s)[6],
                 vdouble (&m)[6]) {
  constexpr int S = slot_stride;
  vdouble power = 0.0;
  auto point = [&](int p, auto&& sum) { // np >= 2
    vdouble sp[6], dp[6];
    _Pragma("GCC unroll 6") for (int k = 0; k < 6; ++k) {
      sp[k] = simd::load(ps[p][k] + e);
      dp[k] = simd::load(pd + (6 * p + k) * S + l);
      sum(k, sp[k]);
    }
    power += (0.5 * w_p[p]) * (sp[0] * dp[0] + sp[1] * dp[1] + sp[2] * dp[2] +
                               2.0 * (sp[3] * dp[3] + sp[4] * dp[4] + sp[5] * dp[5]));
  };
  point(0, [&](int k, const vdouble& sp) {
    s[k] = (0.5 * w_p[0]) * sp;
    m[k] = (w_p[0] * zeta_p[0]) * sp;
  });
  for (int p = 1; p < np; ++p)
    point(p, [&](int k, const vdouble& sp) {
      s[k] += (0.5 * w_p[p]) * sp;
      m[k] += (w_p[p] * zeta_p[p]) * sp;
    });
  return power;
}

// Thick shell, stage C: adds to the generalized hourglass forces r (co-rotational frame)
// those of the points' stresses, whose power is the bending part of their stress power:
// the first moments M = int sigma zeta dV = V / 2 sum_p w_p zeta_p sigma_p in the frame (m:
// the sum, shell_point_sums) give r[0][1] += (M_xx - nu_ps M_zz) / len0,
// r[1][0] += (M_yy - nu_ps M_zz) / len1 and the twist r[0][0] += M_xy / len1,
// r[1][1] += M_xy / len0.
[[gnu::always_inline]] inline void shell_bending_forces(const vdouble (&m)[6], const vdouble& vol,
                                                        const vdouble (&ax)[3][3],
                                                        const vdouble (&len)[3], double nu_ps,
                                                        vdouble (&r)[3][4]) {
  const vdouble S[3][3] = {{m[0], m[3], m[5]}, {m[3], m[1], m[4]}, {m[5], m[4], m[2]}};
  auto frame = [&](int dd, int ee) {
    vdouble sum = 0.0;
    _Pragma("GCC unroll 3") for (int i = 0; i < 3; ++i) sum +=
        ax[dd][i] * (S[i][0] * ax[ee][0] + S[i][1] * ax[ee][1] + S[i][2] * ax[ee][2]);
    return sum;
  };
  const vdouble half = 0.5 * vol;
  const vdouble mxx = half * frame(0, 0), myy = half * frame(1, 1), mxy = half * frame(0, 1),
                mzz = half * frame(2, 2);
  const vdouble il0 = 1.0 / len[0], il1 = 1.0 / len[1];
  r[0][1] += (mxx - nu_ps * mzz) * il0;
  r[1][0] += (myy - nu_ps * mzz) * il1;
  r[0][0] += mxy * il1;
  r[1][1] += mxy * il0;
}

} // namespace

int element_cost(const HourglassControl& hourglass, const ThickShell& thick_shell) {
  if (thick_shell.enabled()) return 148 + 22 * thick_shell.points;
  switch (hourglass.model) {
  case HourglassControl::Model::viscous:
    return 127;
  case HourglassControl::Model::stiffness:
    return 138;
  case HourglassControl::Model::assumed_strain:
    return 148;
  }
  return 148;
}

int HexBlock::init(std::span<const std::int64_t> ids, std::span<const std::array<int, 8>> corners,
                   const double* const x[3], std::size_t base) {
  const int n = static_cast<int>(ids.size());
  const auto p = static_cast<std::size_t>(padded_size(n));
  gid.assign(ids.begin(), ids.end());
  corner_base = base;
  node_begin = 0;
  node_end = 0;
  for (int a = 0; a < 8; ++a) {
    conn[a].resize(p);
    for (std::size_t e = 0; e < p; ++e)
      conn[a][e] = n > 0 ? corners[std::min<std::size_t>(e, n - 1)][a] : 0;
  }
  if (n > 0) {
    node_begin = conn[0][0];
    for (const auto& c : conn)
      for (int k : c) {
        node_begin = std::min(node_begin, k);
        node_end = std::max(node_end, k + 1);
      }
  }
  corner_rows.assign(p / width, 1);
  volume.assign(p, 0.0);
  alive.assign(p, 1.0);
  mass_scale.clear();
  wave_scale.clear();
  step_factor.clear();
  tetrahedron.clear();
  for (std::size_t e = 0; e < p; ++e) {
    const int n = corner_multiplicity(e, 0).first; // distinct nodes
    if (n == 8) continue;
    int k_max = 1;
    for (int c = 0; c < 8; ++c) k_max = std::max(k_max, corner_multiplicity(e, c).second);
    if (step_factor.empty()) step_factor.assign(p, 1.0);
    step_factor[e] = 8.0 / (n * k_max);
    if (n == 4) {
      if (tetrahedron.empty()) tetrahedron.assign(p, 0.0);
      tetrahedron[e] = 1.0;
    }
  }
  hex_volumes(*this, x, volume);
  const double rho = material->elastic().density;
  mass.assign(p, 0.0);
  int bad = -1;
  for (std::size_t e = 0; e < p; ++e) {
    if (static_cast<int>(e) < n && bad < 0) {
      double xe[8][3];
      element_corners(*this, x, e, xe);
      if (!(volume[e] > 0 && hex8::centre_jacobian(xe) > 0)) bad = static_cast<int>(e);
    }
    mass[e] = rho * volume[e];
  }
  for (auto& s : stress) s.assign(p, 0.0);
  plastic_strain.clear();
  temperature.clear();
  if (material->has_plastic_strain()) plastic_strain.assign(p, 0.0);
  if (material->has_temperature()) temperature.assign(p, material->initial_temperature());
  for (auto& h : hourglass_force) h.clear();
  if (hourglass.model != HourglassControl::Model::viscous)
    for (auto& h : hourglass_force) h.assign(p, 0.0);
  const auto np = static_cast<std::size_t>(thick_shell.points);
  point_stress.assign(np, {});
  for (auto& ps : point_stress)
    for (auto& s : ps) s.assign(p, 0.0);
  point_plastic_strain.assign(material->has_plastic_strain() ? np : 0, std::vector<double>(p, 0.0));
  point_temperature.assign(material->has_temperature() ? np : 0,
                           std::vector<double>(p, material->initial_temperature()));
  internal_energy.assign(p, 0.0);
  hourglass_energy.assign(p, 0.0);
  return bad;
}

HexWorkspace::HexWorkspace()
    : buf_(static_cast<std::size_t>(s_count) * slot_stride +
               static_cast<std::size_t>(t_count) * width,
           0.0) {}

// The sums are zero between assemblies: end_nodal_forces clears what it reads (the lines
// are in cache then) instead of a separate pass here. Only an assembly left unfinished
// (an exception in between) leaves values behind, and the next begin clears them.
void HexWorkspace::begin_nodal_forces(int nodes) {
  const std::size_t size = 4 * static_cast<std::size_t>(nodes);
  if (assembled_nodes_ >= 0) std::fill(sums_.begin(), sums_.end(), 0.0);
  if (sums_.size() < size) sums_.resize(size, 0.0); // first calls only
  assembled_nodes_ = nodes;
}

void HexWorkspace::end_nodal_forces(double* const f[3]) {
  const int nn = std::max(assembled_nodes_, 0);
  double* q = sums_.data();
  int k = 0;
#if defined(__AVX__)
  // four nodes at a time: four loads, the transpose, three stores
  for (; k + 4 <= nn; k += 4) {
    double* r = q + 4 * static_cast<std::size_t>(k);
    const __m256d rows[4] = {_mm256_load_pd(r), _mm256_load_pd(r + 4), _mm256_load_pd(r + 8),
                             _mm256_load_pd(r + 12)};
    __m256d c[4];
    simd::transpose4x4(rows, c);
    for (int i = 0; i < 3; ++i) _mm256_storeu_pd(f[i] + k, c[i]);
    for (int j = 0; j < 4; ++j) _mm256_store_pd(r + 4 * j, _mm256_setzero_pd());
  }
#endif
  for (; k < nn; ++k) {
    double* r = q + 4 * static_cast<std::size_t>(k);
    for (int i = 0; i < 3; ++i) f[i][k] = r[i];
    for (int j = 0; j < 4; ++j) r[j] = 0.0;
  }
  assembled_nodes_ = -1;
}

namespace detail {

// hex_forces for one block, compiled three times: Form 0 for the viscous and stiffness
// hourglass forms, 1 for the assumed-strain form, 2 for the thick shell (assumed strain
// with the bending integrated through the thickness), so that each form runs the
// instructions it ran before the next existed (they are not branches in its code).
template <int Form>
void block_forces(HexBlock& b, const NodalView& nodes, double dt, CornerView corners,
                  HexWorkspace& work, HexResult& result) {
  constexpr bool Asq = Form != 0;
  constexpr bool Shell = Form == 2;
  const int n = b.size();
  constexpr int C = HexWorkspace::chunk;
  auto scratch = [&](int slot) {
    return work.buf_.data() + static_cast<std::size_t>(slot) * slot_stride;
  };
  const double M = b.material->elastic().plane_wave_modulus();
  const bool stiff = !Asq && b.hourglass.model == HourglassControl::Model::stiffness;
  const double hg = b.hourglass.coefficient;
  [[maybe_unused]] const double hg_E = hg * b.material->elastic().youngs_modulus;
  [[maybe_unused]] const double hg_mu = hg * b.material->elastic().shear;
  // Assumed strain with a material that yields: the plastic limit of the hourglass forces.
  [[maybe_unused]] const bool limit = Asq && b.material->has_plastic_strain();
  const double c1 = b.bulk_viscosity.linear, c2 = b.bulk_viscosity.quadratic;
  // Thick shell: points, their places and weights, and the plane-stress ratio
  // lambda / (lambda + 2 mu) that gives the bending its through-thickness strain.
  [[maybe_unused]] const int np = b.thick_shell.points;
  [[maybe_unused]] const double* zeta_p =
      Shell ? hex8::thick_shell_point[np - 2] : hex8::thick_shell_point[0];
  [[maybe_unused]] const double* w_p =
      Shell ? hex8::thick_shell_weight[np - 2] : hex8::thick_shell_weight[0];
  [[maybe_unused]] const double nu_ps = (M - 2.0 * b.material->elastic().shear) / M;
  // The points' stress arrays (ps[p][k]: component k at point p).
  [[maybe_unused]] double* ps[hex8::thick_shell_max_points][6] = {};
  for (int p = 0; p < np; ++p)
    for (int k = 0; k < 6; ++k) ps[p][k] = b.point_stress[p][k].data();
  const bool has_ep = !b.plastic_strain.empty(), has_T = !b.temperature.empty();
  const bool erode_ep = b.erosion.plastic_strain > 0 && has_ep;
  const bool scaled = !b.wave_scale.empty(); // mass scaling
  const bool degenerate = !b.step_factor.empty(), tetrahedra = !b.tetrahedron.empty();
  // Nodal assembly (HexWorkspace::begin_nodal_forces), or null.
  double* const sums = work.assembled_nodes_ >= 0 ? work.sums_.data() : nullptr;
  const std::uint8_t* rows = b.corner_rows.data();
  // Non-temporal corner stores need rows aligned to a vector (32 or 64 bytes; every row is if the
  // arrays are), and pay only where the rows are read after the kernel: the nodal assembly reads
  // the rows it asks for back at once, and a streamed row read back comes from memory (the 2-rank
  // can crush spent 10% longer in the kernel).
  bool stream = sums == nullptr;
  for (double* f : corners.f)
    stream = stream &&
             reinterpret_cast<std::uintptr_t>(f + b.corner_base) % (sizeof(double) * width) == 0;
  // Positions and velocities of the block's nodes, packed per node.
  const std::size_t packed_size = node_stride * static_cast<std::size_t>(b.node_end);
  if (work.nodes_.size() < packed_size) work.nodes_.resize(packed_size); // first calls only
  pack_nodes<Form>(nodes, b.node_begin, b.node_end, work.nodes_.data());
  const double* packed = work.nodes_.data();
  const int* conn[8];
  for (int a = 0; a < 8; ++a) conn[a] = b.conn[a].data();
  double* t = work.buf_.data() + static_cast<std::size_t>(s_count) * slot_stride; // stage scratch
  constexpr int W = width;
  auto tmp = [t](int k) { return simd::load(t + k * W); };
  // The smallest stable step: the element's if it is smaller, or equal with a smaller id.
  auto take_step = [&](double dte, std::int64_t id) {
    if (dte < result.dt_stable || (dte == result.dt_stable && id < result.stable_gid)) {
      result.dt_stable = dte;
      result.stable_gid = id;
    }
  };
  const vdouble lane([](auto l) { return static_cast<double>(l); });
  vdouble best_dt = 1e300, best_e = -1.0; // per lane: smallest step so far and its element
  const double* xs = scratch(s_x0);
  const double* vs = scratch(s_v0);
  auto xc = [&](int a, int i, int l) { return simd::load(xs + (3 * a + i) * slot_stride + l); };
  auto vc = [&](int a, int i, int l) { return simd::load(vs + (3 * a + i) * slot_stride + l); };

  for (int e0 = 0; e0 < n; e0 += C) {
    const int nc = padded_size(std::min(C, n - e0)); // lanes in this chunk, whole vectors

    // Stage A: kinematics at the mid-step configuration x(n-1/2) = x(n) - dt/2 v(n-1/2);
    // rotate the old stress into the new frame.
    for (int l = 0; l < nc; l += width) {
      const int e = e0 + l;
      gather<Form>(conn, packed, e, std::min(e + prefetch_ahead, padded_size(n) - width), 0.5 * dt,
                   scratch(s_x0) + l, scratch(s_v0) + l, t);
      simd::stage_barrier();
      // 12 B(x(n-1/2)) one direction at a time, consumed at once: 12 V and 12 V L^T.
      vdouble L[3][3], vol12;
      gradient_by_direction(t, [&](int a, int i, const vdouble& B) {
        _Pragma("GCC unroll 12") for (int r = 0; r < 3; ++r) L[r][i] =
            a == 0 ? vc(a, r, l) * B : L[r][i] + vc(a, r, l) * B;
        if (i == 0) vol12 = a == 0 ? tmp(t_xm0 + a) * B : vol12 + tmp(t_xm0 + a) * B;
      });
      const vdouble vol = vol12 * (1.0 / 12.0);
      const vdouble inv = 1.0 / vol;
      const vdouble inv12 = inv * (1.0 / 12.0);
      for (auto& row : L)
        for (auto& x : row) x *= inv12;
      // Rate of deformation d (xx, yy, zz, xy, yz, xz) and the spin's axial vector w.
      vdouble d[6], w[3];
      hex8::rate_and_spin(L, d, w);
      vdouble Q[3][3], s[6];
      hex8::hughes_winget(w, dt, Q);
      vdouble power;
      if constexpr (Shell) { // the element's stress is the points' average (stage B)
        power = shell_point_rates(ps, e, l, dt, L, d, Q, np, zeta_p, w_p, nu_ps, M, t + t_xm0 * W,
                                  vs, scratch(s_pd0));
      } else {
        _Pragma("GCC unroll 12") for (int k = 0; k < 6; ++k) s[k] = simd::load(&b.stress[k][e]);
        hex8::rotate_symmetric(Q, s);
        power = s[0] * d[0] + s[1] * d[1] + s[2] * d[2] +
                2.0 * (s[3] * d[3] + s[4] * d[4] + s[5] * d[5]);
        _Pragma("GCC unroll 12") for (int k = 0; k < 6; ++k) simd::store(s[k], &b.stress[k][e]);
      }
      vdouble density = simd::load(&b.mass[e]) * inv;
      if (b.eroded > 0) {
        // Eroded elements deform no more: with no rate of deformation their material
        // state (plastic strain, temperature) stays as it was when they eroded, whatever
        // their nodes do (QA round 12: it grew to 4e15 and went non-finite, and every
        // later checkpoint was refused). Any finite density serves them.
        const auto gone = simd::load(&b.alive[e]) == 0.0;
        if (stdx::any_of(gone)) {
          _Pragma("GCC unroll 6") for (int k = 0; k < 6; ++k) stdx::where(gone, d[k]) = 0.0;
          stdx::where(gone, density) = 1.0;
          if constexpr (Shell)
            for (int k = 0; k < 6 * np; ++k) {
              vdouble dk = simd::load(scratch(s_pd0 + k) + l);
              stdx::where(gone, dk) = 0.0;
              simd::store(dk, scratch(s_pd0 + k) + l);
            }
        }
      }
      _Pragma("GCC unroll 12") for (int k = 0; k < 6; ++k) simd::store(d[k], scratch(s_d0 + k) + l);
      simd::store(density, scratch(s_density) + l);
      simd::store(power, scratch(s_power_old) + l);
      simd::store(vol, scratch(s_volume_mid) + l);
      if (stiff) // the stiffness form rotates its hourglass forces with Q
        _Pragma("GCC unroll 12") for (int i = 0; i < 3; ++i)
            _Pragma("GCC unroll 12") for (int j = 0; j < 3; ++j)
                simd::store(Q[i][j], scratch(s_q0 + 3 * i + j) + l);
      simd::stage_barrier();
    }

    // Stage B: constitutive update of the whole chunk through the batch interface.
    MaterialBatch batch;
    batch.n = nc;
    batch.dt = dt;
    _Pragma("GCC unroll 12") for (int k = 0; k < 6; ++k) {
      batch.d[k] = scratch(s_d0 + k);
      batch.stress[k] = b.stress[k].data() + e0;
    }
    batch.density = scratch(s_density);
    batch.plastic_strain = has_ep ? b.plastic_strain.data() + e0 : nullptr;
    batch.temperature = has_T ? b.temperature.data() + e0 : nullptr;
    batch.wave_speed = scratch(s_wave_speed);
    if constexpr (Shell) {
      // Each point through the thickness, then the element's averages of the state (for
      // the flow stress and erosion).
      for (int p = 0; p < np; ++p) {
        MaterialBatch pb = batch;
        _Pragma("GCC unroll 6") for (int k = 0; k < 6; ++k) {
          pb.d[k] = scratch(s_pd0 + 6 * p + k);
          pb.stress[k] = ps[p][k] + e0;
        }
        pb.plastic_strain = has_ep ? b.point_plastic_strain[p].data() + e0 : nullptr;
        pb.temperature = has_T ? b.point_temperature[p].data() + e0 : nullptr;
        pb.wave_speed = p == 0 ? scratch(s_wave_speed) : scratch(s_q1);
        b.material->update(pb);
        if (p > 0)
          for (int l = 0; l < nc; l += width)
            simd::store(
                stdx::max(simd::load(scratch(s_wave_speed) + l), simd::load(scratch(s_q1) + l)),
                scratch(s_wave_speed) + l);
      }
      auto average = [&](auto&& point, double* out) {
        for (int l = 0; l < nc; l += width) {
          vdouble sum = (0.5 * w_p[0]) * simd::load(point(0) + e0 + l);
          for (int p = 1; p < np; ++p) sum += (0.5 * w_p[p]) * simd::load(point(p) + e0 + l);
          simd::store(sum, out + e0 + l);
        }
      };
      // (The stress average is formed in stage C, with the points' other sums.)
      if (has_ep)
        average([&](int p) { return b.point_plastic_strain[p].data(); }, b.plastic_strain.data());
      if (has_T)
        average([&](int p) { return b.point_temperature[p].data(); }, b.temperature.data());
    } else {
      b.material->update(batch);
    }
    if (limit) b.material->flow_stress(batch, scratch(s_flow));

    // Stage C: forces at x(n): stress divergence, bulk viscosity, hourglass; energies and
    // the stable time step.
    for (int l = 0; l < nc; l += width) {
      const int e = e0 + l;
      // C1: 12 B(x(n)) into the stage scratch, with G_ij = sum_b v_ib B_jb on the way.
      edge_sums(xs + l, t);
      simd::stage_barrier();
      vdouble G[3][3];
      gradient_by_direction(t, [&](int a, int i, const vdouble& B) {
        simd::store(B, t + (t_b0 + 3 * a + i) * W);
        _Pragma("GCC unroll 12") for (int r = 0; r < 3; ++r) G[r][i] =
            a == 0 ? vc(a, r, l) * B : G[r][i] + vc(a, r, l) * B;
      });
      simd::stage_barrier();
      auto Bt = [&](int a, int i) { return tmp(t_b0 + 3 * a + i); }; // 12 B_ia
      vdouble vol12 = xc(0, 0, l) * Bt(0, 0), bbd[3]; // 144 B:B by direction (short sums)
      _Pragma("GCC unroll 12") for (int a = 1; a < 8; ++a) vol12 += xc(a, 0, l) * Bt(a, 0);
      _Pragma("GCC unroll 3") for (int i = 0; i < 3; ++i) {
        bbd[i] = Bt(0, i) * Bt(0, i);
        _Pragma("GCC unroll 12") for (int a = 1; a < 8; ++a) bbd[i] += Bt(a, i) * Bt(a, i);
      }
      const vdouble bb144 = (bbd[0] + bbd[1]) + bbd[2];
      for (auto& row : G)
        for (auto& x : row) x *= 1.0 / 12.0;
      const vdouble vol = vol12 * (1.0 / 12.0);
      const vdouble inv = 1.0 / vol;
      const vdouble mass =
          scaled ? simd::load(&b.mass[e]) * simd::load(&b.mass_scale[e]) : simd::load(&b.mass[e]);
      const vdouble rho = mass * inv;
      const vdouble c = scaled
                            ? simd::load(scratch(s_wave_speed) + l) * simd::load(&b.wave_scale[e])
                            : simd::load(scratch(s_wave_speed) + l);
      vdouble d[6], s[6];
      _Pragma("GCC unroll 12") for (int k = 0; k < 6; ++k) d[k] = simd::load(scratch(s_d0 + k) + l);
      // Thick shell: the element's stress is the points' average, formed here with their
      // stress power and moments.
      [[maybe_unused]] vdouble shell_power_new, shell_m[6];
      if constexpr (Shell) {
        shell_power_new = shell_point_sums(ps, e, l, np, zeta_p, w_p, scratch(s_pd0), s, shell_m);
        _Pragma("GCC unroll 12") for (int k = 0; k < 6; ++k) simd::store(s[k], &b.stress[k][e]);
      } else {
        _Pragma("GCC unroll 12") for (int k = 0; k < 6; ++k) s[k] = simd::load(&b.stress[k][e]);
      }
      const vdouble trd = d[0] + d[1] + d[2];
      // Characteristic length: the element's stable-step length V / sqrt(2 B:B) scaled
      // by sqrt(3), which is the edge of a cube (and needs no cube root).
      const vdouble bb = bb144 * (1.0 / 144.0);
      const vdouble inv_sqrt_bb = 1.0 / stdx::sqrt(2.0 * bb);
      const vdouble lc = vol * inv_sqrt_bb;
      const vdouble len = 1.7320508075688772 * lc;
      // Compressing: faster than round-off. A rigid motion's tr D is a few ulps of either
      // sign, and the linear term's step factor (c1 c, whatever tr D's size) would switch
      // on with the sign: the first step of a deck in SI and of the same deck in mm-ms
      // differed by 6% (QA round 5). Below a strain of 1e-12 per wave transit of the
      // element, q is at most 1e-12 of the bulk modulus and is left out.
      const auto compressing = trd * len < -1e-12 * c;
      vdouble q = 0.0, qv = 0.0; // bulk viscosity pressure and its rate term for dt
      stdx::where(compressing, q) = rho * len * (c2 * len * trd * trd - c1 * c * trd);
      stdx::where(compressing, qv) = c1 * c - c2 * len * trd;

      // Hourglass (Flanagan-Belytschko, with gamma = Gamma - h B never formed):
      //   h_aj = (1/V) sum_b Gamma_ab x_jb, G_ij = sum_b v_ib B_jb,
      //   q_ia = sum_b v_ib Gamma_ab - G_ij h_aj (the hourglass velocities),
      //   f_ia = -(sigma_ij - q delta_ij - P_ij) B_ja - sum_al Q_i,al Gamma_al,a,
      //   P_ij = sum_al Q_i,al h_al,j.
      vdouble h[4][3], vg[3][4], J[3][3];
      _Pragma("GCC unroll 12") for (int i = 0; i < 3; ++i) {
        vdouble col[8], out[4];
        _Pragma("GCC unroll 12") for (int a = 0; a < 8; ++a) col[a] = xc(a, i, l);
        hex8::gamma_sums(col, out);
        hex8::natural_sums(col, J[i]); // (all forms: the centre Jacobian's sign, below)
        _Pragma("GCC unroll 12") for (int al = 0; al < 4; ++al) h[al][i] = out[al] * inv;
        _Pragma("GCC unroll 12") for (int a = 0; a < 8; ++a) col[a] = vc(a, i, l);
        hex8::gamma_sums(col, vg[i]);
      }
      vdouble Qh[3][4];
      vdouble hgp[3] = {0.0, 0.0, 0.0}; // hourglass power by direction (three short sums)
      const vdouble kv = (0.25 * hg) * rho * c * len * len;
      const vdouble ks = (hg * M / 3.0) * bb * inv;
      // Assumed strain: the co-rotational axes and extents, and q in those axes.
      vdouble ax[3][3], extent[3], ql[3][4];
      if constexpr (Asq) hex8::corotational_frame(J, ax, extent);
      _Pragma("GCC unroll 12") for (int al = 0; al < 4; ++al) {
        vdouble qa[3];
        _Pragma("GCC unroll 12") for (int i = 0; i < 3; ++i) qa[i] =
            vg[i][al] - (G[i][0] * h[al][0] + G[i][1] * h[al][1] + G[i][2] * h[al][2]);
        if (stiff) {
          vdouble old[3];
          _Pragma("GCC unroll 12") for (int i = 0; i < 3; ++i) old[i] =
              simd::load(&b.hourglass_force[3 * al + i][e]);
          _Pragma("GCC unroll 12") for (int i = 0; i < 3; ++i) {
            const vdouble rot = simd::load(scratch(s_q0 + 3 * i) + l) * old[0] +
                                simd::load(scratch(s_q0 + 3 * i + 1) + l) * old[1] +
                                simd::load(scratch(s_q0 + 3 * i + 2) + l) * old[2];
            Qh[i][al] = rot + dt * ks * qa[i];
            simd::store(Qh[i][al], &b.hourglass_force[3 * al + i][e]);
            hgp[i] += 0.5 * (rot + Qh[i][al]) * qa[i];
          }
        } else if constexpr (Asq) {
          _Pragma("GCC unroll 12") for (int d = 0; d < 3; ++d) ql[d][al] =
              ax[d][0] * qa[0] + ax[d][1] * qa[1] + ax[d][2] * qa[2];
        } else {
          _Pragma("GCC unroll 12") for (int i = 0; i < 3; ++i) {
            Qh[i][al] = kv * qa[i];
            hgp[i] += Qh[i][al] * qa[i];
          }
        }
      }
      if constexpr (Asq) {
        // Assumed strain: the generalized forces advance in the co-rotational frame and are
        // stored in it (so they turn with the element and need no rotation of their own),
        // then go back to global components for the forces.
        // With a flow stress, the forces are then limited to a fully plastic section's
        // (hex8::assumed_strain_limit); the work of the forces includes what that dissipates.
        vdouble r[3][4], old[3][4];
        if constexpr (Shell)
          hex8::assumed_strain_rate<false>(hg_E, hg_mu, extent, ql, r);
        else
          hex8::assumed_strain_rate(hg_E, hg_mu, extent, ql, r);
        _Pragma("GCC unroll 12") for (int al = 0; al < 4; ++al)
            _Pragma("GCC unroll 12") for (int d = 0; d < 3; ++d) {
          old[d][al] = simd::load(&b.hourglass_force[3 * al + d][e]);
          r[d][al] = old[d][al] + dt * r[d][al];
        }
        if (limit) {
          if constexpr (Shell)
            hex8::thick_shell_limit(simd::load(scratch(s_flow) + l), extent, r);
          else
            hex8::assumed_strain_limit(simd::load(scratch(s_flow) + l), extent, r);
        }
        _Pragma("GCC unroll 12") for (int al = 0; al < 4; ++al)
            _Pragma("GCC unroll 12") for (int d = 0; d < 3; ++d) {
          simd::store(r[d][al], &b.hourglass_force[3 * al + d][e]);
          hgp[d] += 0.5 * (old[d][al] + r[d][al]) * ql[d][al];
        }
        // Thick shell: the bending forces of the points' stresses (their work is in the
        // internal energy).
        if constexpr (Shell) shell_bending_forces(shell_m, vol, ax, extent, nu_ps, r);
        _Pragma("GCC unroll 12") for (int al = 0; al < 4; ++al)
            _Pragma("GCC unroll 12") for (int i = 0; i < 3; ++i) Qh[i][al] =
                ax[0][i] * r[0][al] + ax[1][i] * r[1][al] + ax[2][i] * r[2][al];
      }
      // -S/12 with S = sigma - q I - P (not symmetric once P is in): the corner forces
      // below are -S B - (hourglass) and the gradient in the scratch is 12 B.
      vdouble S[3][3] = {{s[0] - q, s[3], s[5]}, {s[3], s[1] - q, s[4]}, {s[5], s[4], s[2] - q}};
      _Pragma("GCC unroll 12") for (int i = 0; i < 3; ++i)
          _Pragma("GCC unroll 12") for (int j = 0; j < 3; ++j) S[i][j] =
              (S[i][j] - (Qh[i][0] * h[0][j] + Qh[i][1] * h[1][j] + Qh[i][2] * h[2][j] +
                          Qh[i][3] * h[3][j])) *
              (-1.0 / 12.0);

      // Energies over the step just taken (dt = 0 on the first cycle).
      vdouble power_new =
          s[0] * d[0] + s[1] * d[1] + s[2] * d[2] + 2.0 * (s[3] * d[3] + s[4] * d[4] + s[5] * d[5]);
      if constexpr (Shell) power_new = shell_power_new;
      const vdouble vmid = simd::load(scratch(s_volume_mid) + l);
      vdouble dE = dt * vmid * (0.5 * (simd::load(scratch(s_power_old) + l) + power_new) - q * trd);
      vdouble hg_power = (hgp[0] + hgp[1]) + hgp[2];
      const auto dead = simd::load(&b.alive[e]) == 0.0; // eroded elements store no energy
      const bool any_dead = stdx::any_of(dead);
      stdx::where(dead, dE) = 0.0;
      stdx::where(dead, hg_power) = 0.0;
      // (The old values stay at hand for an element that erodes below: the increments of
      // its last step, from an inverted or failing shape, are not counted.)
      const vdouble ie_old = simd::load(&b.internal_energy[e]);
      const vdouble he_old = simd::load(&b.hourglass_energy[e]);
      simd::store(ie_old + dE, &b.internal_energy[e]);
      simd::store(he_old + dt * hg_power, &b.hourglass_energy[e]);
      simd::store(vol, &b.volume[e]);

      // Stable time step: Flanagan-Belytschko bound on the maximum eigenvalue,
      // omega^2 <= 8 c^2 B:B / V^2, i.e. dt = V / (c sqrt(2 B:B)), reduced for the bulk
      // viscosity.
      // The viscous hourglass force damps the nodes at a rate of at most
      // r = kv lambda / (m / 8): lambda bounds the largest eigenvalue of the damping
      // matrix sum_al gamma_al gamma_al^T, m / 8 is this element's share of any of its
      // nodes' mass. Central differences with a lagged damping rate r and a frequency
      // omega are stable while dt^2 omega^2 + 2 dt r < 4, which is the bulk viscosity's
      // form with r lc / 4 added to its rate term. lambda is the smaller of two bounds:
      // a cheap one (hex8::hourglass_damping_bound_frobenius, exact on parallelepipeds)
      // and Gershgorin's (hex8::hourglass_damping_bound), which is formed only where the
      // step from the cheap bound is not above its lane's smallest so far: elsewhere the
      // element's step, at least that, cannot be the smallest. The step is therefore
      // min(cheap, Gershgorin)'s wherever it matters, on any decomposition.
      vdouble dte;
      // (Wedges, pyramids, tetrahedra: their nodes' masses, HexBlock::step_factor.)
      const vdouble sf = degenerate ? simd::load(&b.step_factor[e]) : vdouble(1.0);
      if (!Asq) {
        // Both forms bound lambda, the largest eigenvalue of sum_al gamma_al gamma_al^T.
        // Viscous: the damping rate r = kv lambda / (m / 8) joins the rate term (below).
        // Stiffness: K_h = ks sum_al gamma_al gamma_al^T ("1 ks" in each direction) has
        // omega_h^2 <= ks lambda / (m / 8), next to the plain omega_p^2 = 4 c^2 / lc^2.
        // Their sum's largest eigenvalue is at most that of [[p, k sqrt(ph)], [k sqrt(ph),
        // h]], with k the cosine of the smallest angle between the two operators' ranges
        // (span B and span gamma, in each direction): max(p, h) where they are orthogonal
        // (any parallelepiped), p + h where they meet. The gammas span the complement of
        // {1, x_0, x_1, x_2}, and with S = xc^T xc (centred positions) and G = B^T B,
        // cos^2 of any B c to span {1, x} is V^2 c^T S^-1 c / c^T G c, whose least value
        // is V^2 / lambda_max(S G); lambda_max(S G) <= V^2 + e, e the largest absolute
        // row sum of S G - V^2 I (Gershgorin), so k^2 <= e / (V^2 + e). In the step's
        // terms, the sound speed becomes
        // c_e^2 = (c^2 + w) / 2 + sqrt((c^2 - w)^2 / 4 + k^2 c^2 w), w = 2 ks lambda lc^2 / m.
        // (The plain step alone was up to 1.63 times the stable one at coefficient 1,
        // 1.13 at 0.3; QA round 19, test_element_step.cpp.)
        const vdouble kr = (0.25 * 8.0) * kv * lc / mass;
        vdouble kc = 0.0, k2 = 0.0;
        if (stiff) {
          kc = (2.0 * lc * lc / mass) * ks;
          // S from the natural and gamma sums the kernel has formed (the positions'
          // coordinates in the orthogonal basis 1, xi, eta, zeta, Gamma_al, each of
          // squared norm 8: S = (J J^T + V^2 h^T h) / 8), G from B.
          vdouble S[3][3], G[3][3];
          const vdouble v2 = vol * vol;
          _Pragma("GCC unroll 3") for (int i = 0; i < 3; ++i)
              _Pragma("GCC unroll 3") for (int j = i; j < 3; ++j) {
            const vdouble jj = J[i][0] * J[j][0] + J[i][1] * J[j][1] + J[i][2] * J[j][2];
            const vdouble hh_ij =
                h[0][i] * h[0][j] + h[1][i] * h[1][j] + h[2][i] * h[2][j] + h[3][i] * h[3][j];
            S[i][j] = 0.125 * (jj + v2 * hh_ij);
            if (i == j) {
              G[i][i] = bbd[i] * (1.0 / 144.0);
            } else {
              G[i][j] = Bt(0, i) * Bt(0, j);
              _Pragma("GCC unroll 8") for (int a = 1; a < 8; ++a) G[i][j] += Bt(a, i) * Bt(a, j);
              G[i][j] *= 1.0 / 144.0;
            }
            S[j][i] = S[i][j];
            G[j][i] = G[i][j];
          }
          vdouble e = 0.0; // Gershgorin: |mu| <= the largest absolute row sum of S G - V^2 I
          _Pragma("GCC unroll 3") for (int i = 0; i < 3; ++i) {
            vdouble row = 0.0;
            _Pragma("GCC unroll 3") for (int j = 0; j < 3; ++j) {
              vdouble sg = S[i][0] * G[0][j] + S[i][1] * G[1][j] + S[i][2] * G[2][j];
              if (i == j) sg -= v2;
              row += stdx::abs(sg);
            }
            e = stdx::max(e, row);
          }
          k2 = e / (v2 + e);
        }
        auto step = [&](const vdouble& lambda) {
          if (stiff) {
            const vdouble w = kc * lambda, cc = c * c, half = 0.5 * (cc - w);
            const vdouble ce2 = 0.5 * (cc + w) + stdx::sqrt(half * half + k2 * cc * w);
            return lc / (qv + stdx::sqrt(qv * qv + ce2));
          }
          const vdouble qh = qv + kr * lambda;
          return lc / (qh + stdx::sqrt(qh * qh + c * c));
        };
        vdouble hhd[3]; // sum of h_al,i^2, by direction
        _Pragma("GCC unroll 3") for (int i = 0; i < 3; ++i) hhd[i] =
            ((h[0][i] * h[0][i] + h[1][i] * h[1][i]) + h[2][i] * h[2][i]) + h[3][i] * h[3][i];
        const vdouble hh = (hhd[0] + hhd[1]) + hhd[2];
        const vdouble cheap = hex8::hourglass_damping_bound_frobenius(bb, hh);
        dte = sf * step(cheap);
        // (Every element's own step, where the caller asks for each: formed everywhere.)
        if (result.element_dt || stdx::any_of(dte <= best_dt)) {
          vdouble Bc[3][8];
          _Pragma("GCC unroll 12") for (int a = 0; a < 8; ++a)
              _Pragma("GCC unroll 12") for (int i = 0; i < 3; ++i) Bc[i][a] =
                  Bt(a, i) * (1.0 / 12.0);
          dte = sf * step(stdx::min(cheap, hex8::hourglass_damping_bound(Bc, h)));
        }
      } else {
        // The assumed-strain forms take the plain step: their hourglass stiffness, the
        // physical one of the bending modes, raises the element's largest frequency by
        // under 2% even on warped elements, within the plain step's margin
        // (test_element_step.cpp, docs/element.md).
        dte = sf * (lc / (qv + stdx::sqrt(qv * qv + c * c)));
      }
      // A tetrahedron (a b c c d d d d) has no hourglass modes: its four nodes carry linear
      // fields only. Its step is the plain one of its nodes, each with the gradient B_n
      // of the corners that share it and the mass m / 4: omega^2 <= 4 c^2 sum_n |B_n|^2 /
      // V^2, so dt = V / (c sqrt(sum_n |B_n|^2)) (dt omega_max 1.58-2.00 over random
      // tetrahedra; test_element_step.cpp), with the bulk viscosity as above.
      if (tetrahedra) {
        const auto tet = simd::load(&b.tetrahedron[e]) > 0.0;
        if (stdx::any_of(tet)) {
          vdouble sum = 0.0; // 144 sum_n |B_n|^2
          _Pragma("GCC unroll 3") for (int i = 0; i < 3; ++i) {
            const vdouble b23 = Bt(2, i) + Bt(3, i);
            const vdouble b47 = (Bt(4, i) + Bt(5, i)) + (Bt(6, i) + Bt(7, i));
            sum += ((Bt(0, i) * Bt(0, i) + Bt(1, i) * Bt(1, i)) + b23 * b23) + b47 * b47;
          }
          const vdouble lt = vol / stdx::sqrt(sum * (1.0 / 144.0));
          stdx::where(tet, dte) = lt / (qv + stdx::sqrt(qv * qv + c * c));
        }
      }

      // Eroded elements: no force, no energy, no time step (select, not multiply: their
      // arithmetic may have produced non-finite values).
      if (any_dead) {
        stdx::where(dead, dte) = 1e300;
        for (auto& hk : b.hourglass_force) { // (stiffness forms only)
          if (hk.empty()) break;
          vdouble q = simd::load(&hk[e]);
          stdx::where(dead, q) = 0.0;
          simd::store(q, &hk[e]);
        }
        _Pragma("GCC unroll 12") for (int k = 0; k < 6; ++k) {
          vdouble sk = simd::load(&b.stress[k][e]);
          stdx::where(dead, sk) = 0.0;
          simd::store(sk, &b.stress[k][e]);
          for (auto& pt : b.point_stress) {
            vdouble pk = simd::load(&pt[k][e]);
            stdx::where(dead, pk) = 0.0;
            simd::store(pk, &pt[k][e]);
          }
        }
      }

      // Corner forces f_a = -(S B_a + sum_al Q_al Gamma_al,a), formed and stored one
      // component at a time (the hourglass part of all eight corners comes from four
      // values), with their sum kept for the finiteness check (a sum of sums, not one
      // chain of 24 additions).
      // With nodal assembly, the rows go to the corner slots only where the block asks for
      // them (corner_rows) and otherwise to the stage scratch, for the assembly after the
      // bookkeeping (which may erode an element).
      if (result.element_dt) simd::store(dte, result.element_dt + e);
      vdouble check = dte;
      const bool slots = !sums || rows[e / W] != 0;
      _Pragma("GCC unroll 12") for (int i = 0; i < 3; ++i) {
        vdouble hgf[8], fa[8];
        hex8::gamma_spread(Qh[i], hgf);
        _Pragma("GCC unroll 12") for (int a = 0; a < 8; ++a) {
          fa[a] = S[i][0] * Bt(a, 0) + S[i][1] * Bt(a, 1) + S[i][2] * Bt(a, 2) - hgf[a];
          if (any_dead) stdx::where(dead, fa[a]) = 0.0;
        }
        check += ((fa[0] + fa[1]) + (fa[2] + fa[3])) + ((fa[4] + fa[5]) + (fa[6] + fa[7]));
        // Element-major slots: the lanes' eight corners are contiguous, whole rows that
        // the gather reads only after the kernel, streamed past the cache when aligned.
        double* row = corners.f[i] + b.corner_base + 8 * static_cast<std::size_t>(e);
        if (!slots)
          simd::store_transposed(fa, t + (t_rows0 + 8 * i) * W);
        else if (stream)
          simd::store_transposed<true>(fa, row);
        else
          simd::store_transposed(fa, row);
      }

      // Bookkeeping. The common case (every live element healthy, none to erode) stays in
      // the vector: the stable step is kept per lane as a running minimum with the index
      // of its element (ascending within a lane, so the first of equal steps stays), and
      // the lanes are merged after the last chunk. A vector with anything to report takes
      // the scalar path.
      const auto real = lane < static_cast<double>(n - e); // not padding
      const auto live = (!dead) && real;
      // Inverted: a non-positive volume, or a non-positive Jacobian at the centre. The
      // volume is the exact integral of det J, which a tangled element keeps positive
      // where its folded parts' volumes cancel, as a plastic (volume-keeping) element
      // does (QA round 21: six of eight elements turned inside out at their centres ran
      // on to exit 0 with nodes at 22 times the driven speed). J holds the natural sums,
      // 8 times the centre Jacobian's columns.
      const auto inverted = !(vol > 0.0) || !(hex8::determinant(J) > 0.0);
      auto report = inverted || !(stdx::abs(check) <= std::numeric_limits<double>::max());
      if (erode_ep) report = report || simd::load(&b.plastic_strain[e]) >= b.erosion.plastic_strain;
      const int lanes = std::min(width, n - e);
      double* rows_of[3]; // where the rows went (corner slots or stage scratch)
      _Pragma("GCC unroll 3") for (int i = 0; i < 3; ++i) rows_of[i] =
          slots ? corners.f[i] + b.corner_base + 8 * static_cast<std::size_t>(e)
                : t + (t_rows0 + 8 * i) * W;
      // Nodal assembly: each real lane's (element's) eight corners in turn, lane after
      // lane, so that every node receives its corners in ascending (element, corner).
      auto assemble = [&] {
        if (!sums) return;
        // (Never taken since rows are not streamed with sums; kept: removing it changes
        // GCC's FMA contraction of the corner forces, and so the last bits.)
        if (stream && slots) simd::stream_fence();
        for (int k = 0; k < lanes; ++k) {
          const double* f[3] = {rows_of[0] + 8 * k, rows_of[1] + 8 * k, rows_of[2] + 8 * k};
          _Pragma("GCC unroll 2") for (int h = 0; h < 8; h += 4) {
            double* const q[4] = {sums + 4 * static_cast<std::ptrdiff_t>(conn[h][e + k]),
                                  sums + 4 * static_cast<std::ptrdiff_t>(conn[h + 1][e + k]),
                                  sums + 4 * static_cast<std::ptrdiff_t>(conn[h + 2][e + k]),
                                  sums + 4 * static_cast<std::ptrdiff_t>(conn[h + 3][e + k])};
            simd::add_columns4(q, f[0] + h, f[1] + h, f[2] + h);
          }
        }
      };
      if (stdx::none_of(report && live)) {
        const auto lower = live && dte < best_dt;
        stdx::where(lower, best_dt) = dte;
        stdx::where(lower, best_e) = lane + static_cast<double>(e);
        assemble();
        continue;
      }
      // The scalar path may overwrite this vector's streamed corner rows (erosion): order
      // the non-temporal stores first.
      if (stream) simd::stream_fence();
      for (int k = 0; k < lanes; ++k) {
        const std::int64_t id = b.gid[e + k];
        if (b.alive[e + k] == 0.0) continue;
        // An element crushed flat reaches a volume that is positive by round-off, and
        // forces that are not finite, before its volume turns negative: with `inverted`
        // it erodes then too (QA round 7: the run stopped instead).
        const bool erode = (b.erosion.inverted && (inverted[k] || !std::isfinite(check[k]))) ||
                           (erode_ep && b.plastic_strain[e + k] >= b.erosion.plastic_strain);
        if (erode) { // delete it now: this cycle's forces already leave it out
          b.alive[e + k] = 0.0;
          ++b.eroded;
          b.internal_energy[e + k] = ie_old[k]; // its energies as before this step
          b.hourglass_energy[e + k] = he_old[k];
          for (int a = 0; a < 8; ++a)
            for (double* r : rows_of) r[8 * k + a] = 0.0;
          for (auto& sk : b.stress) sk[e + k] = 0.0;
          for (auto& hk : b.hourglass_force)
            if (!hk.empty()) hk[e + k] = 0.0;
          for (auto& pt : b.point_stress)
            for (auto& sk : pt) sk[e + k] = 0.0;
          ++result.eroded;
          continue;
        }
        if (inverted[k]) {
          if (result.inverted_gid < 0 || id < result.inverted_gid) result.inverted_gid = id;
        } else if (!std::isfinite(check[k])) {
          if (result.nonfinite_gid < 0 || id < result.nonfinite_gid) result.nonfinite_gid = id;
        }
        take_step(dte[k], id);
      }
      assemble();
    }
  }
  if (stream) simd::stream_fence();
  for (int k = 0; k < width; ++k)
    if (best_e[k] >= 0) take_step(best_dt[k], b.gid[static_cast<std::size_t>(best_e[k])]);
}

} // namespace detail

void hex_forces(HexBlock& b, const NodalView& nodes, double dt, CornerView corners,
                HexWorkspace& work, HexResult& result) {
  if (b.thick_shell.enabled())
    detail::block_forces<2>(b, nodes, dt, corners, work, result);
  else if (b.hourglass.model == HourglassControl::Model::assumed_strain)
    detail::block_forces<1>(b, nodes, dt, corners, work, result);
  else
    detail::block_forces<0>(b, nodes, dt, corners, work, result);
}

void element_corners(const HexBlock& b, const double* const x[3], std::size_t e,
                     double (&xe)[8][3]) {
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i) xe[a][i] = x[i][b.conn[a][e]] - x[i][b.conn[0][e]];
}

void hex_volumes(const HexBlock& b, const double* const x[3], std::span<double> out) {
  const std::size_t n = std::min(out.size(), b.conn[0].size());
  for (std::size_t e = 0; e < n; ++e) {
    double xe[8][3], B[8][3];
    element_corners(b, x, e, xe);
    hex8::gradient(xe, B);
    out[e] = hex8::volume(xe, B);
  }
}

} // namespace anvil
