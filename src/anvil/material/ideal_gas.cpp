#include "anvil/material/ideal_gas.hpp"

#include <algorithm>
#include <cmath>

namespace anvil {

namespace {
constexpr ParamSpec gas_params[] = {
    {"density", "kg/m^3", true, 0, 0, 1e300, true, false, "initial mass density"},
    {"gamma", "-", false, 1.4, 1, 1e300, true, false, "ratio of specific heats"},
    {"specific_energy", "J/kg", true, 0, 0, 1e300, false, false,
     "initial specific internal energy"},
};

// The gas's stiffness: the adiabatic bulk modulus gamma p0, no shear.
ElasticConstants gas_constants(const ParamValues& p) {
  return ElasticConstants::no_shear(p.at("density"), p.at("gamma") * (p.at("gamma") - 1) *
                                                         p.at("density") * p.at("specific_energy"));
}
} // namespace

std::span<const ParamSpec> IdealGas::params() {
  return gas_params;
}

IdealGas::IdealGas(const ParamValues& p)
    : Material(gas_constants(p)), gamma_(p.at("gamma")), e0_(p.at("specific_energy")) {}

double IdealGas::initial_pressure() const {
  return (gamma_ - 1) * elastic().density * e0_;
}

void IdealGas::update(const MaterialBatch& b) const {
  const double g1 = gamma_ - 1;
#pragma omp simd
  for (int i = 0; i < b.n; ++i) {
    const double p = g1 * b.density[i] * std::max(b.energy[i], 0.0);
    for (int k = 0; k < 3; ++k) b.stress[k][i] = -p;
    for (int k = 3; k < 6; ++k) b.stress[k][i] = 0;
    b.wave_speed[i] = std::sqrt(gamma_ * p / b.density[i]);
  }
}

} // namespace anvil
