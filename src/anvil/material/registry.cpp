#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <type_traits>
#include <vector>

#include <fmt/format.h>

#include "anvil/material/elastic.hpp"
#include "anvil/material/fluid.hpp"
#include "anvil/material/ideal_gas.hpp"
#include "anvil/material/j2_plasticity.hpp"
#include "anvil/material/johnson_cook.hpp"
#include "anvil/material/mie_gruneisen.hpp"
#include "anvil/material/piecewise_linear_plasticity.hpp"

namespace anvil {

namespace {
template <class M>
std::unique_ptr<Material> make(const ParamValues& p, const TableValues& t) {
  if constexpr (std::is_constructible_v<M, const ParamValues&, const TableValues&>)
    return std::make_unique<M>(p, t);
  else
    return std::make_unique<M>(p);
}

ParamProblem johnson_cook_check(const ParamValues& p, const TableValues&) {
  if (p.at("melt_temperature") == 0) {
    if (p.at("specific_heat") > 0)
      return {"specific_heat", "specific_heat is used with melt_temperature (the thermal "
                               "softening and heating): give both, or neither"};
    return {};
  }
  if (!(p.at("melt_temperature") > p.at("room_temperature")))
    return {"melt_temperature", fmt::format("melt_temperature {} must exceed room_temperature {}",
                                            p.at("melt_temperature"), p.at("room_temperature"))};
  if (!(p.at("specific_heat") > 0))
    return {"specific_heat", "specific_heat is required with melt_temperature (the adiabatic "
                             "heating)"};
  return {};
}
template <class E>
std::unique_ptr<Eos> make_eos(const ParamValues& p) {
  return std::make_unique<E>(p);
}

const std::array<MaterialModel, 6>& models() {
  static const std::array<MaterialModel, 6> list = {{
      {"elastic", Elastic::params(), {}, &make<Elastic>, "hypoelastic isotropic solid"},
      {"j2_plasticity",
       J2Plasticity::params(),
       {},
       &make<J2Plasticity>,
       "von Mises plasticity, linear isotropic hardening"},
      {"piecewise_linear_plasticity", PiecewiseLinearPlasticity::params(),
       PiecewiseLinearPlasticity::tables(), &make<PiecewiseLinearPlasticity>,
       "von Mises plasticity, tabulated hardening, Cowper-Symonds rate (LS-DYNA MAT_024)",
       &PiecewiseLinearPlasticity::check},
      {"johnson_cook",
       JohnsonCook::params(),
       {},
       &make<JohnsonCook>,
       "Johnson-Cook viscoplasticity with adiabatic heating",
       &johnson_cook_check},
      {"ideal_gas",
       IdealGas::params(),
       {},
       &make<IdealGas>,
       "ideal gas p = (gamma - 1) rho e (particles only)"},
      {"fluid",
       Fluid::params(),
       {},
       &make<Fluid>,
       "fluid: Newtonian viscosity, pressure from K or an equation of state (particles only; "
       "LS-DYNA MAT_NULL)"},
  }};
  return list;
}

const std::array<EosModel, 1>& eoses() {
  static const std::array<EosModel, 1> list = {{
      {"mie_gruneisen", MieGruneisen::params(), &make_eos<MieGruneisen>,
       "Mie-Gruneisen on a linear Us-up Hugoniot"},
  }};
  return list;
}

// A strength model whose pressure an equation of state replaces: the strength model
// advances the deviator (its yield test sees only the deviator), then the mean stress is
// set to -p(rho, e) and the wave speed to sqrt(c_bulk^2 + 4 G / (3 rho)). Scratch is
// per call (small, on the stack in chunks) so the object stays immutable and shareable.
class WithEos : public Material {
public:
  WithEos(std::unique_ptr<Material> strength, std::unique_ptr<Eos> eos)
      : Material(strength->elastic()), strength_(std::move(strength)), eos_(std::move(eos)) {}
  void update(const MaterialBatch& b) const override {
    strength_->update(b);
    constexpr int chunk = 64;
    double p[chunk], c2[chunk];
    const double rho0 = elastic().density, G43 = 4.0 / 3.0 * elastic().shear;
    for (int i0 = 0; i0 < b.n; i0 += chunk) {
      const int m = std::min(chunk, b.n - i0);
      eos_->pressure(m, rho0, b.density + i0, b.energy + i0, p, c2);
      for (int i = 0; i < m; ++i) {
        const int k = i0 + i;
        const double mean = (b.stress[0][k] + b.stress[1][k] + b.stress[2][k]) * (1.0 / 3.0);
        for (int d = 0; d < 3; ++d) b.stress[d][k] += -p[i] - mean;
        b.wave_speed[k] = std::sqrt(c2[i] + G43 / b.density[k]);
      }
    }
  }
  bool has_plastic_strain() const override { return strength_->has_plastic_strain(); }
  void flow_stress(const MaterialBatch& b, double* out) const override {
    strength_->flow_stress(b, out);
  }
  bool has_temperature() const override { return strength_->has_temperature(); }
  double initial_temperature() const override { return strength_->initial_temperature(); }
  bool needs_energy() const override { return true; }

private:
  std::unique_ptr<Material> strength_;
  std::unique_ptr<Eos> eos_;
};
} // namespace

double equivalent_strain_rate(const MaterialBatch& b, int p) {
  const double d[6] = {b.d[0][p], b.d[1][p], b.d[2][p], b.d[3][p], b.d[4][p], b.d[5][p]};
  const double dm = (d[0] + d[1] + d[2]) / 3;
  const double dd = (d[0] - dm) * (d[0] - dm) + (d[1] - dm) * (d[1] - dm) +
                    (d[2] - dm) * (d[2] - dm) + 2 * (d[3] * d[3] + d[4] * d[4] + d[5] * d[5]);
  return std::sqrt(2.0 / 3.0 * dd);
}

void Material::flow_stress(const MaterialBatch& b, double* out) const {
  std::fill(out, out + b.n, std::numeric_limits<double>::infinity());
}

std::span<const MaterialModel> material_models() {
  return models();
}

const MaterialModel* find_material_model(std::string_view name) {
  for (const auto& m : models())
    if (m.name == name) return &m;
  return nullptr;
}

std::span<const EosModel> eos_models() {
  return eoses();
}

const EosModel* find_eos_model(std::string_view name) {
  for (const auto& m : eoses())
    if (m.name == name) return &m;
  return nullptr;
}

std::unique_ptr<Material> make_material(std::string_view model, const ParamValues& params,
                                        const TableValues& tables, std::string_view eos_model,
                                        const ParamValues& eos_params) {
  auto m = find_material_model(model)->make(params, tables);
  if (eos_model.empty()) return m;
  return std::make_unique<WithEos>(std::move(m), find_eos_model(eos_model)->make(eos_params));
}

} // namespace anvil
