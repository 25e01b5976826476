#include "anvil/material/j2_plasticity.hpp"

#include <cmath>

namespace anvil {

namespace {
constexpr ParamSpec j2_params[] = {
    {"density", "kg/m^3", true, 0, 0, 1e300, true, false, "reference mass density"},
    {"youngs_modulus", "Pa", true, 0, 0, 1e300, true, false, "Young's modulus"},
    {"poissons_ratio", "-", true, 0, -1, 0.5, true, true, "Poisson's ratio"},
    {"yield_stress", "Pa", true, 0, 0, 1e300, true, false, "initial yield stress"},
    {"hardening_modulus", "Pa", false, 0, 0, 1e300, false, false,
     "slope of yield stress against plastic strain"},
};
} // namespace

std::span<const ParamSpec> J2Plasticity::params() {
  return j2_params;
}

J2Plasticity::J2Plasticity(const ParamValues& p)
    : Material(p), yield_(p.at("yield_stress")), hardening_(p.at("hardening_modulus")) {}

void J2Plasticity::update(const MaterialBatch& b) const {
  const double G = elastic().shear, lam = elastic().lambda;
  const double M = elastic().plane_wave_modulus();
  const double dt = b.dt, H = hardening_, Y0 = yield_;
#pragma omp simd
  for (int p = 0; p < b.n; ++p) {
    double s[6];
    const double tr = (b.d[0][p] + b.d[1][p] + b.d[2][p]) * dt;
    for (int k = 0; k < 3; ++k) s[k] = b.stress[k][p] + lam * tr + 2 * G * b.d[k][p] * dt;
    for (int k = 3; k < 6; ++k) s[k] = b.stress[k][p] + 2 * G * b.d[k][p] * dt;
    const double mean = (s[0] + s[1] + s[2]) * (1.0 / 3.0);
    const double d0 = s[0] - mean, d1 = s[1] - mean, d2 = s[2] - mean;
    const double j2 = 0.5 * (d0 * d0 + d1 * d1 + d2 * d2) + s[3] * s[3] + s[4] * s[4] + s[5] * s[5];
    const double q = std::sqrt(3.0 * j2); // von Mises stress of the trial state
    const double ep = b.plastic_strain[p];
    const double f = q - (Y0 + H * ep);
    // Radial return: the deviator shrinks by (1 - 3 G dgamma / q).
    const double dgamma = f > 0 ? f / (3 * G + H) : 0.0;
    const double scale = f > 0 ? 1.0 - 3 * G * dgamma / q : 1.0;
    b.stress[0][p] = mean + d0 * scale;
    b.stress[1][p] = mean + d1 * scale;
    b.stress[2][p] = mean + d2 * scale;
    for (int k = 3; k < 6; ++k) b.stress[k][p] = s[k] * scale;
    b.plastic_strain[p] = ep + dgamma;
    b.wave_speed[p] = std::sqrt(M / b.density[p]);
  }
}

} // namespace anvil
