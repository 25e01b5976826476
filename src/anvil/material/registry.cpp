#include <array>

#include "anvil/material/elastic.hpp"
#include "anvil/material/j2_plasticity.hpp"
#include "anvil/material/johnson_cook.hpp"

namespace anvil {

namespace {
template <class M>
std::unique_ptr<Material> make(const ParamValues& p) {
  return std::make_unique<M>(p);
}

const std::array<MaterialModel, 3>& models() {
  static const std::array<MaterialModel, 3> list = {{
      {"elastic", Elastic::params(), &make<Elastic>, "hypoelastic isotropic solid"},
      {"j2_plasticity", J2Plasticity::params(), &make<J2Plasticity>,
       "von Mises plasticity, linear isotropic hardening"},
      {"johnson_cook", JohnsonCook::params(), &make<JohnsonCook>,
       "Johnson-Cook viscoplasticity with adiabatic heating"},
  }};
  return list;
}
} // namespace

std::span<const MaterialModel> material_models() {
  return models();
}

const MaterialModel* find_material_model(std::string_view name) {
  for (const auto& m : models())
    if (m.name == name) return &m;
  return nullptr;
}

} // namespace anvil
