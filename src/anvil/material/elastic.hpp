#pragma once

#include "anvil/material/material.hpp"

namespace anvil {

// Hypoelastic isotropic solid: stress rate = lambda tr(D) I + 2 G D (objective through
// the rotation applied by the caller).
class Elastic : public Material {
public:
  explicit Elastic(const ParamValues& p) : Material(p) {}
  void update(const MaterialBatch& b) const override;
  static std::span<const ParamSpec> params();
};

} // namespace anvil
