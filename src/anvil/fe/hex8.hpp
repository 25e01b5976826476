// The 8-node hexahedron with one-point (uniform strain) integration of Flanagan and
// Belytschko (1981, IJNME 17, 679-706). Written once as templates over the value type:
// `double` for setup and tests, simd::vdouble in the vectorised kernel, so both paths
// run the same arithmetic in the same order.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

#include "anvil/core/simd.hpp"

namespace anvil::hex8 {

// Everything here is small, fixed-size arithmetic: fully unrolled and inlined, so that
// node permutations and +-1 coefficients become constants.
#define ANVIL_HEX8_INLINE [[gnu::always_inline]] inline

// Hourglass base vectors Gamma (eta zeta, xi zeta, xi eta, xi eta zeta at the nodes).
inline constexpr double gamma_base[4][8] = {{1, 1, -1, -1, -1, -1, 1, 1},
                                            {1, -1, -1, 1, -1, 1, 1, -1},
                                            {1, -1, 1, -1, 1, -1, 1, -1},
                                            {-1, 1, -1, 1, 1, -1, 1, -1}};

// For node a, the nodes that play "2..8" in Flanagan and Belytschko's formula for b_1.
inline constexpr int fb_perm[8][7] = {
    {1, 2, 3, 4, 5, 6, 7}, {2, 3, 0, 5, 6, 7, 4}, {3, 0, 1, 6, 7, 4, 5}, {0, 1, 2, 7, 4, 5, 6},
    {7, 6, 5, 0, 3, 2, 1}, {4, 7, 6, 1, 0, 3, 2}, {5, 4, 7, 2, 1, 0, 3}, {6, 5, 4, 3, 2, 1, 0}};

// The twelve edges (bottom face, top face, verticals) and the edge joining two nodes.
inline constexpr int edge_nodes[12][2] = {{0, 1}, {1, 2}, {2, 3}, {0, 3}, {4, 5}, {5, 6},
                                          {6, 7}, {4, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
constexpr int edge_of(int p, int q) {
  for (int e = 0; e < 12; ++e)
    if ((edge_nodes[e][0] == p && edge_nodes[e][1] == q) ||
        (edge_nodes[e][0] == q && edge_nodes[e][1] == p))
      return e;
  return -1;
}

// For node a, the edges s_23, s_34, s_26, s_56, s_48, s_58 of the gradient below, where
// s_mn joins n_m and n_n in Flanagan and Belytschko's numbering (n_m = fb_perm[a][m - 2]).
struct GradientEdges {
  int e[8][6];
};
inline constexpr GradientEdges gradient_edges = [] {
  GradientEdges g{};
  for (int a = 0; a < 8; ++a) {
    const int* p = fb_perm[a];
    const int pairs[6][2] = {{p[0], p[1]}, {p[1], p[2]}, {p[0], p[4]},
                             {p[3], p[4]}, {p[2], p[6]}, {p[3], p[6]}};
    for (int m = 0; m < 6; ++m) g.e[a][m] = edge_of(pairs[m][0], pairs[m][1]);
  }
  return g;
}();
static_assert([] {
  for (const auto& row : gradient_edges.e)
    for (int e : row)
      if (e < 0) return false;
  return true;
}());

// Gradient operator B_ia = integral over the element of dN_a/dx_i = dV/dx_ia, exact for
// the trilinear map (Flanagan and Belytschko eq. 79). x[a][i]: node a, coordinate i.
// Evaluated in the factored form of the volume derivative (as LULESH's VoluDer): with
// n_1..n_8 the nodes fb_perm[a] (n_1 = a) and s_pq = x_p + x_q,
//   12 B_ia = s_34 (j) s_23 (k) - s_23 (j) s_34 (k) + s_26 (j) s_56 (k) - s_56 (j) s_26 (k)
//           - s_48 (j) s_58 (k) + s_58 (j) s_48 (k),   (j, k) = (i + 1, i + 2) mod 3,
// the same polynomial as eq. 79, rearranged. Every pair is an edge of the hexahedron
// that does not touch node a, so the twelve edge sums are formed once and shared by the
// eight nodes (each edge serves four of them): 36 additions and 8 x 3 x 6 products.
//
// The kernel evaluates it in pieces (edge_sums, then gradient12 one coordinate direction
// at a time, without the factor 1/12) so that few values are live at once; gradient()
// is the same arithmetic in one piece.
template <class V>
ANVIL_HEX8_INLINE void edge_sums(const V (&x)[8][3], V (&s)[12][3]) {
  _Pragma("GCC unroll 12") for (int e = 0; e < 12; ++e)
      _Pragma("GCC unroll 3") for (int i = 0; i < 3; ++i) s[e][i] =
          x[edge_nodes[e][0]][i] + x[edge_nodes[e][1]][i];
}

// 12 B_ia from the edge sums of the two other directions: sj(e) = s_e (i + 1),
// sk(e) = s_e (i + 2) (mod 3). Every product is sj(.) * sk(.), so a caller that holds the
// twelve sk in registers needs one instruction per product.
template <class V, class SJ, class SK>
ANVIL_HEX8_INLINE V gradient12(int a, const SJ& sj, const SK& sk) {
  const int e23 = gradient_edges.e[a][0], e34 = gradient_edges.e[a][1];
  const int e26 = gradient_edges.e[a][2], e56 = gradient_edges.e[a][3];
  const int e48 = gradient_edges.e[a][4], e58 = gradient_edges.e[a][5];
  return V(sj(e34) * sk(e23) - sj(e23) * sk(e34) + sj(e26) * sk(e56) - sj(e56) * sk(e26) -
           sj(e48) * sk(e58) + sj(e58) * sk(e48));
}

template <class V>
ANVIL_HEX8_INLINE void gradient(const V (&x)[8][3], V (&B)[8][3]) {
  V s[12][3];
  edge_sums(x, s);
  _Pragma("GCC unroll 8") for (int a = 0; a < 8; ++a)
      _Pragma("GCC unroll 3") for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    B[a][i] = gradient12<V>(
                  a, [&](int e) -> const V& { return s[e][j]; },
                  [&](int e) -> const V& { return s[e][k]; }) *
              (1.0 / 12.0);
  }
}

// Volume from the gradient: V = sum_a x_a B_xa (exact).
template <class V>
ANVIL_HEX8_INLINE V volume(const V (&x)[8][3], const V (&B)[8][3]) {
  V v = x[0][0] * B[0][0];
  _Pragma("GCC unroll 8") for (int a = 1; a < 8; ++a) v += x[a][0] * B[a][0];
  return v;
}

// Sum of B_ia^2, the measure of the element's maximum eigenvalue.
template <class V>
ANVIL_HEX8_INLINE V gradient_norm2(const V (&B)[8][3]) {
  V s = B[0][0] * B[0][0];
  _Pragma("GCC unroll 8") for (int a = 0; a < 8; ++a)
      _Pragma("GCC unroll 8") for (int i = (a == 0 ? 1 : 0); i < 3; ++i) s += B[a][i] * B[a][i];
  return s;
}

// Sum over the nodes of w_a Gamma_alpha,a for each of the four hourglass base vectors.
// Gamma's entries are +-1, so this is additions only, factored through four partial
// sums: out = (S_A + S_B, S_A - S_B, S_C + S_D, S_C - S_D) with S_A = w0 - w2 - w4 + w6,
// S_B = w1 - w3 - w5 + w7, S_C = w4 - w5 + w6 - w7, S_D = w0 - w1 + w2 - w3
// (16 additions instead of 28).
template <class V>
ANVIL_HEX8_INLINE void gamma_sums(const V (&w)[8], V (&out)[4]) {
  const V sa = (w[0] - w[2]) + (w[6] - w[4]), sb = (w[1] - w[3]) + (w[7] - w[5]);
  const V sc = (w[4] - w[5]) + (w[6] - w[7]), sd = (w[0] - w[1]) + (w[2] - w[3]);
  out[0] = sa + sb;
  out[1] = sa - sb;
  out[2] = sc + sd;
  out[3] = sc - sd;
}

// The transpose: out_a = sum_alpha Gamma_alpha,a q_alpha for the eight nodes, through
// A = q0 + q1, B = q0 - q1, C = q2 + q3, D = q2 - q3 (12 additions instead of 24).
template <class V>
ANVIL_HEX8_INLINE void gamma_spread(const V (&q)[4], V (&out)[8]) {
  const V A = q[0] + q[1], B = q[0] - q[1], C = q[2] + q[3], D = q[2] - q[3];
  out[0] = A + D;
  out[1] = B - D;
  out[2] = D - A;
  out[3] = -(B + D);
  out[4] = C - A;
  out[5] = -(B + C);
  out[6] = A + C;
  out[7] = B - C;
}

// 8 times the columns of the Jacobian at the centre, J_d = sum_a w_a dN_a/dxi_d at xi = 0,
// for one coordinate direction of the nodal values w: out = (sum_a xi_a w_a, sum_a eta_a
// w_a, sum_a zeta_a w_a) with the nodes' natural coordinates +-1 (additions only).
template <class V>
ANVIL_HEX8_INLINE void natural_sums(const V (&w)[8], V (&out)[3]) {
  const V p01 = w[0] + w[1], p23 = w[2] + w[3], p45 = w[4] + w[5], p67 = w[6] + w[7];
  out[0] = ((w[1] - w[0]) + (w[2] - w[3])) + ((w[5] - w[4]) + (w[6] - w[7]));
  out[1] = (p23 - p01) + (p67 - p45);
  out[2] = (p45 + p67) - (p01 + p23);
}

// Determinant of a 3 x 3 matrix (scalars or vectors of them).
template <class V>
ANVIL_HEX8_INLINE V determinant(const V (&J)[3][3]) {
  return J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
         J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
         J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
}

// det J at the element's centre (V on a parallelepiped is 8 times it), from the corner
// positions x[a][i]: the one-point element's measure of its volume, which a tangled
// element's exact volume can hide.
template <class V>
ANVIL_HEX8_INLINE V centre_jacobian(const V (&x)[8][3]) {
  V J[3][3];
  for (int i = 0; i < 3; ++i) {
    V col[8];
    for (int a = 0; a < 8; ++a) col[a] = x[a][i];
    natural_sums(col, J[i]); // 8 dx_i / dxi_d
  }
  return determinant(J) / 512.0;
}

// The element's co-rotational frame: orthonormal axes e[d] (components e[d][i]) from the
// centre Jacobian's columns (J[i][d] = 8 dx_i/dxi_d, natural_sums of the positions) by
// Gram-Schmidt in the order xi, eta, zeta, and the element's extents along them,
// len[d] = the diagonal of the triangular factor J = e^T R (8 times the half-edges a, b, c
// of a box; len[0] len[1] len[2] = 64 V on any parallelepiped). The frame rotates with the
// element, so quantities stored in it are objective.
template <class V>
ANVIL_HEX8_INLINE void corotational_frame(const V (&J)[3][3], V (&e)[3][3], V (&len)[3]) {
  using std::abs;
  using std::sqrt;
  const V n0 = sqrt(J[0][0] * J[0][0] + J[1][0] * J[1][0] + J[2][0] * J[2][0]);
  const V i0 = 1.0 / n0;
  _Pragma("GCC unroll 3") for (int i = 0; i < 3; ++i) e[0][i] = J[i][0] * i0;
  const V p = J[0][1] * e[0][0] + J[1][1] * e[0][1] + J[2][1] * e[0][2];
  V w[3];
  _Pragma("GCC unroll 3") for (int i = 0; i < 3; ++i) w[i] = J[i][1] - p * e[0][i];
  const V n1 = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  const V i1 = 1.0 / n1;
  _Pragma("GCC unroll 3") for (int i = 0; i < 3; ++i) e[1][i] = w[i] * i1;
  e[2][0] = e[0][1] * e[1][2] - e[0][2] * e[1][1];
  e[2][1] = e[0][2] * e[1][0] - e[0][0] * e[1][2];
  e[2][2] = e[0][0] * e[1][1] - e[0][1] * e[1][0];
  len[0] = n0;
  len[1] = n1;
  len[2] = abs(J[0][2] * e[2][0] + J[1][2] * e[2][1] + J[2][2] * e[2][2]);
}

// The assumed-strain hourglass stiffness (docs/element.md, "Assumed-strain hourglass
// control"): the rate r[d][al] = dQ_d,al/dt of the generalized hourglass forces from the
// hourglass velocities q[d][al] = sum_b v_db gamma_al,b, both in the co-rotational frame
// (d = 0, 1, 2 along the element's xi, eta, zeta axes; al as gamma_base: eta zeta,
// xi zeta, xi eta, xi eta zeta). len: the frame's extents (corotational_frame); E and mu:
// Young's and shear modulus, already scaled by the deck's coefficient. With
// w = len0 len1 len2 / 192 (= V / 3 on a parallelepiped) and il = 1 / len:
//   the modes whose field depends on the direction's own coordinate (normal strain, a
//   beam fibre bending):  r = E w il_d^2 q (al = 0..2), E w il_d^2 q / 3 (al = 3);
//   the three "twist" modes t = (q[0][0], q[1][1], q[2][2]) (shear only), coupled through
//   g_xy = t_x il_1 + t_y il_0, g_yz = t_y il_2 + t_z il_1, g_zx = t_z il_0 + t_x il_2:
//   r[0][0] = mu w (g_xy il_1 + g_zx il_2), r[1][1] = mu w (g_xy il_0 + g_yz il_2),
//   r[2][2] = mu w (g_yz il_1 + g_zx il_0).
// Zeta = false leaves out the zeta group (the normal modes (0, 1) and (1, 0) and the
// twist modes' g_xy part: r[0][1] = r[1][0] = 0), whose stresses a thick shell
// integrates at its points through the thickness instead (docs/element.md).
template <bool Zeta = true, class V>
ANVIL_HEX8_INLINE void assumed_strain_rate(double E, double mu, const V (&len)[3],
                                           const V (&q)[3][4], V (&r)[3][4]) {
  const V i01 = 1.0 / (len[0] * len[1]);
  const V il[3] = {len[1] * i01, len[0] * i01, 1.0 / len[2]};
  const V w = (1.0 / 192.0) * len[0] * len[1] * len[2];
  _Pragma("GCC unroll 3") for (int d = 0; d < 3; ++d) {
    const V k = (E * w) * (il[d] * il[d]);
    _Pragma("GCC unroll 3") for (int al = 0; al < 3; ++al) if (al != d) r[d][al] = k * q[d][al];
    r[d][3] = (1.0 / 3.0) * k * q[d][3];
  }
  const V gyz = q[1][1] * il[2] + q[2][2] * il[1];
  const V gzx = q[2][2] * il[0] + q[0][0] * il[2];
  const V mw = mu * w;
  if constexpr (Zeta) {
    const V gxy = q[0][0] * il[1] + q[1][1] * il[0];
    r[0][0] = mw * (gxy * il[1] + gzx * il[2]);
    r[1][1] = mw * (gxy * il[0] + gyz * il[2]);
  } else {
    r[0][1] = 0.0;
    r[1][0] = 0.0;
    r[0][0] = mw * (gzx * il[2]);
    r[1][1] = mw * (gyz * il[2]);
  }
  r[2][2] = mw * (gyz * il[1] + gzx * il[0]);
}

// One group of the plastic limits below: the fibre stresses of the normal modes (d, al)
// and (e, be) and the shear moment t (iv = 2 / V, ks = sqrt 3 iv), checked with von Mises'
// criterion against sy (sy2 = sy^2) and scaled back onto it when past it (then phi > 0);
// returns the factor.
template <class V>
ANVIL_HEX8_INLINE V limit_group(V (&Q)[3][4], const V (&len)[3], const V& iv, const V& ks,
                                const V& sy, const V& sy2, int d, int al, int e, int be,
                                const V& t) {
  using std::sqrt;
  const V sa = Q[d][al] * len[d] * iv, sb = Q[e][be] * len[e] * iv, ss = t * ks;
  const V phi = sa * sa - sa * sb + sb * sb + ss * ss;
  const V k = simd::select(phi > sy2, sy / sqrt(phi), V(1.0));
  Q[d][al] *= k;
  Q[e][be] *= k;
  return k;
}

// The xi eta zeta modes' limit: each clipped to |s| <= sy on its own.
template <class V>
ANVIL_HEX8_INLINE void limit_xi_eta_zeta(const V& sy, const V (&len)[3], V (&Q)[3][4]) {
  _Pragma("GCC unroll 3") for (int d = 0; d < 3; ++d) {
    const V cap = (sy * (1.0 / 256.0)) * (len[(d + 1) % 3] * len[(d + 2) % 3]); // |s| <= sy
    Q[d][3] = simd::select(Q[d][3] > cap, cap, simd::select(Q[d][3] < -cap, -cap, Q[d][3]));
  }
}

// The plastic limit of the assumed-strain hourglass forces (docs/element.md, "Plastic
// limit"): Q[d][al] the generalized forces in the co-rotational frame (as r in
// assumed_strain_rate), len the frame's extents, sy the material's current flow stress.
// The hourglass stress field's first moments T (T = int sigma c dV, c the coordinate the
// stress varies with; V = len0 len1 len2 / 64, the frame's box) are
//   normal-strain modes: T = Q len_d, fully plastic (sigma = +-sy across the section) at
//   sy V / 2, and sy V / 4 for the xi eta zeta modes (al = 3);
//   twist modes: Q_twist = A T_s with T_s = (T_xy, T_yz, T_zx), the shear stresses' moments,
//   A as in assumed_strain_rate (Q_x = T_xy il1 + T_zx il2, ...), fully plastic at
//   (sy / sqrt 3) V / 2.
// Written as fibre stresses s = 2 T / V (4 T / V for al = 3; 2 sqrt(3) T / V for shear),
// which equal sy when fully plastic, the stresses that vary with one coordinate form a
// group checked with von Mises' criterion, sa^2 - sa sb + sb^2 + ss^2 <= sy^2:
//   zeta: sigma_xx (d 0, al 1), sigma_yy (1, 0), tau_xy;  eta: sigma_xx (0, 2),
//   sigma_zz (2, 0), tau_zx;  xi: sigma_yy (1, 2), sigma_zz (2, 1), tau_yz;
// and a group past it is scaled back onto it (radially). Each xi eta zeta mode is
// clipped to |s| <= sy on its own. The groups are limited independently, and the
// one-point stress (the membrane) does not enter: see docs/element.md.
template <class V>
ANVIL_HEX8_INLINE void assumed_strain_limit(const V& sy, const V (&len)[3], V (&Q)[3][4]) {
  const V iv = 128.0 / (len[0] * len[1] * len[2]); // 2 / V
  const V il2 = 1.0 / len[2];
  // Shear moments from the twist forces (A^-1 Q; det A = 2 il0 il1 il2).
  const V qx = Q[0][0], qy = Q[1][1], qz = Q[2][2];
  const V txy = 0.5 * (qx * len[1] + qy * len[0] - qz * (len[0] * len[1] * il2));
  const V tyz = 0.5 * (qz * len[1] + qy * len[2] - qx * (len[1] * len[2] / len[0]));
  const V tzx = 0.5 * (qx * len[2] + qz * len[0] - qy * (len[2] * len[0] / len[1]));
  const V ks = 1.7320508075688772 * iv;
  const V sy2 = sy * sy;
  auto group = [&](int d, int al, int e, int be, const V& t) {
    return limit_group(Q, len, iv, ks, sy, sy2, d, al, e, be, t);
  };
  const V kz = group(0, 1, 1, 0, txy);
  const V ky = group(0, 2, 2, 0, tzx);
  const V kx = group(1, 2, 2, 1, tyz);
  const V sxy = txy * kz, syz = tyz * kx, szx = tzx * ky;
  const V il0 = 1.0 / len[0], il1 = 1.0 / len[1];
  const auto scaled = (kz < 1.0) || (ky < 1.0) || (kx < 1.0);
  Q[0][0] = simd::select(scaled, sxy * il1 + szx * il2, Q[0][0]);
  Q[1][1] = simd::select(scaled, sxy * il0 + syz * il2, Q[1][1]);
  Q[2][2] = simd::select(scaled, syz * il1 + szx * il0, Q[2][2]);
  limit_xi_eta_zeta(sy, len, Q);
}

// Gauss points and weights on [-1, 1] through the thickness of a thick-shell element
// (docs/element.md, "Thick shell"): row n - 2 holds the n-point rule, n = 2..5.
inline constexpr int thick_shell_max_points = 5;
inline constexpr double thick_shell_point[4][5] = {
    {-0.5773502691896257, 0.5773502691896257},
    {-0.7745966692414834, 0.0, 0.7745966692414834},
    {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526},
    {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640}};
inline constexpr double thick_shell_weight[4][5] = {
    {1.0, 1.0},
    {0.5555555555555556, 0.8888888888888888, 0.5555555555555556},
    {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538},
    {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
     0.2369268850561891}};

// The plastic limit of assumed_strain_rate<false>'s forces (the thick shell's):
// assumed_strain_limit's eta and xi groups and xi eta zeta clips (the zeta group yields at the
// integration points). With no zeta-group force, the twist forces give the shear moments directly:
// T_zx = Q_x len2, T_yz = Q_y len2 (and Q_z = T_yz il1 + T_zx il0).
template <class V>
ANVIL_HEX8_INLINE void thick_shell_limit(const V& sy, const V (&len)[3], V (&Q)[3][4]) {
  const V iv = 128.0 / (len[0] * len[1] * len[2]); // 2 / V
  const V tyz = Q[1][1] * len[2], tzx = Q[0][0] * len[2];
  const V ks = 1.7320508075688772 * iv;
  const V sy2 = sy * sy;
  const V ky = limit_group(Q, len, iv, ks, sy, sy2, 0, 2, 2, 0, tzx);
  const V kx = limit_group(Q, len, iv, ks, sy, sy2, 1, 2, 2, 1, tyz);
  const V syz = tyz * kx, szx = tzx * ky;
  const V il0 = 1.0 / len[0], il1 = 1.0 / len[1], il2 = 1.0 / len[2];
  const auto scaled = (ky < 1.0) || (kx < 1.0);
  Q[0][0] = simd::select(scaled, szx * il2, Q[0][0]);
  Q[1][1] = simd::select(scaled, syz * il2, Q[1][1]);
  Q[2][2] = simd::select(scaled, syz * il1 + szx * il0, Q[2][2]);
  limit_xi_eta_zeta(sy, len, Q);
}

// Hourglass shape vectors gamma_alpha = Gamma_alpha - (1/V)(Gamma_alpha . x_i) B_i, which
// are orthogonal to every linear velocity field on any shape (the property that lets the
// element pass the patch test with hourglass control on).
template <class V>
ANVIL_HEX8_INLINE void hourglass_shape(const V (&x)[8][3], const V (&B)[8][3], const V& inv_volume,
                                       V (&g)[4][8]) {
  _Pragma("GCC unroll 8") for (int al = 0; al < 4; ++al) {
    V h[3];
    _Pragma("GCC unroll 8") for (int i = 0; i < 3; ++i) {
      h[i] = gamma_base[al][0] * x[0][i];
      _Pragma("GCC unroll 8") for (int a = 1; a < 8; ++a) h[i] += gamma_base[al][a] * x[a][i];
      h[i] *= inv_volume;
    }
    _Pragma("GCC unroll 8") for (int a = 0; a < 8; ++a) g[al][a] =
        gamma_base[al][a] - (h[0] * B[a][0] + h[1] * B[a][1] + h[2] * B[a][2]);
  }
}

// A cheaper bound on the same eigenvalue as hourglass_damping_bound below: it is the
// squared spectral norm of the 8 x 4 matrix [gamma_alpha] = Gamma - B H, at most
// (|Gamma| + |B| |H|)^2 with |Gamma| = sqrt 8 (four orthogonal columns of squared norm 8)
// and the Frobenius norms |B|^2 = B:B (bb), |H|^2 = sum h_alpha,i^2 (hh). Exactly 8 on
// any parallelepiped (H = 0). Neither bound is always the smaller.
template <class V>
ANVIL_HEX8_INLINE V hourglass_damping_bound_frobenius(const V& bb, const V& hh) {
  using std::sqrt;
  const V root = 2.8284271247461903 + sqrt(bb * hh);
  return root * root;
}

// A bound on the largest eigenvalue of sum_alpha gamma_alpha gamma_alpha^T, the matrix
// through which the viscous hourglass force damps the nodal velocities (gamma_alpha =
// Gamma_alpha - B h_alpha as in hourglass_shape, h_alpha = (1/V) sum_a Gamma_alpha,a x_a,
// given here as h[alpha][i], and B by its columns Bc[i][a]). Its eigenvalues are those of
// the 4 x 4 Gram matrix G_ab = gamma_a . gamma_b = 8 delta_ab - h_a . g_b - h_b . g_a +
// h_a . (B^T B) h_b, g_a,i = sum_n Gamma_a,n B_ni, bounded by Gershgorin's largest
// absolute row sum: exactly 8 on any parallelepiped (h = 0), growing as the element warps
// and flattens.
template <class V>
ANVIL_HEX8_INLINE V hourglass_damping_bound(const V (&Bc)[3][8], const V (&h)[4][3]) {
  using std::abs;
  using std::max;
  V g[3][4];
  _Pragma("GCC unroll 8") for (int i = 0; i < 3; ++i) gamma_sums(Bc[i], g[i]);
  V M[3][3];
  _Pragma("GCC unroll 8") for (int i = 0; i < 3; ++i)
      _Pragma("GCC unroll 8") for (int j = i; j < 3; ++j) {
    V s = Bc[i][0] * Bc[j][0];
    _Pragma("GCC unroll 8") for (int a = 1; a < 8; ++a) s += Bc[i][a] * Bc[j][a];
    M[i][j] = s;
    M[j][i] = s;
  }
  // p_b = (B^T B) h_b - g_b, so that G_ab = 8 delta_ab + h_a . p_b - h_b . g_a.
  V p[4][3];
  _Pragma("GCC unroll 8") for (int b = 0; b < 4; ++b)
      _Pragma("GCC unroll 8") for (int i = 0; i < 3; ++i) p[b][i] =
          M[i][0] * h[b][0] + M[i][1] * h[b][1] + M[i][2] * h[b][2] - g[i][b];
  V G[4][4];
  _Pragma("GCC unroll 8") for (int a = 0; a < 4; ++a)
      _Pragma("GCC unroll 8") for (int b = a; b < 4; ++b) {
    V s = h[a][0] * p[b][0] + h[a][1] * p[b][1] + h[a][2] * p[b][2] -
          (h[b][0] * g[0][a] + h[b][1] * g[1][a] + h[b][2] * g[2][a]);
    if (a == b) s += 8.0;
    G[a][b] = s;
    G[b][a] = s;
  }
  V bound = abs(G[0][0]) + abs(G[0][1]) + abs(G[0][2]) + abs(G[0][3]);
  _Pragma("GCC unroll 8") for (int a = 1; a < 4; ++a) bound =
      max(bound, abs(G[a][0]) + abs(G[a][1]) + abs(G[a][2]) + abs(G[a][3]));
  return bound;
}

// The velocity gradient L split into the rate of deformation d (xx, yy, zz, xy, yz, xz)
// and the spin's axial vector w (W_zy, W_xz, W_yx). For elements and particles alike.
template <class V>
ANVIL_HEX8_INLINE void rate_and_spin(const V (&L)[3][3], V (&d)[6], V (&w)[3]) {
  d[0] = L[0][0];
  d[1] = L[1][1];
  d[2] = L[2][2];
  d[3] = 0.5 * (L[0][1] + L[1][0]);
  d[4] = 0.5 * (L[1][2] + L[2][1]);
  d[5] = 0.5 * (L[0][2] + L[2][0]);
  w[0] = 0.5 * (L[2][1] - L[1][2]);
  w[1] = 0.5 * (L[0][2] - L[2][0]);
  w[2] = 0.5 * (L[1][0] - L[0][1]);
}

// Incremental rotation of Hughes and Winget (1980): Q = (I - A)^-1 (I + A), A = dt/2 W,
// which for a skew A with axial vector a is Q = I + 2 (A + A^2) / (1 + |a|^2). It is
// exactly orthogonal and reproduces the rotation of the mid-step configuration, so a
// rigidly spinning body keeps its stress unchanged but for the rotation.
template <class V>
ANVIL_HEX8_INLINE void hughes_winget(const V (&w)[3], double dt, V (&Q)[3][3]) {
  const V a0 = (0.5 * dt) * w[0], a1 = (0.5 * dt) * w[1], a2 = (0.5 * dt) * w[2];
  const V k = 2.0 / (1.0 + (a0 * a0 + a1 * a1 + a2 * a2));
  // A = [[0, -a2, a1], [a2, 0, -a0], [-a1, a0, 0]]; A^2 = a a^T - |a|^2 I.
  const V n2 = a0 * a0 + a1 * a1 + a2 * a2;
  Q[0][0] = 1.0 + k * (a0 * a0 - n2);
  Q[1][1] = 1.0 + k * (a1 * a1 - n2);
  Q[2][2] = 1.0 + k * (a2 * a2 - n2);
  Q[0][1] = k * (a0 * a1 - a2);
  Q[1][0] = k * (a0 * a1 + a2);
  Q[0][2] = k * (a0 * a2 + a1);
  Q[2][0] = k * (a0 * a2 - a1);
  Q[1][2] = k * (a1 * a2 - a0);
  Q[2][1] = k * (a1 * a2 + a0);
}

// s <- Q s Q^T for a symmetric tensor in (xx, yy, zz, xy, yz, xz) order.
template <class V>
ANVIL_HEX8_INLINE void rotate_symmetric(const V (&Q)[3][3], V (&s)[6]) {
  const V S[3][3] = {{s[0], s[3], s[5]}, {s[3], s[1], s[4]}, {s[5], s[4], s[2]}};
  V T[3][3];
  _Pragma("GCC unroll 8") for (int i = 0; i < 3; ++i)
      _Pragma("GCC unroll 8") for (int j = 0; j < 3; ++j) T[i][j] =
          Q[i][0] * S[0][j] + Q[i][1] * S[1][j] + Q[i][2] * S[2][j];
  auto r = [&](int i, int j) { return T[i][0] * Q[j][0] + T[i][1] * Q[j][1] + T[i][2] * Q[j][2]; };
  s[0] = r(0, 0);
  s[1] = r(1, 1);
  s[2] = r(2, 2);
  s[3] = r(0, 1);
  s[4] = r(1, 2);
  s[5] = r(0, 2);
}

} // namespace anvil::hex8
