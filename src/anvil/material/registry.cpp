#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "anvil/material/elastic.hpp"
#include "anvil/material/ideal_gas.hpp"
#include "anvil/material/j2_plasticity.hpp"
#include "anvil/material/johnson_cook.hpp"
#include "anvil/material/mie_gruneisen.hpp"

namespace anvil {

namespace {
template <class M>
std::unique_ptr<Material> make(const ParamValues& p) {
  return std::make_unique<M>(p);
}
template <class E>
std::unique_ptr<Eos> make_eos(const ParamValues& p) {
  return std::make_unique<E>(p);
}

const std::array<MaterialModel, 4>& models() {
  static const std::array<MaterialModel, 4> list = {{
      {"elastic", Elastic::params(), &make<Elastic>, "hypoelastic isotropic solid"},
      {"j2_plasticity", J2Plasticity::params(), &make<J2Plasticity>,
       "von Mises plasticity, linear isotropic hardening"},
      {"johnson_cook", JohnsonCook::params(), &make<JohnsonCook>,
       "Johnson-Cook viscoplasticity with adiabatic heating"},
      {"ideal_gas", IdealGas::params(), &make<IdealGas>,
       "ideal gas p = (gamma - 1) rho e (particles only)"},
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
                                        std::string_view eos_model, const ParamValues& eos_params) {
  auto m = find_material_model(model)->make(params);
  if (eos_model.empty()) return m;
  return std::make_unique<WithEos>(std::move(m), find_eos_model(eos_model)->make(eos_params));
}

} // namespace anvil
