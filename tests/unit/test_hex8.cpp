// The element's building blocks against their definitions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "anvil/fe/hex8.hpp"
#include "anvil/mesh/generators.hpp"
#include "anvil/mesh/mesh.hpp"

namespace {

using namespace anvil;

// A distorted hexahedron: unit brick with every node moved by up to 20%.
void distorted(double (&x)[8][3], unsigned seed) {
  static constexpr double s[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                     {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i) x[a][i] = s[a][i] * (1.0 + 0.5 * i) + u(rng);
}

double volume_of(const double (&x)[8][3]) {
  std::array<Vec3, 8> p;
  for (int a = 0; a < 8; ++a) p[a] = {x[a][0], x[a][1], x[a][2]};
  return hex_volume(p);
}

// Reference: B_ia = dV/dx_ia (Flanagan and Belytschko 1981, eq. 79), checked against a
// central difference of the exact (Gauss 2x2x2) volume. Tolerance 1e-8 relative: the
// difference quotient's truncation and round-off at h = 1e-6.
TEST(Hex8, GradientIsDerivativeOfVolume) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    double x[8][3], B[8][3];
    distorted(x, seed);
    hex8::gradient(x, B);
    EXPECT_NEAR(hex8::volume(x, B), volume_of(x), 1e-13 * volume_of(x));
    const double h = 1e-6;
    for (int a = 0; a < 8; ++a)
      for (int i = 0; i < 3; ++i) {
        double xp[8][3], xm[8][3];
        std::copy(&x[0][0], &x[0][0] + 24, &xp[0][0]);
        std::copy(&x[0][0], &x[0][0] + 24, &xm[0][0]);
        xp[a][i] += h;
        xm[a][i] -= h;
        const double fd = (volume_of(xp) - volume_of(xm)) / (2 * h);
        EXPECT_NEAR(B[a][i], fd, 1e-8) << "node " << a << " component " << i;
      }
  }
}

// Patch-test properties on a distorted element (Flanagan and Belytschko 1981): the
// gradient integrates linear fields exactly (sum_a x_ja B_ia = V delta_ij) and the
// hourglass shape vectors are orthogonal to linear fields (sum_a gamma_a x_ia = 0,
// sum_a gamma_a = 0). Tolerance: round-off, 1e-12 relative.
TEST(Hex8, LinearCompletenessAndHourglassOrthogonality) {
  double x[8][3], B[8][3], g[4][8];
  distorted(x, 7);
  hex8::gradient(x, B);
  const double V = hex8::volume(x, B);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double s = 0;
      for (int a = 0; a < 8; ++a) s += x[a][j] * B[a][i];
      EXPECT_NEAR(s, i == j ? V : 0.0, 1e-12 * V);
    }
  double sumB[3] = {0, 0, 0};
  for (int a = 0; a < 8; ++a)
    for (int i = 0; i < 3; ++i) sumB[i] += B[a][i];
  for (double s : sumB) EXPECT_NEAR(s, 0.0, 1e-12 * V);
  hex8::hourglass_shape(x, B, 1.0 / V, g);
  for (int al = 0; al < 4; ++al) {
    double s0 = 0, s[3] = {0, 0, 0};
    for (int a = 0; a < 8; ++a) {
      s0 += g[al][a];
      for (int i = 0; i < 3; ++i) s[i] += g[al][a] * x[a][i];
    }
    EXPECT_NEAR(s0, 0.0, 1e-12);
    for (double v : s) EXPECT_NEAR(v, 0.0, 1e-12);
  }
}

