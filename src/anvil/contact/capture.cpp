#include "anvil/contact/capture.hpp"

#include "anvil/core/simd.hpp"

namespace anvil {

namespace {
using simd::vdouble;

// std::min(a, b) and std::max(a, b) lane by lane: (b < a) ? b : a and (a < b) ? b : a.
inline vdouble smin(const vdouble& a, const vdouble& b) {
  vdouble r = a;
  where(b < a, r) = b;
  return r;
}
inline vdouble smax(const vdouble& a, const vdouble& b) {
  vdouble r = a;
  where(a < b, r) = b;
  return r;
}
std::size_t padded(std::size_t n) {
  return static_cast<std::size_t>(simd::padded_size(static_cast<int>(n)));
}
} // namespace

void FaceCaptures::resize(std::size_t n) {
  const std::size_t m = padded(n);
  for (int i = 0; i < 3; ++i) {
    normal[i].resize(m);
    lo[i].resize(m);
    hi[i].resize(m);
    centre[i].resize(m);
  }
  offset.resize(m);
  warp.resize(m);
}

void compute_captures(const FaceCorners& in, FaceCaptures& out) {
  out.resize(in.n);
  const std::size_t m = padded(in.n);
  for (std::size_t f = 0; f < m; f += simd::width) {
    vdouble x[4][3];
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) x[a][i] = simd::gather(in.x[i], in.corner[a] + f);
    // face_plane(): centre, normal from the diagonals, size, warp.
    vdouble c[3];
    for (int i = 0; i < 3; ++i) c[i] = 0.25 * (x[0][i] + x[1][i] + x[2][i] + x[3][i]);
    const vdouble d1[3] = {x[2][0] - x[0][0], x[2][1] - x[0][1], x[2][2] - x[0][2]};
    const vdouble d2[3] = {x[3][0] - x[1][0], x[3][1] - x[1][1], x[3][2] - x[1][2]};
    const vdouble n[3] = {d1[1] * d2[2] - d1[2] * d2[1], d1[2] * d2[0] - d1[0] * d2[2],
                          d1[0] * d2[1] - d1[1] * d2[0]};
    const vdouble len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const vdouble inv = 1 / len;
    const auto flat = !(len > 0);
    vdouble nu[3];
    for (int i = 0; i < 3; ++i) {
      nu[i] = n[i] * inv;
      where(flat, nu[i]) = 0.0;
    }
    const vdouble size = sqrt(0.5 * len);
    vdouble warp = 0.0;
    for (int a = 0; a < 4; ++a) {
      const vdouble h =
          (x[a][0] - c[0]) * nu[0] + (x[a][1] - c[1]) * nu[1] + (x[a][2] - c[2]) * nu[2];
      warp = smax(warp, abs(h));
    }
    // capture_box(): the corners and the corners swept back by 2 depth, padded.
    const vdouble s = -2 * simd::load(in.depth + f);
    const vdouble pad = 0.05 * size;
    for (int i = 0; i < 3; ++i) {
      const vdouble back = nu[i] * s;
      vdouble lo = 1e300, hi = -1e300;
      for (int a = 0; a < 4; ++a) {
        const vdouble v = x[a][i], w = v + back;
        lo = smin(lo, smin(v, w));
        hi = smax(hi, smax(v, w));
      }
      simd::store(lo - pad, out.lo[i].data() + f);
      simd::store(hi + pad, out.hi[i].data() + f);
      simd::store(nu[i], out.normal[i].data() + f);
      simd::store(c[i], out.centre[i].data() + f);
    }
    simd::store(c[0] * nu[0] + c[1] * nu[1] + c[2] * nu[2], out.offset.data() + f);
    simd::store(warp, out.warp.data() + f);
  }
}

} // namespace anvil
