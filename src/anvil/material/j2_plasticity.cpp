#include "anvil/material/j2_plasticity.hpp"

#include <cmath>

#include "anvil/core/simd.hpp"

namespace anvil {

namespace {
constexpr ParamSpec j2_params[] = {
    {"density", "kg/m^3", true, 0, 0, 1e300, true, false, "reference mass density"},
    {"youngs_modulus", "Pa", true, 0, 0, 1e300, true, false, "Young's modulus"},
    {"poissons_ratio", "-", true, 0, -1, 0.5, true, true, "Poisson's ratio"},
    {"yield_stress", "Pa", true, 0, 0, 1e300, true, false, "initial yield stress"},
    {"hardening_modulus", "Pa", false, 0, 0, 1e300, false, false,
     "slope of yield stress against plastic strain"},
};
} // namespace

std::span<const ParamSpec> J2Plasticity::params() {
  return j2_params;
}

J2Plasticity::J2Plasticity(const ParamValues& p)
    : Material(p), yield_(p.at("yield_stress")), hardening_(p.at("hardening_modulus")) {}

namespace {

struct J2Constants {
  double G, G2, G3, lam, M, H, Y0, dt, G3H;
};

// The radial return of one point (V = double) or of simd::width points (V = vdouble),
// the same operations in the same order on both, so that a point gets the same bits
// whether it falls in a vector or in the scalar remainder of a batch (this file is
// compiled without contraction). Branch-free: the elastic points are masked, not
// skipped, so the loop vectorises across points.
template <class V, class Mask>
[[gnu::always_inline]] inline void radial_return(const J2Constants& c, const V (&d)[6], V (&s)[6],
                                                 V& ep, const V& density, V& wave_speed) {
  using std::sqrt; // and, by argument-dependent lookup, the simd sqrt
  const V tr = (d[0] + d[1] + d[2]) * c.dt;
  for (int k = 0; k < 3; ++k) s[k] = s[k] + c.lam * tr + c.G2 * d[k] * c.dt;
  for (int k = 3; k < 6; ++k) s[k] = s[k] + c.G2 * d[k] * c.dt;
  const V mean = (s[0] + s[1] + s[2]) * (1.0 / 3.0);
  const V d0 = s[0] - mean, d1 = s[1] - mean, d2 = s[2] - mean;
  const V j2 = 0.5 * (d0 * d0 + d1 * d1 + d2 * d2) + s[3] * s[3] + s[4] * s[4] + s[5] * s[5];
  const V q = sqrt(3.0 * j2); // von Mises stress of the trial state
  const V f = q - (c.Y0 + c.H * ep);
  // Radial return: the deviator shrinks by (1 - 3 G dgamma / q); elastic points keep
  // dgamma = 0 and scale = 1 (selected, not multiplied: q may be 0 there).
  const Mask yielding = f > 0.0;
  V dgamma = f / c.G3H;
  V scale = 1.0 - c.G3 * dgamma / q;
  simd::keep_where(yielding, dgamma, 0.0);
  simd::keep_where(yielding, scale, 1.0);
  s[0] = mean + d0 * scale;
  s[1] = mean + d1 * scale;
  s[2] = mean + d2 * scale;
  for (int k = 3; k < 6; ++k) s[k] = s[k] * scale;
  ep = ep + dgamma;
  wave_speed = sqrt(c.M / density);
}

} // namespace

void J2Plasticity::update(const MaterialBatch& b) const {
  using simd::vdouble;
  const double G = elastic().shear;
  const J2Constants c{G,          2 * G,  3 * G, elastic().lambda,  elastic().plane_wave_modulus(),
                      hardening_, yield_, b.dt,  3 * G + hardening_};
  int p = 0;
  for (; p + simd::width <= b.n; p += simd::width) {
    vdouble d[6], s[6];
    for (int k = 0; k < 6; ++k) {
      d[k] = simd::load(b.d[k] + p);
      s[k] = simd::load(b.stress[k] + p);
    }
    vdouble ep = simd::load(b.plastic_strain + p), c_l;
    radial_return<vdouble, simd::vmask>(c, d, s, ep, simd::load(b.density + p), c_l);
    for (int k = 0; k < 6; ++k) simd::store(s[k], b.stress[k] + p);
    simd::store(ep, b.plastic_strain + p);
    simd::store(c_l, b.wave_speed + p);
  }
  for (; p < b.n; ++p) { // remainder (particle batches are not padded)
    double d[6], s[6];
    for (int k = 0; k < 6; ++k) {
      d[k] = b.d[k][p];
      s[k] = b.stress[k][p];
    }
    double ep = b.plastic_strain[p], c_l;
    radial_return<double, bool>(c, d, s, ep, b.density[p], c_l);
    for (int k = 0; k < 6; ++k) b.stress[k][p] = s[k];
    b.plastic_strain[p] = ep;
    b.wave_speed[p] = c_l;
  }
}

void J2Plasticity::flow_stress(const MaterialBatch& b, double* out) const {
  for (int p = 0; p < b.n; ++p) out[p] = yield_ + hardening_ * b.plastic_strain[p];
}

} // namespace anvil
