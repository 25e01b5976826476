#pragma once

#include "anvil/material/material.hpp"

namespace anvil {

// Ideal gas (no strength): sigma = -p I, p = (gamma - 1) rho e, sound speed
// sqrt(gamma p / rho). `specific_energy` is the initial e; the density parameter the
// initial density. Needs the caller to track e (particles do; the hexahedra do not).
class IdealGas : public Material {
public:
  explicit IdealGas(const ParamValues& p);
  void update(const MaterialBatch& b) const override;
  bool needs_energy() const override { return true; }
  double initial_energy() const override { return e0_; }
  double initial_pressure() const override;
  static std::span<const ParamSpec> params();

private:
  double gamma_, e0_;
};

} // namespace anvil