// The two bounds on the viscous hourglass damping matrix sum_al gamma_al gamma_al^T that
// the stable step uses, against the largest eigenvalue of the Gram matrix of the shape
// vectors formed explicitly by hourglass_shape (found by power iteration): Gershgorin's
// largest absolute row sum of that matrix, and (sqrt 8 + |B| |h|)^2; neither
// below the eigenvalue, and both exactly 8 on a parallelepiped, where gamma = Gamma (Flanagan and
// Belytschko 1981). Tolerances: round-off, 1e-12 relative; the power iteration's estimate may fall
// short of the eigenvalue, never exceed it.
TEST(Hex8, HourglassDampingBoundBoundsTheDampingMatrix) {
  auto check = [](const double(&x)[8][3]) {
    double B[8][3], g[4][8];
    hex8::gradient(x, B);
    const double V = hex8::volume(x, B);
    hex8::hourglass_shape(x, B, 1.0 / V, g);
    double Bc[3][8], h[4][3];
    for (int a = 0; a < 8; ++a)
      for (int i = 0; i < 3; ++i) Bc[i][a] = B[a][i];
    for (int al = 0; al < 4; ++al)
      for (int i = 0; i < 3; ++i) {
        h[al][i] = 0;
        for (int a = 0; a < 8; ++a) h[al][i] += hex8::gamma_base[al][a] * x[a][i] / V;
      }
    double G[4][4], gersh = 0;
    for (int a = 0; a < 4; ++a) {
      double row = 0;
      for (int b = 0; b < 4; ++b) {
        G[a][b] = 0;
        for (int n = 0; n < 8; ++n) G[a][b] += g[a][n] * g[b][n];
        row += std::abs(G[a][b]);
      }
      gersh = std::max(gersh, row);
    }
    double v[4] = {1, 0.9, 0.8, 0.7}, lambda = 0;
    for (int it = 0; it < 500; ++it) {
      double w[4] = {0, 0, 0, 0}, n = 0;
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) w[a] += G[a][b] * v[b];
      for (double c : w) n += c * c;
      n = std::sqrt(n);
      lambda = n;
      for (int a = 0; a < 4; ++a) v[a] = w[a] / n;
    }
    const double bound = hex8::hourglass_damping_bound(Bc, h);
    EXPECT_NEAR(bound, gersh, 1e-12 * gersh);
    EXPECT_GE(bound, lambda * (1 - 1e-12));
    double hh = 0;
    for (const auto& row : h)
      for (double v : row) hh += v * v;
    const double cheap = hex8::hourglass_damping_bound_frobenius(hex8::gradient_norm2(B), hh);
    EXPECT_GE(cheap, lambda * (1 - 1e-12));
    return std::min(bound, cheap);
  };
  for (unsigned seed = 1; seed <= 5; ++seed) {
    double x[8][3];
    distorted(x, seed);
    EXPECT_GT(check(x), 8.0);
  }
  // A sheared, stretched brick (a parallelepiped): gamma = Gamma, orthogonal, norm^2 8.
  double p[8][3];
  static constexpr double s[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                     {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for (int a = 0; a < 8; ++a) {
    p[a][0] = 3.0 * s[a][0] + 0.4 * s[a][1] + 0.2 * s[a][2];
    p[a][1] = 0.5 * s[a][1] - 0.3 * s[a][2];
    p[a][2] = 0.05 * s[a][2];
  }
  EXPECT_NEAR(check(p), 8.0, 8e-12);
  // A thin element warped out of its plane, as in a tight fold: the bound grows.
  double w[8][3];
  for (int a = 0; a < 8; ++a) {
    w[a][0] = 2.0 * s[a][0];
    w[a][1] = 2.0 * s[a][1];
    w[a][2] = 0.1 * s[a][2] + ((a == 0 || a == 2 || a == 4 || a == 6) ? 0.3 : 0.0);
  }
  EXPECT_GT(check(w), 8.0);
}

// The Hughes-Winget rotation is orthogonal and equals the Cayley transform of the spin:
// for a rigid rotation by angle theta about an axis, it rotates by exactly theta when the
// spin is computed at the mid-step, w = 2 tan(theta/2) / dt.
TEST(Hex8, HughesWingetIsTheIncrementalRotation) {
  const double dt = 1e-3, theta = 0.3;
  const double axis[3] = {1 / std::sqrt(3.0), 1 / std::sqrt(3.0), 1 / std::sqrt(3.0)};
  const double rate = 2 * std::tan(theta / 2) / dt;
  double w[3] = {rate * axis[0], rate * axis[1], rate * axis[2]}, Q[3][3];
  hex8::hughes_winget(w, dt, Q);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double s = 0;
      for (int k = 0; k < 3; ++k) s += Q[i][k] * Q[j][k];
      EXPECT_NEAR(s, i == j ? 1.0 : 0.0, 1e-14);
    }
  // Rodrigues' rotation matrix for the same axis and angle.
  const double c = std::cos(theta), s = std::sin(theta);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double r = c * (i == j) + (1 - c) * axis[i] * axis[j];
      const int k = 3 - i - j;
      if (i != j) r += ((j == (i + 1) % 3) ? -1.0 : 1.0) * s * axis[k];
      EXPECT_NEAR(Q[i][j], r, 1e-14) << i << j;
    }
}

} // namespace

