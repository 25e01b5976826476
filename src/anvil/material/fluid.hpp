#pragma once

#include "anvil/material/material.hpp"

namespace anvil {

// A fluid (no strength; LS-DYNA's *MAT_NULL): the deviatoric stress is the Newtonian
// viscous stress 2 mu D', the pressure advances with the bulk modulus K (the mean stress
// by K tr(D) dt, as the elastic solid's), or comes from an equation of state that
// replaces it (`eos:`, which a liquid at impact wants). Wave speed sqrt(K / rho). No
// pressure cutoff: the fluid carries tension. Particles only (the deck readers refuse it
// on hexahedra, whose hourglass control needs a shear stiffness).
class Fluid : public Material {
public:
  explicit Fluid(const ParamValues& p);
  void update(const MaterialBatch& b) const override;
  static std::span<const ParamSpec> params();

private:
  double viscosity_;
};

} // namespace anvil
