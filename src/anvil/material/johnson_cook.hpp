#pragma once

#include "anvil/material/material.hpp"

namespace anvil {

// Johnson-Cook viscoplasticity: sigma_y = (A + B ep^n)(1 + C ln(max(rate/rate0, 1)))
// (1 - T*^m), T* = (T - T_room)/(T_melt - T_room) clipped to [0, 1]; rate is the
// equivalent total strain rate of the step; radial return solved by safeguarded Newton
// on the plastic increment with the rate and thermal factors frozen over the step;
// adiabatic heating dT = taylor_quinney * sigma_y * dep / (density * specific_heat).
// Without melt_temperature, no thermal term and no temperature (LS-DYNA's simplified
// Johnson-Cook, MAT_098); max_hardening_stress caps A + B ep^n, saturation_stress the
// flow stress (MAT_098's SIGMAX and SIGSAT).
class JohnsonCook : public Material {
public:
  explicit JohnsonCook(const ParamValues& p);
  void update(const MaterialBatch& b) const override;
  bool has_plastic_strain() const override { return true; }
  void flow_stress(const MaterialBatch& b, double* out) const override;
  bool has_temperature() const override { return thermal_; }
  double initial_temperature() const override { return thermal_ ? room_ : 0.0; }
  static std::span<const ParamSpec> params();

  // Yield stress at the given state (exposed for tests).
  double yield_stress(double plastic_strain, double strain_rate, double temperature) const;

private:
  double factor(double rate, double T) const;  // the rate and thermal factors
  double hardening(double ep) const;           // A + B ep^n, capped by max_hardening_stress
  double flow(double ep, double factor) const; // times the factors, capped by saturation
  double A_, B_, C_, n_, m_, rate0_, room_, melt_, cp_, chi_, sigmax_, sigsat_;
  bool thermal_;
};

} // namespace anvil