namespace {

// A box with half-edges (a, b, c) along the columns of a rotation, and the energy 1/2 q . K q
// that the assumed-strain stiffness gives a nodal displacement field u(local x, y, z)
// (the code's q = sum_a u_a Gamma_a, a box being a parallelepiped).
struct RotatedBox {
  double R[3][3]; // columns: the box's axes
  double half[3] = {0.3, 0.5, 0.2};
  double x[8][3];
  RotatedBox() {
    const double n[3] = {1 / std::sqrt(14.0), 2 / std::sqrt(14.0), 3 / std::sqrt(14.0)};
    const double t = 0.7, co = std::cos(t), si = std::sin(t);
    const double K[3][3] = {{0, -n[2], n[1]}, {n[2], 0, -n[0]}, {-n[1], n[0], 0}};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) R[i][j] = co * (i == j) + (1 - co) * n[i] * n[j] + si * K[i][j];
    for (int a = 0; a < 8; ++a)
      for (int i = 0; i < 3; ++i) {
        x[a][i] = 0.1 * (i + 1);
        for (int d = 0; d < 3; ++d) x[a][i] += R[i][d] * half[d] * coord(a, d);
      }
  }
  static double coord(int a, int d) {
    static constexpr double s[3][8] = {
        {-1, 1, 1, -1, -1, 1, 1, -1}, {-1, -1, 1, 1, -1, -1, 1, 1}, {-1, -1, -1, -1, 1, 1, 1, 1}};
    return s[d][a];
  }
  template <class Field>
  double energy(double E, double mu, Field&& u) const {
    double J[3][3], col[8];
    for (int i = 0; i < 3; ++i) {
      for (int a = 0; a < 8; ++a) col[a] = x[a][i];
      hex8::natural_sums(col, J[i]);
    }
    double e[3][3], len[3];
    hex8::corotational_frame(J, e, len);
    double q[3][4] = {}, ql[3][4] = {}, r[3][4];
    for (int a = 0; a < 8; ++a) {
      double ul[3], ug[3] = {0, 0, 0};
      u(half[0] * coord(a, 0), half[1] * coord(a, 1), half[2] * coord(a, 2), ul);
      for (int i = 0; i < 3; ++i)
        for (int d = 0; d < 3; ++d) ug[i] += R[i][d] * ul[d];
      for (int al = 0; al < 4; ++al)
        for (int i = 0; i < 3; ++i) q[i][al] += hex8::gamma_base[al][a] * ug[i];
    }
    for (int d = 0; d < 3; ++d)
      for (int al = 0; al < 4; ++al)
        for (int i = 0; i < 3; ++i) ql[d][al] += e[d][i] * q[i][al];
    hex8::assumed_strain_rate(E, mu, len, ql, r);
    double U = 0;
    for (int d = 0; d < 3; ++d)
      for (int al = 0; al < 4; ++al) U += 0.5 * ql[d][al] * r[d][al];
    return U;
  }
};

// The frame of a rotated box is its axes, its extents 8 times its half-edges.
TEST(Hex8, CorotationalFrameOfARotatedBox) {
  const RotatedBox box;
  double J[3][3], col[8], e[3][3], len[3];
  for (int i = 0; i < 3; ++i) {
    for (int a = 0; a < 8; ++a) col[a] = box.x[a][i];
    hex8::natural_sums(col, J[i]);
  }
  hex8::corotational_frame(J, e, len);
  for (int d = 0; d < 3; ++d) {
    EXPECT_NEAR(len[d], 8 * box.half[d], 1e-14);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(e[d][i], box.R[i][d], 1e-14);
  }
}

