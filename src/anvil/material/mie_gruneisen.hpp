#pragma once

#include "anvil/material/material.hpp"

namespace anvil {

// Mie-Gruneisen equation of state on a linear shock Hugoniot Us = c0 + s up (as in
// Steinberg's and LS-DYNA's form without the quadratic terms), mu = rho/rho0 - 1:
//   compression (mu > 0): p = rho0 c0^2 mu (1 + (1 - gamma0/2) mu) / (1 - (s - 1) mu)^2
//                             + gamma0 rho0 e
//   tension     (mu <= 0): p = rho0 c0^2 mu + gamma0 rho0 e
// e is the specific internal energy (J/kg). Used with a strength model for strong shocks.
class MieGruneisen : public Eos {
public:
  explicit MieGruneisen(const ParamValues& p);
  void pressure(int n, double rho0, const double* rho, const double* e, double* p,
                double* c2) const override;
  static std::span<const ParamSpec> params();

private:
  double c0_, s_, gamma0_;
};

} // namespace anvil
