#include "anvil/material/elastic.hpp"

#include <cmath>
#include <limits>

#include <fmt/format.h>

namespace anvil {

namespace {
constexpr ParamSpec elastic_params[] = {
    {"density", "kg/m^3", true, 0, 0, 1e300, true, false, "reference mass density"},
    {"youngs_modulus", "Pa", true, 0, 0, 1e300, true, false, "Young's modulus"},
    {"poissons_ratio", "-", true, 0, -1, 0.5, true, true, "Poisson's ratio"},
};
} // namespace

ElasticConstants ElasticConstants::from(const ParamValues& p) {
  ElasticConstants c;
  c.density = p.at("density");
  c.youngs_modulus = p.at("youngs_modulus");
  c.poissons_ratio = p.at("poissons_ratio");
  const double E = c.youngs_modulus, nu = c.poissons_ratio;
  c.shear = E / (2 * (1 + nu));
  c.bulk = E / (3 * (1 - 2 * nu));
  c.lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
  return c;
}

ElasticConstants ElasticConstants::no_shear(double density, double bulk) {
  ElasticConstants c;
  c.density = density;
  c.bulk = bulk;
  c.lambda = bulk;
  c.shear = 0;
  c.youngs_modulus = 0;
  c.poissons_ratio = 0.5;
  return c;
}

std::string elastic_wave_problem(const ParamValues& p) {
  const ElasticConstants c = ElasticConstants::from(p);
  const double speed = std::sqrt(c.plane_wave_modulus() / c.density);
  if (std::isfinite(speed) && speed > 0 && c.density >= std::numeric_limits<double>::min())
    return {};
  return fmt::format("density {} and youngs_modulus {} give a wave speed of {} m/s, which the "
                     "time step cannot use (check their units)",
                     c.density, c.youngs_modulus, speed);
}

std::span<const ParamSpec> Elastic::params() {
  return elastic_params;
}

void Elastic::update(const MaterialBatch& b) const {
  const double G2 = 2 * elastic().shear, lam = elastic().lambda;
  const double M = elastic().plane_wave_modulus();
  const double dt = b.dt;
#pragma omp simd
  for (int p = 0; p < b.n; ++p) {
    const double tr = (b.d[0][p] + b.d[1][p] + b.d[2][p]) * dt;
    for (int k = 0; k < 3; ++k) b.stress[k][p] += lam * tr + G2 * b.d[k][p] * dt;
    for (int k = 3; k < 6; ++k) b.stress[k][p] += G2 * b.d[k][p] * dt;
    b.wave_speed[p] = std::sqrt(M / b.density[p]);
  }
}

} // namespace anvil
