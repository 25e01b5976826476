#include "anvil/material/piecewise_linear_plasticity.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace anvil {

namespace {
constexpr ParamSpec plp_params[] = {
    {"density", "kg/m^3", true, 0, 0, 1e300, true, false, "reference mass density"},
    {"youngs_modulus", "Pa", true, 0, 0, 1e300, true, false, "Young's modulus"},
    {"poissons_ratio", "-", true, 0, -1, 0.5, true, true, "Poisson's ratio"},
    {"yield_stress", "Pa", false, 0, 0, 1e300, true, false,
     "initial yield stress of the bilinear form (instead of hardening_curve)"},
    {"hardening_modulus", "Pa", false, 0, 0, 1e300, false, false,
     "slope of yield stress against plastic strain, bilinear form"},
    {"cowper_symonds_C", "1/s", false, 0, 0, 1e300, false, false,
     "Cowper-Symonds rate constant C (0: no rate effect)"},
    {"cowper_symonds_p", "-", false, 0, 0, 1e300, false, false, "Cowper-Symonds exponent p"},
};
constexpr TableSpec plp_tables[] = {
    {"hardening_curve", "plastic strain", "-", "yield stress", "Pa",
     "yield stress against equivalent plastic strain, [[0, sigma_0], [ep_1, sigma_1], ...]"},
};
} // namespace

std::span<const ParamSpec> PiecewiseLinearPlasticity::params() {
  return plp_params;
}

std::span<const TableSpec> PiecewiseLinearPlasticity::tables() {
  return plp_tables;
}

ParamProblem PiecewiseLinearPlasticity::check(const ParamValues& p, const TableValues& t) {
  const auto curve = t.find("hardening_curve");
  const bool bilinear = p.at("yield_stress") > 0;
  if (curve == t.end() && !bilinear)
    return {"yield_stress", "give yield_stress (with hardening_modulus) or hardening_curve"};
  if (curve != t.end()) {
    if (bilinear)
      return {"yield_stress", "give either yield_stress (with hardening_modulus) or "
                              "hardening_curve, not both: the curve holds the initial yield"};
    if (p.at("hardening_modulus") > 0)
      return {"hardening_modulus", "hardening_modulus is the bilinear form's slope; with "
                                   "hardening_curve the curve's segments are the slopes"};
    const ParamTable& c = curve->second;
    if (c.x.empty() || c.x.front() != 0)
      return {"hardening_curve",
              fmt::format("the curve must start at plastic strain 0 (the initial yield), "
                          "not {}",
                          c.x.empty() ? 0.0 : c.x.front())};
    for (std::size_t i = 0; i < c.y.size(); ++i) {
      const int at = static_cast<int>(i);
      if (!(c.y[i] > 0) || !std::isfinite(c.y[i]))
        return {"hardening_curve",
                fmt::format("yield stress {} at plastic strain {} must be a finite number > 0",
                            c.y[i], c.x[i]),
                at};
      if (i > 0 && c.y[i] < c.y[i - 1])
        return {"hardening_curve",
                fmt::format("the yield stress falls from {} to {} at plastic strain {}: "
                            "softening curves are not supported (the radial return needs a "
                            "yield stress that does not fall)",
                            c.y[i - 1], c.y[i], c.x[i]),
                at};
      // The slope of the segment to this point (QA round 27: strains 1e-320 apart made it
      // infinite, the yield stress at 0 became inf * 0 = NaN, and nothing ever yielded).
      if (i > 0 && !std::isfinite((c.y[i] - c.y[i - 1]) / (c.x[i] - c.x[i - 1])))
        return {"hardening_curve",
                fmt::format("the slope from plastic strain {} to {} is not a finite number: "
                            "the points are too close or the stresses too large",
                            c.x[i - 1], c.x[i]),
                at};
    }
  }
  // C = 0: no rate effect, whatever p says (LS-DYNA's SRC, C: "if zero, rate effects are
  // not considered"); C > 0 needs its exponent.
  if (p.at("cowper_symonds_C") > 0 && !(p.at("cowper_symonds_p") > 0))
    return {"cowper_symonds_p", "the Cowper-Symonds law needs its exponent p (> 0) with C > 0"};
  return {};
}

