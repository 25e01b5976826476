#include "anvil/material/johnson_cook.hpp"

#include <algorithm>
#include <cmath>

namespace anvil {

namespace {
constexpr ParamSpec jc_params[] = {
    {"density", "kg/m^3", true, 0, 0, 1e300, true, false, "reference mass density"},
    {"youngs_modulus", "Pa", true, 0, 0, 1e300, true, false, "Young's modulus"},
    {"poissons_ratio", "-", true, 0, -1, 0.5, true, true, "Poisson's ratio"},
    {"A", "Pa", true, 0, 0, 1e300, true, false, "yield stress at zero plastic strain"},
    {"B", "Pa", true, 0, 0, 1e300, false, false, "hardening coefficient"},
    {"C", "-", false, 0, 0, 1e300, false, false, "strain-rate coefficient"},
    {"n", "-", true, 0, 0, 1e300, true, false, "hardening exponent"},
    {"m", "-", false, 1, 0, 1e300, true, false, "thermal softening exponent"},
    {"reference_strain_rate", "1/s", false, 1, 0, 1e300, true, false,
     "strain rate at which C has no effect"},
    {"room_temperature", "K", false, 293, 0, 1e300, true, false,
     "initial and reference temperature"},
    {"melt_temperature", "K", false, 0, 0, 1e300, true, false,
     "melting temperature (0: no thermal softening, no heating)"},
    {"specific_heat", "J/(kg K)", false, 0, 0, 1e300, true, false,
     "specific heat capacity (with melt_temperature)"},
    {"taylor_quinney", "-", false, 0.9, 0, 1, false, false,
     "fraction of plastic work converted to heat"},
    {"max_hardening_stress", "Pa", false, 0, 0, 1e300, false, false,
     "cap on A + B ep^n before the rate factor (0: none; LS-DYNA MAT_098 SIGMAX)"},
    {"saturation_stress", "Pa", false, 0, 0, 1e300, false, false,
     "cap on the flow stress (0: none; LS-DYNA MAT_098 SIGSAT)"},
};
} // namespace

std::span<const ParamSpec> JohnsonCook::params() {
  return jc_params;
}

JohnsonCook::JohnsonCook(const ParamValues& p)
    : Material(p), A_(p.at("A")), B_(p.at("B")), C_(p.at("C")), n_(p.at("n")), m_(p.at("m")),
      rate0_(p.at("reference_strain_rate")), room_(p.at("room_temperature")),
      melt_(p.at("melt_temperature")), cp_(p.at("specific_heat")), chi_(p.at("taylor_quinney")),
      sigmax_(p.at("max_hardening_stress")), sigsat_(p.at("saturation_stress")),
      thermal_(melt_ > 0) {}

double JohnsonCook::factor(double rate, double T) const {
  const double rate_factor = 1 + C_ * std::log(std::max(rate / rate0_, 1.0));
  if (!thermal_) return rate_factor;
  const double ts = std::clamp((T - room_) / (melt_ - room_), 0.0, 1.0);
  return rate_factor * (1 - std::pow(ts, m_));
}

double JohnsonCook::hardening(double ep) const {
  const double h = A_ + B_ * std::pow(std::max(ep, 0.0), n_);
  return sigmax_ > 0 ? std::min(h, sigmax_) : h;
}

double JohnsonCook::flow(double ep, double factor) const {
  const double y = hardening(ep) * factor;
  return sigsat_ > 0 ? std::min(y, sigsat_) : y;
}

double JohnsonCook::yield_stress(double ep, double rate, double T) const {
  return flow(ep, factor(rate, T));
}

void JohnsonCook::flow_stress(const MaterialBatch& b, double* out) const {
  for (int p = 0; p < b.n; ++p)
    out[p] = yield_stress(b.plastic_strain[p], equivalent_strain_rate(b, p),
                          thermal_ ? b.temperature[p] : room_);
}

void JohnsonCook::update(const MaterialBatch& b) const {
  const double G = elastic().shear, lam = elastic().lambda;
  const double M = elastic().plane_wave_modulus();
  const double dt = b.dt;
  for (int p = 0; p < b.n; ++p) {
    double s[6];
    const double* d[6] = {b.d[0] + p, b.d[1] + p, b.d[2] + p, b.d[3] + p, b.d[4] + p, b.d[5] + p};
    const double tr = (*d[0] + *d[1] + *d[2]) * dt;
    for (int k = 0; k < 3; ++k) s[k] = b.stress[k][p] + lam * tr + 2 * G * *d[k] * dt;
    for (int k = 3; k < 6; ++k) s[k] = b.stress[k][p] + 2 * G * *d[k] * dt;
    const double mean = (s[0] + s[1] + s[2]) * (1.0 / 3.0);
    double dev[6] = {s[0] - mean, s[1] - mean, s[2] - mean, s[3], s[4], s[5]};
    const double j2 = 0.5 * (dev[0] * dev[0] + dev[1] * dev[1] + dev[2] * dev[2]) +
                      dev[3] * dev[3] + dev[4] * dev[4] + dev[5] * dev[5];
    const double q = std::sqrt(3.0 * j2);
    const double rate = equivalent_strain_rate(b, p);
    const double ep = b.plastic_strain[p];
    const double T = thermal_ ? b.temperature[p] : room_;
    const double f = factor(rate, T);
    double dgamma = 0;
    if (q > flow(ep, f)) {
      // Solve g(x) = q - 3 G x - sigma_y(ep + x) = 0. g decreases; g(0) > 0 and, since
      // hardening only raises sigma_y, g < 0 at the perfectly plastic increment
      // (q - sigma_y(ep)) / 3G, which brackets the root and is a good start (the slope of
      // ep^n is infinite at ep = 0, on the other side). Newton steps that leave the bracket
      // are replaced by bisection; converged when g is at round-off level of q. Where a
      // cap holds the flow stress (max_hardening_stress, saturation_stress) its slope is 0.
      double lo = 0, hi = (q - flow(ep, f)) / (3 * G), x = hi;
      for (int it = 0; it < 100; ++it) {
        const double e = std::max(ep + x, 1e-300);
        const double y = flow(e, f);
        const double g = q - 3 * G * x - y;
        if (std::abs(g) <= 1e-14 * q || hi - lo <= 1e-16 * hi) break;
        if (g > 0)
          lo = x;
        else
          hi = x;
        const bool capped =
            (sigmax_ > 0 && A_ + B_ * std::pow(e, n_) >= sigmax_) || (sigsat_ > 0 && y >= sigsat_);
        const double slope = capped ? -3 * G : -3 * G - B_ * n_ * std::pow(e, n_ - 1) * f;
        double next = x - g / slope;
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
        x = next;
      }
      dgamma = x;
      const double scale = 1 - 3 * G * dgamma / q;
      for (double& c : dev) c *= scale;
      if (thermal_)
        b.temperature[p] = T + chi_ * flow(ep + dgamma, f) * dgamma / (b.density[p] * cp_);
    }
    b.stress[0][p] = mean + dev[0];
    b.stress[1][p] = mean + dev[1];
    b.stress[2][p] = mean + dev[2];
    for (int k = 3; k < 6; ++k) b.stress[k][p] = dev[k];
    b.plastic_strain[p] = ep + dgamma;
    b.wave_speed[p] = std::sqrt(M / b.density[p]);
  }
}

} // namespace anvil
