// The nodal assembly in the element kernel (HexWorkspace::begin_nodal_forces) against the
// gather of the corner slots: the same bits for every node, on meshes with nodes of any
// corner count, two blocks sharing nodes, and a partition with nodes shared between ranks.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "anvil/fe/hex_block.hpp"
#include "anvil/material/material.hpp"
#include "anvil/mesh/generators.hpp"
#include "anvil/parallel/fe_decomposition.hpp"

namespace {

using namespace anvil;

bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// A cylinder (an O-grid: nodes with 2, 3, 4, 6 and 8 corners) and a
// box on its end face as a second block, glued to it: the nodes of the box's bottom face
// are the cylinder's (both blocks add to them).
Mesh two_block_mesh() {
  Mesh m = generate_cylinder({.radius = 0.01, .length = 0.04, .axis = 2, .divisions = {3, 6}});
  Mesh box = generate_box({{-0.004, -0.004, 0.04}, {0.004, 0.004, 0.05}, {3, 3, 2}});
  m.append(box, "box");
  // Glue: every box node that lies on a cylinder node takes the cylinder node's id.
  const auto nc = static_cast<std::int64_t>(m.nodes.size() - box.nodes.size());
  for (auto& h : m.blocks[1].elements)
    for (auto& n : h)
      for (std::int64_t k = 0; k < nc; ++k) {
        const Vec3 d{m.nodes[n].x - m.nodes[k].x, m.nodes[n].y - m.nodes[k].y,
                     m.nodes[n].z - m.nodes[k].z};
        if (d.x * d.x + d.y * d.y + d.z * d.z < 1e-18) {
          n = k;
          break;
        }
      }
  return m;
}

struct Phase {
  std::vector<HexBlock> blocks;
  std::array<std::vector<double>, 3> f;
  std::array<CornerArray, 3> corner;
  HexWorkspace work;
};

// Two cycles of the FE phase on rank `rank` of `ranks` (elements dealt round-robin in
// runs of 24: nodes inside a rank and shared ones): the forces by the gather (assembly =
// false) or by the kernel's assembly.
Phase run(const Mesh& mesh, const Material& material, int rank, int ranks, bool assembly) {
  std::vector<int> owner(static_cast<std::size_t>(mesh.num_elements()));
  for (std::size_t e = 0; e < owner.size(); ++e) owner[e] = static_cast<int>(e / 24) % ranks;
  const FeDecomposition fe = decompose_fe(mesh, owner, rank, ranks);
  const std::size_t nn = fe.node_gid.size();
  std::array<std::vector<double>, 3> x, v;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 3; ++i) {
    x[i].resize(nn);
    v[i].resize(nn);
  }
  for (std::size_t k = 0; k < nn; ++k) {
    const Vec3 p = mesh.nodes[fe.node_gid[k]];
    x[0][k] = p.x;
    x[1][k] = p.y;
    x[2][k] = p.z;
  }
  // Velocities by global node id (the same on any partition), strong enough to yield.
  std::vector<double> vg(static_cast<std::size_t>(3 * mesh.num_nodes()));
  for (double& s : vg) s = 40.0 * u(rng);
  for (std::size_t k = 0; k < nn; ++k)
    for (int i = 0; i < 3; ++i) v[i][k] = vg[3 * static_cast<std::size_t>(fe.node_gid[k]) + i];
  Phase r;
  const double* xs[3] = {x[0].data(), x[1].data(), x[2].data()};
  for (const auto& lb : fe.blocks) {
    HexBlock b;
    b.material = &material;
    b.init(lb.gid, lb.conn, xs, lb.corner_base);
    if (assembly) b.corner_rows = lb.exchanged_vectors;
    r.blocks.push_back(std::move(b));
  }
  for (int i = 0; i < 3; ++i) {
    r.f[i].assign(nn, -1.0);
    r.corner[i].assign(fe.total_slots(), 0.0);
  }
  const NodalView nv{{x[0].data(), x[1].data(), x[2].data()},
                     {v[0].data(), v[1].data(), v[2].data()}};
  const CornerView cv{{r.corner[0].data(), r.corner[1].data(), r.corner[2].data()}};
  double* const fs[3] = {r.f[0].data(), r.f[1].data(), r.f[2].data()};
  for (double dt : {0.0, 1e-7}) {
    HexResult res;
    if (assembly) r.work.begin_nodal_forces(static_cast<int>(nn));
    for (auto& b : r.blocks)
      if (b.size() > 0) hex_forces(b, nv, dt, cv, r.work, res);
    if (assembly) {
      r.work.end_nodal_forces(fs);
      // Remote slots stay zero here: the listed nodes are summed as the gather does.
      gather_corners(fe, {r.corner[0].data(), r.corner[1].data(), r.corner[2].data()},
                     {fs[0], fs[1], fs[2]}, fe.exchanged_nodes);
    } else {
      gather_corners(fe, {r.corner[0].data(), r.corner[1].data(), r.corner[2].data()},
                     {fs[0], fs[1], fs[2]});
    }
  }
  return r;
}

TEST(NodalAssembly, SameBitsAsTheGather) {
  const Mesh mesh = two_block_mesh();
  ASSERT_EQ(mesh.blocks.size(), 2u);
  const auto material = find_material_model("j2_plasticity")
                            ->make({{"density", 7850},
                                    {"youngs_modulus", 200e9},
                                    {"poissons_ratio", 0.3},
                                    {"yield_stress", 250e6},
                                    {"hardening_modulus", 1e9}},
                                   {});
  for (int ranks : {1, 3})
    for (int rank = 0; rank < ranks; ++rank) {
      const Phase a = run(mesh, *material, rank, ranks, false);
      const Phase b = run(mesh, *material, rank, ranks, true);
      std::size_t nonzero = 0;
      for (int i = 0; i < 3; ++i)
        for (std::size_t k = 0; k < a.f[i].size(); ++k) {
          nonzero += a.f[i][k] != 0.0;
          EXPECT_TRUE(same_bits(a.f[i][k], b.f[i][k]))
              << "rank " << rank << " of " << ranks << ", node " << k << ", component " << i << ": "
              << a.f[i][k] << " vs " << b.f[i][k];
        }
      EXPECT_GT(nonzero, a.f[0].size()); // the forces are not trivially zero
    }
}

} // namespace
