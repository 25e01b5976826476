// Constant-strain patch test on a distorted mesh (Flanagan and Belytschko 1981, section
// 4; the patch test of Irons): a linear velocity field v = L x imposed on every node of a
// mesh with randomly moved interior nodes must give every element the same rate of
// deformation sym(L), the same stress, no hourglass force, and zero net force on every
// interior node. Tolerances: round-off (1e-10 relative to the stress or to the force
// scale sigma h^2). The artificial bulk viscosity is off: it depends on each element's
// size by design (a shock-smearing term, not part of the element formulation), so on a
// distorted mesh it is not uniform under uniform compression. The same box cut into
// wedges and into tetrahedra (hexahedra whose nodes repeat) passes with the same
// tolerances.
#include <gtest/gtest.h>

#include <random>

#include "anvil/core/simd.hpp"
#include "anvil/mesh/generators.hpp"
#include "kernel_rig.hpp"

namespace {

using namespace anvil;

Mesh distorted_box(unsigned seed, Shape shape) {
  BoxSpec spec{{0, 0, 0}, {0.03, 0.03, 0.03}, {3, 3, 3}};
  spec.shape = shape;
  Mesh m = generate_box(spec);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.0025, 0.0025); // a quarter of the spacing
  for (auto& p : m.nodes) {
    const bool interior = p.x > 1e-9 && p.x < 0.03 - 1e-9 && p.y > 1e-9 && p.y < 0.03 - 1e-9 &&
                          p.z > 1e-9 && p.z < 0.03 - 1e-9;
    if (interior) p += Vec3{u(rng), u(rng), u(rng)};
  }
  return m;
}

bool interior(const Vec3& p) {
  auto in = [](double c) { return c > 1e-9 && c < 0.03 - 1e-9; };
  return in(p.x) && in(p.y) && in(p.z);
}

constexpr double L[3][3] = {{-40.0, 25.0, 5.0}, {-5.0, 10.0, 15.0}, {20.0, -30.0, -60.0}}; // 1/s
constexpr BulkViscosity no_bulk_viscosity{0.0, 0.0};

// The velocity gradient the element sees: the kernel differentiates v = L x(n) with
// respect to the mid-step positions x(n) - dt/2 v = (I - dt/2 L) x(n), which gives
// L (I - dt/2 L)^-1.
void midstep_gradient(double dt, double (&out)[3][3]) {
  double A[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) A[i][j] = (i == j) - 0.5 * dt * L[i][j];
  const double det = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
                     A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                     A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
  double inv[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
      inv[i][j] = (A[i1][j1] * A[i2][j2] - A[i1][j2] * A[i2][j1]) / det;
    }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      out[i][j] = L[i][0] * inv[0][j] + L[i][1] * inv[1][j] + L[i][2] * inv[2][j];
}

// The element forms: the three hourglass controls, and the thick shell (three points
// through the thickness, the assumed-strain form for its other modes).
struct Form {
  HourglassControl::Model hourglass;
  int thick_shell_points = 0;
  Shape shape = Shape::hexahedron; // wedges, tetrahedra: the box's cells cut
};

class Patch : public ::testing::TestWithParam<Form> {};

test::KernelRig rig_for(unsigned seed, const Form& f) {
  return test::KernelRig(distorted_box(seed, f.shape), "elastic", test::elastic_steel(),
                         {f.hourglass, 0.1}, no_bulk_viscosity, ThickShell{f.thick_shell_points});
}

