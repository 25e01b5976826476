// A single-rank element-kernel rig for verification tests that prescribe the motion of
// every node: a mesh, one block with a material, nodal arrays, and a call that runs the
// FE phase (kernel + exact gather) for given positions and velocities.
#pragma once

#include <memory>

#include "anvil/fe/hex_block.hpp"
#include "anvil/material/material.hpp"
#include "anvil/mesh/mesh.hpp"
#include "anvil/parallel/fe_decomposition.hpp"

namespace anvil::test {

struct KernelRig {
  Mesh mesh;
  FeDecomposition fe;
  std::unique_ptr<Material> material;
  HexBlock block;
  std::array<std::vector<double>, 3> x, v, f;
  std::array<CornerArray, 3> corner;
  HexWorkspace work;
  HexResult result;

  KernelRig(Mesh m, const std::string& model, const ParamValues& params,
            HourglassControl hourglass = {}, BulkViscosity bulk = {}, ThickShell shell = {})
      : mesh(std::move(m)) {
    fe = decompose_fe(mesh, std::vector<int>(static_cast<std::size_t>(mesh.num_elements()), 0), 0,
                      1);
    material = find_material_model(model)->make(params, {});
    block.material = material.get();
    block.hourglass = hourglass;
    block.bulk_viscosity = bulk;
    block.thick_shell = shell;
    const std::size_t nn = fe.node_gid.size();
    for (int i = 0; i < 3; ++i) {
      x[i].resize(nn);
      v[i].assign(nn, 0.0);
      f[i].assign(nn, 0.0);
      corner[i].assign(fe.total_slots(), 0.0);
    }
    for (std::size_t k = 0; k < nn; ++k)
      for (int i = 0; i < 3; ++i) x[i][k] = mesh.nodes[fe.node_gid[k]][i];
    const double* xs[3] = {x[0].data(), x[1].data(), x[2].data()};
    block.init(fe.blocks[0].gid, fe.blocks[0].conn, xs, 0);
  }

  // The FE phase at the current x (t(n)) and v (t(n-1/2)) over dt_prev.
  void forces(double dt_prev) {
    const NodalView nv{{x[0].data(), x[1].data(), x[2].data()},
                       {v[0].data(), v[1].data(), v[2].data()}};
    const CornerView cv{{corner[0].data(), corner[1].data(), corner[2].data()}};
    result = HexResult{};
    hex_forces(block, nv, dt_prev, cv, work, result);
    gather_corners(fe, {corner[0].data(), corner[1].data(), corner[2].data()},
                   {f[0].data(), f[1].data(), f[2].data()});
  }
};

// Steel-like elastic parameters.
inline ParamValues elastic_steel() {
  return {{"density", 7850}, {"youngs_modulus", 200e9}, {"poissons_ratio", 0.3}};
}

} // namespace anvil::test