PiecewiseLinearPlasticity::PiecewiseLinearPlasticity(const ParamValues& p, const TableValues& t)
    : Material(p) {
  if (const auto curve = t.find("hardening_curve"); curve != t.end()) {
    x_ = curve->second.x;
    y_ = curve->second.y;
    for (std::size_t i = 0; i + 1 < x_.size(); ++i)
      slope_.push_back((y_[i + 1] - y_[i]) / (x_[i + 1] - x_[i]));
    slope_.push_back(slope_.empty() ? 0.0 : slope_.back()); // extended with the last slope
  } else {
    x_ = {0.0};
    y_ = {p.at("yield_stress")};
    slope_ = {p.at("hardening_modulus")};
  }
  C_ = p.at("cowper_symonds_C");
  if (C_ > 0) inverse_p_ = 1 / p.at("cowper_symonds_p");
}

int PiecewiseLinearPlasticity::segment(double ep) const {
  // The last point at or below ep (ep >= 0 = x_[0]).
  const auto k = std::upper_bound(x_.begin() + 1, x_.end(), ep) - x_.begin() - 1;
  return static_cast<int>(k);
}

double PiecewiseLinearPlasticity::static_yield(double ep) const {
  const int k = segment(ep);
  return y_[k] + slope_[k] * (ep - x_[k]);
}

double PiecewiseLinearPlasticity::rate_factor(double rate) const {
  return C_ > 0 ? 1 + std::pow(rate / C_, inverse_p_) : 1.0;
}

void PiecewiseLinearPlasticity::flow_stress(const MaterialBatch& b, double* out) const {
  for (int p = 0; p < b.n; ++p)
    out[p] = rate_factor(equivalent_strain_rate(b, p)) * static_yield(b.plastic_strain[p]);
}

void PiecewiseLinearPlasticity::update(const MaterialBatch& b) const {
  const double G = elastic().shear, lam = elastic().lambda;
  const double M = elastic().plane_wave_modulus();
  const double dt = b.dt;
  const int last = static_cast<int>(x_.size()) - 1;
  for (int p = 0; p < b.n; ++p) {
    double s[6];
    const double tr = (b.d[0][p] + b.d[1][p] + b.d[2][p]) * dt;
    for (int k = 0; k < 3; ++k) s[k] = b.stress[k][p] + lam * tr + 2 * G * b.d[k][p] * dt;
    for (int k = 3; k < 6; ++k) s[k] = b.stress[k][p] + 2 * G * b.d[k][p] * dt;
    const double mean = (s[0] + s[1] + s[2]) * (1.0 / 3.0);
    double dev[6] = {s[0] - mean, s[1] - mean, s[2] - mean, s[3], s[4], s[5]};
    const double j2 = 0.5 * (dev[0] * dev[0] + dev[1] * dev[1] + dev[2] * dev[2]) +
                      dev[3] * dev[3] + dev[4] * dev[4] + dev[5] * dev[5];
    const double q = std::sqrt(3.0 * j2); // von Mises stress of the trial state
    const double ep = b.plastic_strain[p];
    const double R = C_ > 0 ? rate_factor(equivalent_strain_rate(b, p)) : 1.0;
    int k = segment(ep);
    double dgamma = 0;
    if (q > R * (y_[k] + slope_[k] * (ep - x_[k]))) {
      // q - 3 G dgamma = R sigma(ep + dgamma) on segment k's line; the left side falls
      // and the right side does not, so the root lies on the first segment whose line
      // puts it before the segment's end.
      for (;;) {
        dgamma = (q - R * (y_[k] + slope_[k] * (ep - x_[k]))) / (3 * G + R * slope_[k]);
        if (k == last || ep + dgamma <= x_[k + 1]) break;
        ++k;
      }
      const double scale = 1 - 3 * G * dgamma / q;
      for (double& c : dev) c *= scale;
    }
    b.stress[0][p] = mean + dev[0];
    b.stress[1][p] = mean + dev[1];
    b.stress[2][p] = mean + dev[2];
    for (int c = 3; c < 6; ++c) b.stress[c][p] = dev[c];
    b.plastic_strain[p] = ep + dgamma;
    b.wave_speed[p] = std::sqrt(M / b.density[p]);
  }
}

} // namespace anvil
