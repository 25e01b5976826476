#include "anvil/material/fluid.hpp"

#include <cmath>

namespace anvil {

namespace {
constexpr ParamSpec fluid_params[] = {
    {"density", "kg/m^3", true, 0, 0, 1e300, true, false, "reference mass density"},
    {"bulk_modulus", "Pa", true, 0, 0, 1e300, true, false,
     "bulk modulus K (rho c^2 of the sound speed c)"},
    {"viscosity", "Pa s", false, 0, 0, 1e300, false, false, "dynamic viscosity mu"},
};

} // namespace

std::span<const ParamSpec> Fluid::params() {
  return fluid_params;
}

Fluid::Fluid(const ParamValues& p)
    : Material(ElasticConstants::no_shear(p.at("density"), p.at("bulk_modulus"))),
      viscosity_(p.at("viscosity")) {}

void Fluid::update(const MaterialBatch& b) const {
  const double K = elastic().bulk, mu2 = 2 * viscosity_, dt = b.dt;
#pragma omp simd
  for (int p = 0; p < b.n; ++p) {
    const double trace = b.d[0][p] + b.d[1][p] + b.d[2][p];
    const double mean =
        (b.stress[0][p] + b.stress[1][p] + b.stress[2][p]) * (1.0 / 3.0) + K * trace * dt;
    for (int k = 0; k < 3; ++k) b.stress[k][p] = mean + mu2 * (b.d[k][p] - trace * (1.0 / 3.0));
    for (int k = 3; k < 6; ++k) b.stress[k][p] = mu2 * b.d[k][p];
    b.wave_speed[p] = std::sqrt(K / b.density[p]);
  }
}

} // namespace anvil
