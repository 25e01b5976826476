#include "anvil/material/mie_gruneisen.hpp"

#include <algorithm>

namespace anvil {

namespace {
constexpr ParamSpec mg_params[] = {
    {"c0", "m/s", true, 0, 0, 1e300, true, false, "bulk sound speed (Hugoniot intercept)"},
    {"s", "-", true, 0, 0, 1e300, false, false, "Hugoniot slope dUs/dup"},
    {"gamma0", "-", true, 0, 0, 1e300, false, false, "Gruneisen coefficient"},
};
} // namespace

std::span<const ParamSpec> MieGruneisen::params() {
  return mg_params;
}

MieGruneisen::MieGruneisen(const ParamValues& p)
    : c0_(p.at("c0")), s_(p.at("s")), gamma0_(p.at("gamma0")) {}

void MieGruneisen::pressure(int n, double rho0, const double* rho, const double* e, double* p,
                            double* c2) const {
  const double A = rho0 * c0_ * c0_, b = 1 - 0.5 * gamma0_, a = s_ - 1, g = gamma0_ * rho0;
#pragma omp simd
  for (int i = 0; i < n; ++i) {
    const double mu = rho[i] / rho0 - 1;
    // The Hugoniot's denominator vanishes at mu = 1/(s-1) (the limiting compression);
    // keep it away from zero so that a wild state gives a large, finite pressure.
    const double den = std::max(1 - a * std::max(mu, 0.0), 1e-3);
    const double comp = A * mu * (1 + b * mu) / (den * den);
    const double dcomp =
        A * ((1 + 2 * b * mu) * den + 2 * a * mu * (1 + b * mu)) / (den * den * den);
    const bool c = mu > 0;
    p[i] = (c ? comp : A * mu) + g * e[i];
    // dp/drho at constant e; the energy term's contribution (p gamma0 rho0 / rho^2) is
    // small and left out of the sound speed.
    c2[i] = std::max(c ? dcomp / rho0 : c0_ * c0_, 0.0);
  }
}

} // namespace anvil
