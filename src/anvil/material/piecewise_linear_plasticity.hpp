#pragma once

#include <vector>

#include "anvil/material/material.hpp"

namespace anvil {

// Von Mises plasticity with isotropic hardening given point by point, LS-DYNA's
// *MAT_PIECEWISE_LINEAR_PLASTICITY (MAT_024): the yield stress is a piecewise linear
// function of the equivalent plastic strain, `hardening_curve` [[0, sigma_0], [ep_1,
// sigma_1], ...] extended past its last point with its last slope (or the bilinear
// `yield_stress` + `hardening_modulus` ep), scaled by the Cowper-Symonds factor
// 1 + (rate / C)^(1/p) of the step's equivalent strain rate. Radial return, exact for
// the piecewise linear curve: the plastic increment is solved on the segment where it
// ends, found by walking the segments from the point's current one (the rate factor
// frozen over the step, as in LS-DYNA's VP = 0).
class PiecewiseLinearPlasticity : public Material {
public:
  PiecewiseLinearPlasticity(const ParamValues& p, const TableValues& t);
  void update(const MaterialBatch& b) const override;
  bool has_plastic_strain() const override { return true; }
  void flow_stress(const MaterialBatch& b, double* out) const override;
  static std::span<const ParamSpec> params();
  static std::span<const TableSpec> tables();
  static ParamProblem check(const ParamValues& p, const TableValues& t);

  // The static yield stress at a plastic strain, and the rate factor at an equivalent
  // strain rate (exposed for tests).
  double static_yield(double plastic_strain) const;
  double rate_factor(double strain_rate) const;

private:
  int segment(double plastic_strain) const;
  // The curve's points and the slope after each (the last one's: the extension).
  std::vector<double> x_, y_, slope_;
  double C_ = 0, inverse_p_ = 0; // C = 0: no rate effect
};

} // namespace anvil
