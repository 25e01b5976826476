#pragma once

#include "anvil/material/material.hpp"

namespace anvil {

// Von Mises plasticity with linear isotropic hardening, sigma_y = yield_stress +
// hardening_modulus * plastic strain, integrated by radial return (exact for linear
// hardening: one step, no iteration).
class J2Plasticity : public Material {
public:
  explicit J2Plasticity(const ParamValues& p);
  void update(const MaterialBatch& b) const override;
  bool has_plastic_strain() const override { return true; }
  void flow_stress(const MaterialBatch& b, double* out) const override;
  static std::span<const ParamSpec> params();

private:
  double yield_ = 0, hardening_ = 0;
};

} // namespace anvil
