#include "anvil/contact/capture.hpp"

#include <algorithm>

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
  len.resize(m);
  diag.resize(m);
}

namespace {
constexpr int kFields = 16; // arrays of FaceCaptures
constexpr int kSearch = 11; // of which the search reads the first (up to warp)

// One vector of faces: lane l is the face whose corners are points c[a][l] and whose
// depth is depth[l]. r: normal (3), lo (3), hi (3), offset, warp, centre (3), len, diag.
[[gnu::always_inline]] inline void capture_lanes(const FaceCorners& in, const int* const c4[4],
                                                 const vdouble& depth, vdouble (&r)[kFields]) {
  vdouble x[4][3];
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) x[a][i] = simd::gather(in.x[i], c4[a]);
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
  const vdouble s = -2 * depth;
  const vdouble pad = 0.05 * size;
  for (int i = 0; i < 3; ++i) {
    const vdouble back = nu[i] * s;
    vdouble lo = 1e300, hi = -1e300;
    for (int a = 0; a < 4; ++a) {
      const vdouble v = x[a][i], w = v + back;
      lo = smin(lo, smin(v, w));
      hi = smax(hi, smax(v, w));
    }
    r[i] = nu[i];
    r[3 + i] = lo - pad;
    r[6 + i] = hi + pad;
    r[11 + i] = c[i];
  }
  r[9] = c[0] * nu[0] + c[1] * nu[1] + c[2] * nu[2];
  r[10] = warp;
  r[14] = len;
  r[15] = sqrt(d1[0] * d1[0] + d1[1] * d1[1] + d1[2] * d1[2]) +
          sqrt(d2[0] * d2[0] + d2[1] * d2[1] + d2[2] * d2[2]);
}

double* field(FaceCaptures& out, int k) {
  if (k < 3) return out.normal[k].data();
  if (k < 6) return out.lo[k - 3].data();
  if (k < 9) return out.hi[k - 6].data();
  if (k < 11) return k == 9 ? out.offset.data() : out.warp.data();
  if (k < 14) return out.centre[k - 11].data();
  return k == 14 ? out.len.data() : out.diag.data();
}
} // namespace

void compute_captures(const FaceCorners& in, FaceCaptures& out) {
  out.resize(in.n);
  const std::size_t m = padded(in.n);
  double* dst[kFields];
  for (int k = 0; k < kFields; ++k) dst[k] = field(out, k);
  for (std::size_t f = 0; f < m; f += simd::width) {
    const int* c4[4] = {in.corner[0] + f, in.corner[1] + f, in.corner[2] + f, in.corner[3] + f};
    vdouble r[kFields];
    capture_lanes(in, c4, simd::load(in.depth + f), r);
    for (int k = 0; k < kFields; ++k) simd::store(r[k], dst[k] + f);
  }
}

void compute_captures(const FaceCorners& in, std::span<const int> which, FaceCaptures& out,
                      bool search_only) {
  out.resize(in.n);
  const int fields = search_only ? kSearch : kFields;
  double* dst[kFields];
  for (int k = 0; k < kFields; ++k) dst[k] = field(out, k);
  for (std::size_t j = 0; j < which.size(); j += simd::width) {
    // The faces which[j..j + width), the last one repeated past the end.
    int face[simd::width], c[4][simd::width];
    double dep[simd::width];
    for (int l = 0; l < simd::width; ++l) {
      face[l] = which[std::min(j + static_cast<std::size_t>(l), which.size() - 1)];
      for (int a = 0; a < 4; ++a) c[a][l] = in.corner[a][face[l]];
      dep[l] = in.depth[face[l]];
    }
    const int* c4[4] = {c[0], c[1], c[2], c[3]};
    vdouble r[kFields];
    capture_lanes(in, c4, simd::load(dep), r);
    for (int k = 0; k < fields; ++k)
      for (int l = 0; l < simd::width; ++l) dst[k][face[l]] = r[k][l];
  }
}

} // namespace anvil