TEST_P(Patch, LinearVelocityGivesUniformStressAndBalancedInteriorNodes) {
  test::KernelRig rig = rig_for(3, GetParam());
  const std::size_t nn = rig.fe.node_gid.size();
  for (std::size_t k = 0; k < nn; ++k)
    for (int i = 0; i < 3; ++i)
      rig.v[i][k] = L[i][0] * rig.x[0][k] + L[i][1] * rig.x[1][k] + L[i][2] * rig.x[2][k];
  const double dt = 1e-6;
  // x(n) and v(n-1/2) consistent: the mid-step configuration is x - dt/2 v.
  rig.forces(dt);

  const auto& mat = rig.material->elastic();
  double Lm[3][3];
  midstep_gradient(dt, Lm);
  const double D[6] = {Lm[0][0],
                       Lm[1][1],
                       Lm[2][2],
                       0.5 * (Lm[0][1] + Lm[1][0]),
                       0.5 * (Lm[1][2] + Lm[2][1]),
                       0.5 * (Lm[0][2] + Lm[2][0])};
  const double tr = (D[0] + D[1] + D[2]) * dt;
  double expected[6];
  for (int k = 0; k < 6; ++k)
    expected[k] = 2 * mat.shear * D[k] * dt + (k < 3 ? mat.lambda * tr : 0.0);
  double scale = 0;
  for (double s : expected) scale = std::max(scale, std::abs(s));
  for (int e = 0; e < rig.block.size(); ++e)
    for (int k = 0; k < 6; ++k)
      EXPECT_NEAR(rig.block.stress[k][e], expected[k], 1e-10 * scale)
          << "element " << e << " component " << k;

  const double force_scale = scale * 0.01 * 0.01; // sigma h^2
  int checked = 0;
  for (std::size_t k = 0; k < nn; ++k) {
    if (!interior(rig.mesh.nodes[rig.fe.node_gid[k]])) continue;
    ++checked;
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(rig.f[i][k], 0.0, 1e-10 * force_scale) << "node " << k;
  }
  EXPECT_EQ(checked, 8);
  // No hourglass work: the modes of a linear field vanish up to round-off.
  for (int e = 0; e < rig.block.size(); ++e)
    EXPECT_LE(std::abs(rig.block.hourglass_energy[e]),
              1e-12 * std::abs(rig.block.internal_energy[e]));
}

// The explicit patch test: boundary nodes driven along v = L X, interior nodes free and
// started on the same field, 200 cycles of central difference. The interior nodes must
// stay on the homogeneous deformation x = (I + t L) X and the stress stay uniform.
TEST_P(Patch, DrivenBoundaryCarriesInteriorAlongHomogeneousDeformation) {
  test::KernelRig rig = rig_for(5, GetParam());
  const std::size_t nn = rig.fe.node_gid.size();
  // Lumped nodal masses by the same exact gather the solver uses.
  std::vector<double> corner_mass(rig.fe.total_slots(), 0.0), mass(nn);
  for (int e = 0; e < rig.block.size(); ++e)
    for (int a = 0; a < 8; ++a)
      corner_mass[rig.fe.blocks[0].slot(static_cast<std::size_t>(e), a)] =
          rig.block.mass[e] * rig.block.corner_share(static_cast<std::size_t>(e), a);
  gather_corners(rig.fe, {corner_mass.data()}, {mass.data()});
  std::vector<Vec3> X(nn), V(nn);
  for (std::size_t k = 0; k < nn; ++k) {
    X[k] = rig.mesh.nodes[rig.fe.node_gid[k]];
    for (int i = 0; i < 3; ++i) V[k][i] = L[i][0] * X[k].x + L[i][1] * X[k].y + L[i][2] * X[k].z;
    for (int i = 0; i < 3; ++i) rig.v[i][k] = V[k][i];
  }
  const double dt = 2e-8;
  double t = 0, dt_prev = 0;
  for (int n = 0; n < 200; ++n) {
    rig.forces(dt_prev);
    const double dt_avg = 0.5 * (dt_prev + dt);
    for (std::size_t k = 0; k < nn; ++k) {
      const bool free = interior(X[k]);
      for (int i = 0; i < 3; ++i) {
        rig.v[i][k] = free ? rig.v[i][k] + dt_avg * rig.f[i][k] / mass[k] : V[k][i];
        rig.x[i][k] += dt * rig.v[i][k];
      }
    }
    t += dt;
    dt_prev = dt;
  }
  double err = 0;
  for (std::size_t k = 0; k < nn; ++k)
    for (int i = 0; i < 3; ++i)
      err = std::max(err, std::abs(rig.x[i][k] - (X[k][i] + t * V[k][i])));
  EXPECT_LT(err, 1e-12 * 0.03) << "interior nodes left the homogeneous deformation";
  for (int k = 0; k < 6; ++k) {
    double lo = 1e300, hi = -1e300;
    for (int e = 0; e < rig.block.size(); ++e) {
      lo = std::min(lo, rig.block.stress[k][e]);
      hi = std::max(hi, rig.block.stress[k][e]);
    }
    EXPECT_LE(hi - lo, 1e-10 * std::max(std::abs(hi), std::abs(lo))) << "component " << k;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Hourglass, Patch,
    ::testing::Values(Form{HourglassControl::Model::viscous},
                      Form{HourglassControl::Model::stiffness},
                      Form{HourglassControl::Model::assumed_strain},
                      Form{HourglassControl::Model::assumed_strain, 3},
                      Form{HourglassControl::Model::viscous, 0, Shape::wedge},
                      Form{HourglassControl::Model::stiffness, 0, Shape::wedge},
                      Form{HourglassControl::Model::viscous, 0, Shape::tetrahedron}));

} // namespace
