// SPH smoothing kernels in 3-D, both with support 2h (Monaghan 1992; Wendland 1995 as
// normalised by Dehnen and Aly 2012 for support 2h). Each returns W(r, h) and
// (1/r) dW/dr, so that the gradient is dwr * (x_i - x_j) with no division by r (finite
// at r = 0 for both kernels).
#pragma once

#include <algorithm>
#include <numbers>

namespace anvil::sph {

enum class KernelType { cubic_spline, wendland_c2 };

inline constexpr double support_factor = 2.0; // W vanishes at r >= 2h

// Cubic B-spline: W = s (1 - 3/2 q^2 + 3/4 q^3) for q < 1, s/4 (2 - q)^3 for 1 <= q < 2,
// s = 1 / (pi h^3), q = r / h.
inline void cubic_spline(double r, double h, double& w, double& dwr) {
  const double ih = 1.0 / h, q = r * ih;
  const double s = std::numbers::inv_pi * ih * ih * ih;
  if (q < 1) {
    w = s * (1 - 1.5 * q * q + 0.75 * q * q * q);
    dwr = s * ih * ih * (-3 + 2.25 * q);
  } else if (q < 2) {
    const double t = 2 - q;
    w = s * 0.25 * t * t * t;
    dwr = q > 0 ? s * ih * (-0.75 * t * t) / r : 0.0;
  } else {
    w = 0;
    dwr = 0;
  }
}

// Wendland C2: W = 21 / (16 pi h^3) (1 - q/2)^4 (2 q + 1) for q < 2.
inline void wendland_c2(double r, double h, double& w, double& dwr) {
  const double ih = 1.0 / h, q = r * ih;
  if (q >= 2) {
    w = 0;
    dwr = 0;
    return;
  }
  const double s = 21.0 / 16.0 * std::numbers::inv_pi * ih * ih * ih;
  const double t = 1 - 0.5 * q, t3 = t * t * t;
  w = s * t3 * t * (2 * q + 1);
  dwr = s * ih * ih * (-5 * t3);
}

// Normalisation of a kernel in D dimensions, times h^D: cubic spline 2/3, 10/(7 pi),
// 1/pi; Wendland C2 (this shape) 7/(4 pi) in 2-D, 21/(16 pi) in 3-D.
template <KernelType K, int D>
constexpr double kernel_norm() {
  if constexpr (K == KernelType::cubic_spline)
    return D == 1 ? 2.0 / 3.0 : (D == 2 ? 10.0 / 7.0 * std::numbers::inv_pi : std::numbers::inv_pi);
  else
    return D == 2 ? 7.0 / 4.0 * std::numbers::inv_pi : 21.0 / 16.0 * std::numbers::inv_pi;
}

// Branch-free forms for the pair loops in D dimensions (the 3-D values equal those
// above up to round-off; the particle phase uses these everywhere, so every rank runs
// the same arithmetic). r > 0.
template <KernelType K, int D>
inline void kernel_fast(double r, double h, double& w, double& dwr) {
  const double ih = 1.0 / h, q = r * ih;
  const double ihd = D == 1 ? ih : (D == 2 ? ih * ih : ih * ih * ih);
  const double s = kernel_norm<K, D>() * ihd;
  if constexpr (K == KernelType::cubic_spline) {
    const double a = std::max(2 - q, 0.0), b = std::max(1 - q, 0.0);
    w = s * (0.25 * a * a * a - b * b * b);
    // dW/dr = s/h (-3/4 a^2 + 3 b^2); divided by r, finite as r -> 0 (b^2 - a^2/4 ~ -q).
    dwr = s * ih * (3 * b * b - 0.75 * a * a) / r;
  } else {
    const double t = std::max(1 - 0.5 * q, 0.0), t3 = t * t * t;
    w = s * t3 * t * (2 * q + 1);
    dwr = s * ih * ih * (-5 * t3);
  }
}

inline void kernel(KernelType k, double r, double h, double& w, double& dwr) {
  if (k == KernelType::cubic_spline)
    cubic_spline(r, h, w, dwr);
  else
    wendland_c2(r, h, w, dwr);
}

// The kernel's shape w(q), W = norm / h^D w(r / h) (for ratios such as Monaghan's
// W(r) / W(dp), in which the normalisation cancels).
inline double kernel_shape(KernelType k, double q) {
  double w, dwr;
  kernel(k, q, 1.0, w, dwr);
  return w / (k == KernelType::cubic_spline ? kernel_norm<KernelType::cubic_spline, 3>()
                                            : kernel_norm<KernelType::wendland_c2, 3>());
}

} // namespace anvil::sph