// Pure bending u_x = k x y (the strain eps_xx = k y of a beam, the transverse displacement
// quadratic and invisible to the element) stores the beam's energy 1/2 E I k^2 L, with E,
// not lambda + 2 mu; a plate's twist (w = k x y: u = -k y z, v = -k x z, w = k x y) the
// plate's D (1 - nu) k^2 A = (4/3) mu c^3 k^2 (4 a b), with no transverse shear. Round-off.
TEST(Hex8, AssumedStrainStiffnessHasBeamBendingAndPlateTwist) {
  const RotatedBox box;
  const double E = 200e9, nu = 0.3, mu = E / (2 * (1 + nu)), k = 1e-3;
  const double a = box.half[0], b = box.half[1], c = box.half[2], V = 8 * a * b * c;
  const double bend = box.energy(E, mu, [&](double x, double y, double, double(&u)[3]) {
    u[0] = k * x * y;
    u[1] = u[2] = 0;
  });
  EXPECT_NEAR(bend, 0.5 * E * k * k * (b * b / 3) * V, 1e-12 * bend);
  const double twist = box.energy(E, mu, [&](double x, double y, double z, double(&u)[3]) {
    u[0] = -k * y * z;
    u[1] = -k * x * z;
    u[2] = k * x * y;
  });
  EXPECT_NEAR(twist, (4.0 / 3.0) * mu * c * c * c * k * k * 4 * a * b, 1e-12 * twist);
  // A linear field (a rigid rotation plus a stretch) stores nothing.
  const double lin = box.energy(E, mu, [&](double x, double y, double z, double(&u)[3]) {
    u[0] = 0.01 * x - 0.02 * y;
    u[1] = 0.02 * x + 0.03 * z;
    u[2] = -0.03 * y;
  });
  EXPECT_NEAR(lin, 0.0, 1e-12 * bend);
}

} // namespace

// hex8::assumed_strain_limit against the fully plastic resultants it states: in the
// frame of a 10 x 6 x 2 mm box (len = 8 x the half-extents, V = len0 len1 len2 / 64), a
// normal-strain mode's fibre stress is s = 2 Q len_d / V, a shear moment's 2 sqrt(3) T / V,
// an xi eta zeta mode's 4 Q len_d / V. Exact to round-off (1e-12 relative).
TEST(Hex8, AssumedStrainPlasticLimit) {
  const double len[3] = {0.04, 0.024, 0.008};
  const double V = len[0] * len[1] * len[2] / 64, sy = 250e6;
  auto fibre = [&](double Q, int d) { return 2 * Q * len[d] / V; };
  auto force = [&](double s, int d) { return s * V / (2 * len[d]); };
  // Inside the surface: nothing changes, to the bit.
  double Q[3][4] = {};
  Q[0][1] = force(0.5 * sy, 0);
  Q[1][0] = force(0.4 * sy, 1);
  Q[2][3] = 0.9 * sy * len[0] * len[1] / 256;
  double R[3][4];
  std::copy(&Q[0][0], &Q[0][0] + 12, &R[0][0]);
  hex8::assumed_strain_limit(sy, len, R);
  for (int d = 0; d < 3; ++d)
    for (int al = 0; al < 4; ++al) EXPECT_EQ(R[d][al], Q[d][al]) << d << " " << al;
  // Uniaxial bending at three times the limit: back to sy, the other groups untouched.
  double U[3][4] = {};
  U[0][2] = force(3 * sy, 0);   // sigma_xx varying with eta
  U[1][2] = force(0.5 * sy, 1); // sigma_yy varying with xi (another group)
  hex8::assumed_strain_limit(sy, len, U);
  EXPECT_NEAR(fibre(U[0][2], 0), sy, 1e-12 * sy);
  EXPECT_EQ(U[1][2], force(0.5 * sy, 1));
  // Equal biaxial bending (sigma_xx = sigma_yy, both with zeta): von Mises allows sy each.
  double B[3][4] = {};
  B[0][1] = force(2 * sy, 0);
  B[1][0] = force(2 * sy, 1);
  hex8::assumed_strain_limit(sy, len, B);
  EXPECT_NEAR(fibre(B[0][1], 0), sy, 1e-12 * sy);
  EXPECT_NEAR(fibre(B[1][0], 1), sy, 1e-12 * sy);
  // Twist (tau_xy only, T_xy = 2 x its fully plastic value): Q_x = T il1, Q_y = T il0.
  const double Tp = sy / std::sqrt(3.0) * V / 2;
  double W[3][4] = {};
  W[0][0] = 2 * Tp / len[1];
  W[1][1] = 2 * Tp / len[0];
  hex8::assumed_strain_limit(sy, len, W);
  EXPECT_NEAR(W[0][0], Tp / len[1], 1e-12 * Tp / len[1]);
  EXPECT_NEAR(W[1][1], Tp / len[0], 1e-12 * Tp / len[0]);
  EXPECT_NEAR(W[2][2], 0.0, 1e-12 * Tp / len[0]);
  // The xi eta zeta mode of z, past its limit either way: clipped to 4 |Q| len_2 / V = sy.
  double P[3][4] = {};
  P[2][3] = -5 * sy * len[0] * len[1] / 256;
  hex8::assumed_strain_limit(sy, len, P);
  EXPECT_NEAR(4 * P[2][3] * len[2] / V, -sy, 1e-12 * sy);
}

