#include "anvil/sph/lattice.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>

#include "anvil/core/nearest.hpp"

namespace anvil::sph {

Lattice generate_lattice(const LatticeSpec& l, int dims) {
  Lattice out;
  const double s = l.spacing;
  switch (l.shape) {
  case LatticeSpec::Shape::box: {
    int n[3];
    double d[3];
    for (int i = 0; i < 3; ++i) {
      const double len = l.max[i] - l.min[i];
      n[i] = std::max(1, static_cast<int>(std::lround(len / s)));
      d[i] = len / n[i];
      if (i >= dims) { // one layer at the mid-plane (mid-line), unit extent
        n[i] = 1;
        d[i] = len;
      }
    }
    // Below 3 dimensions the out-of-model coordinates are 0 (lattice.hpp).
    auto at = [&](int c, int k) { return c < dims ? l.min[c] + (k + 0.5) * d[c] : 0.0; };
    out.points.reserve(static_cast<std::size_t>(n[0]) * n[1] * n[2]);
    for (int k = 0; k < n[2]; ++k)
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i) out.points.push_back({at(0, i), at(1, j), at(2, k)});
    out.volume = d[0] * (dims >= 2 ? d[1] : 1.0) * (dims >= 3 ? d[2] : 1.0);
    break;
  }
  case LatticeSpec::Shape::sphere: {
    const int m = static_cast<int>(std::ceil(l.radius / s)) + 1;
    const double r2 = l.radius * l.radius;
    const int mz = dims == 3 ? m : 0; // a disc in 2-D
    for (int k = -mz; k < std::max(mz, 1); ++k)
      for (int j = -m; j < m; ++j)
        for (int i = -m; i < m; ++i) {
          const Vec3 o{(i + 0.5) * s, (j + 0.5) * s, dims == 3 ? (k + 0.5) * s : 0.0};
          if (dot(o, o) >= r2) continue;
          Vec3 p = l.center + o;
          if (dims == 2) p.z = 0; // the model's plane
          out.points.push_back(p);
        }
    out.volume = dims == 3 ? s * s * s : s * s;
    break;
  }
  case LatticeSpec::Shape::cylinder: {
    const int a = l.axis, b = (a + 1) % 3, c = (a + 2) % 3;
    const int layers = dims == 3 ? std::max(1, static_cast<int>(std::lround(l.length / s))) : 1;
    const double da = l.length / layers;
    const int m = static_cast<int>(std::ceil(l.radius / s)) + 1;
    const double r2 = l.radius * l.radius, ri2 = l.inner_radius * l.inner_radius;
    for (int k = 0; k < layers; ++k)
      for (int j = -m; j < m; ++j)
        for (int i = -m; i < m; ++i) {
          const double u = (i + 0.5) * s, w = (j + 0.5) * s;
          if (u * u + w * w >= r2 || u * u + w * w < ri2) continue;
          Vec3 p = l.origin;
          p[a] = dims == 3 ? p[a] + (k + 0.5) * da : 0.0; // 2-D (axis z): the model's plane
          // Right-handed (b, c, a): x then y across an axis along z.
          p[b] += u;
          p[c] += w;
          out.points.push_back(p);
        }
    out.volume = dims == 3 ? s * s * da : s * s;
    break;
  }
  }
  out.spacing =
      dims == 3 ? std::cbrt(out.volume) : (dims == 2 ? std::sqrt(out.volume) : out.volume);
  return out;
}

CloudSpacing cloud_spacing(const std::vector<Vec3>& points) {
  CloudSpacing out;
  const std::size_t n = points.size();
  if (n < 2) return out;
  std::vector<double> c[3];
  for (auto& a : c) a.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d) c[d][i] = points[i][d];
  std::vector<std::int64_t> id(n);
  std::iota(id.begin(), id.end(), std::int64_t{0});
  std::vector<int> all(n);
  std::iota(all.begin(), all.end(), 0);
  const NearestGrid grid(c[0].data(), c[1].data(), c[2].data(), id.data(), all);
  std::vector<double> r2(n);
  for (std::size_t i = 0; i < n; ++i) {
    const NearestGrid::Hit h = grid.nearest(points[i], static_cast<int>(i));
    if (!(h.r2 > 0)) return {0, static_cast<int>(i), h.index};
    r2[i] = h.r2;
    if (out.farthest < 0 || h.r2 > r2[static_cast<std::size_t>(out.farthest)])
      out.farthest = static_cast<int>(i);
  }
  out.spacing = std::sqrt(r2[static_cast<std::size_t>(out.farthest)]);
  std::nth_element(r2.begin(), r2.begin() + static_cast<std::ptrdiff_t>(n / 2), r2.end());
  out.median = std::sqrt(r2[n / 2]);
  return out;
}

} // namespace anvil::sph