namespace {

using namespace anvil;

// orient_thickness_zeta turns each element of a thick-shell block so that its thinnest
// direction is zeta: here boxes thin in x, in y and in z. The volume stays positive (the
// turn keeps the orientation), the node set stays, zeta becomes the thin direction, and a
// side set follows its face (the face on the thin side, xmin of the first box, keeps its
// four nodes).
TEST(OrientThickness, ThinnestDirectionBecomesZeta) {
  Mesh m;
  ElementBlock b{"wall", {}};
  const Vec3 size[3] = {{0.001, 0.01, 0.02}, {0.02, 0.001, 0.01}, {0.01, 0.02, 0.001}};
  for (int k = 0; k < 3; ++k) {
    const auto first = static_cast<std::int64_t>(m.nodes.size());
    for (int c = 0; c < 8; ++c) {
      const double xi = (c == 1 || c == 2 || c == 5 || c == 6) ? 1 : 0;
      const double eta = (c == 2 || c == 3 || c == 6 || c == 7) ? 1 : 0;
      const double zeta = c >= 4 ? 1 : 0;
      m.nodes.push_back({0.1 * k + xi * size[k].x, eta * size[k].y, zeta * size[k].z});
    }
    Hex h;
    for (int c = 0; c < 8; ++c) h[c] = first + c;
    b.elements.push_back(h);
  }
  m.blocks.push_back(b);
  m.side_sets["xmin"] = {{0, 3}}; // face {3, 0, 4, 7} of element 0: its x = 0 side
  const std::vector<Hex> before = m.blocks[0].elements;
  orient_thickness_zeta(m, 0);
  for (int k = 0; k < 3; ++k) {
    const Hex& h = m.blocks[0].elements[static_cast<std::size_t>(k)];
    std::array<Vec3, 8> x;
    for (int c = 0; c < 8; ++c) x[c] = m.nodes[static_cast<std::size_t>(h[c])];
    EXPECT_GT(hex_volume(x), 0) << "element " << k;
    std::vector<std::int64_t> a(h.begin(), h.end()), o(before[k].begin(), before[k].end());
    std::sort(a.begin(), a.end());
    std::sort(o.begin(), o.end());
    EXPECT_EQ(a, o) << "element " << k;
    // zeta's edge (corner 0 to corner 4) has the element's thickness.
    const Vec3 d = x[4] - x[0];
    EXPECT_NEAR(std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z), 0.001, 1e-12) << "element " << k;
  }
  const auto& side = m.side_sets["xmin"][0];
  std::vector<std::int64_t> nodes;
  for (int c : hex_faces[static_cast<std::size_t>(side.face)])
    nodes.push_back(m.blocks[0].elements[0][static_cast<std::size_t>(c)]);
  std::sort(nodes.begin(), nodes.end());
  EXPECT_EQ(nodes, (std::vector<std::int64_t>{0, 3, 4, 7}));
}

// A wall one element thick of cubes (QA round 7): the three sizes of a cube tie, so the
// thickness is the direction whose two faces are on the wall's surface, whatever the
// round-off in the corners. Walls thin in x, y and z, at an offset that makes the corner
// coordinates inexact; every element's zeta edge must run through the thickness.
TEST(OrientThickness, AWallOfCubesTurnsByItsFaces) {
  for (int thin = 0; thin < 3; ++thin) {
    BoxSpec spec;
    spec.min = {0.0013, -0.0071, 0.0029};
    spec.max = spec.min;
    spec.divisions = {6, 6, 6};
    for (int i = 0; i < 3; ++i) spec.max[i] += i == thin ? 0.002 : 0.012;
    spec.divisions[static_cast<std::size_t>(thin)] = 1;
    Mesh m = generate_box(spec);
    orient_thickness_zeta(m, 0);
    int wrong = 0;
    for (const Hex& h : m.blocks[0].elements) {
      const Vec3 d =
          m.nodes[static_cast<std::size_t>(h[4])] - m.nodes[static_cast<std::size_t>(h[0])];
      wrong += std::abs(std::abs(d[thin]) - 0.002) > 1e-9 ? 1 : 0;
    }
    EXPECT_EQ(wrong, 0) << "wall thin in direction " << thin;
  }
}

} // namespace
