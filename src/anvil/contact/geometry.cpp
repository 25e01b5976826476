#include "anvil/contact/geometry.hpp"

#include <algorithm>
#include <cmath>

#include "anvil/core/simd.hpp"

namespace anvil {

namespace {
constexpr double sx[4] = {-1, 1, 1, -1};
constexpr double sy[4] = {-1, -1, 1, 1};
} // namespace

std::array<double, 4> quad_shape(double xi, double eta) {
  std::array<double, 4> n;
  for (int a = 0; a < 4; ++a) n[a] = 0.25 * (1 + sx[a] * xi) * (1 + sy[a] * eta);
  return n;
}

std::array<double, 4> foot_shape(double xi, double eta, bool triangle) {
  if (!triangle) return quad_shape(xi, eta);
  // lb - la = xi max(la + lb, 0.05) (see foot() below), la + lb = (1 - eta) / 2.
  const double s = 0.5 * (1 - eta), d = xi * std::max(s, 0.05);
  return {0.5 * (s - d), 0.5 * (s + d), 0.25 * (1 + eta), 0.25 * (1 + eta)};
}

namespace {

// The projection written once for one face (V = double) and for `simd::width` faces, one
// per lane (V = simd::vdouble): every lane does the scalar operations in the scalar
// order (no contraction in this file), so both give the same bits.
namespace stdx = std::experimental;
using simd::vdouble;
using simd::vmask;
inline bool any(bool m) {
  return m;
}
inline bool any(const vmask& m) {
  return stdx::any_of(m);
}
inline void set_where(bool m, double& v, double x) {
  if (m) v = x;
}
inline void set_where(const vmask& m, vdouble& v, const vdouble& x) {
  stdx::where(m, v) = x;
}
inline void set_where(bool m, bool& v, bool x) {
  if (m) v = x;
}
inline void set_where(const vmask& m, vmask& v, bool x) {
  v = (v && !m) || (m && vmask(x));
}
inline double abs_(double v) {
  return std::abs(v);
}
inline vdouble abs_(const vdouble& v) {
  return stdx::abs(v);
}
inline double sqrt_(double v) {
  return std::sqrt(v);
}
inline vdouble sqrt_(const vdouble& v) {
  return stdx::sqrt(v);
}

template <class V>
struct V3 {
  V x, y, z;
};
template <class V>
V3<V> add(const V3<V>& a, const V3<V>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class V>
V3<V> sub(const V3<V>& a, const V3<V>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class V, class S>
V3<V> mul(const V3<V>& a, const S& s) {
  return {a.x * s, a.y * s, a.z * s};
}
template <class V>
V dot3(const V3<V>& a, const V3<V>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class V>
V3<V> cross3(const V3<V>& a, const V3<V>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

template <class V, class M>
struct Foot {
  V xi, eta, gap;
  V3<V> point, normal;
  M converged;
};

// x(xi, eta) = c + a xi + b eta + d xi eta; Newton on the gradient of |x - p|^2 / 2 from
// the centre, on dot products formed once. A triangle (x2 = x3: the face of a wedge,
// pyramid or tetrahedron) is flat: its foot is the projection on its plane, in closed
// form. With barycentric coordinates la, lb, lc of x0, x1, x2 the bilinear map of the
// collapsed quadrilateral gives eta = 2 lc - 1 and xi = (lb - la) / (la + lb), so that its
// shape functions (quad_shape) are la, lb and lc shared by the last two corners (within 5%
// of the apex xi = (lb - la) / 0.05, below, and foot_shape gives la and lb from it).
// (Newton from the centre converges slowly there: the map is singular at the collapsed
// edge.)
template <class V, class M>
Foot<V, M> foot(const V3<V> (&x)[4], const V3<V>& p) {
  const M tri = (x[2].x == x[3].x) && (x[2].y == x[3].y) && (x[2].z == x[3].z);
  const V3<V> c = mul(add(add(add(x[0], x[1]), x[2]), x[3]), 0.25);
  const V3<V> a = mul(sub(add(add(mul(x[0], -1.0), x[1]), x[2]), x[3]), 0.25);
  const V3<V> b = mul(add(add(sub(mul(x[0], -1.0), x[1]), x[2]), x[3]), 0.25);
  const V3<V> d = mul(sub(add(sub(x[0], x[1]), x[2]), x[3]), 0.25);
  const V3<V> r0 = sub(c, p);
  const V aa = dot3(a, a), bb = dot3(b, b), dd = dot3(d, d);
  const V ab = dot3(a, b), ad = dot3(a, d), bd = dot3(b, d);
  const V ra = dot3(r0, a), rb = dot3(r0, b), rd = dot3(r0, d);
  const V scale = aa + bb;
  V xi = 0.0, eta = 0.0;
  M active = !tri, converged(false);
  for (int it = 0; it < 12 && any(active); ++it) {
    // res = x(xi, eta) - p, t_xi = a + eta d, t_eta = b + xi d.
    const V xe = xi * eta;
    const V res_a = ra + xi * aa + eta * ab + xe * ad;
    const V res_b = rb + xi * ab + eta * bb + xe * bd;
    const V res_d = rd + xi * ad + eta * bd + xe * dd;
    const V g1 = res_a + eta * res_d, g2 = res_b + xi * res_d;
    // The Hessian's curvature term uses d. Newton converges quadratically: after a step
    // below 1e-6 the error is of order 1e-12 times the face's relative curvature. Far
    // from the surface (the Hessian not positive) Gauss-Newton, which converges only
    // linearly, stops after a step below 1e-12, or gives up where even it is singular.
    const V h11 = aa + eta * (2 * ad + eta * dd), h22 = bb + xi * (2 * bd + xi * dd);
    const V tt = ab + xi * ad + eta * bd + xe * dd; // t_xi . t_eta
    V h12 = tt + res_d;
    V det = h11 * h22 - h12 * h12;
    V done = 1e-6;
    const M gauss = !(det > 1e-12 * scale * scale);
    if (any(gauss)) {
      set_where(gauss, h12, tt);
      set_where(gauss, det, h11 * h22 - tt * tt);
      set_where(gauss, done, V(1e-12));
      set_where(gauss && !(det > 0.0), active, false);
    }
    const V dxi = -(h22 * g1 - h12 * g2) / det;
    const V deta = -(h11 * g2 - h12 * g1) / det;
    V nxi = xi + dxi, neta = eta + deta;
    set_where(nxi < -3.0, nxi, V(-3.0));
    set_where(3.0 < nxi, nxi, V(3.0));
    set_where(neta < -3.0, neta, V(-3.0));
    set_where(3.0 < neta, neta, V(3.0));
    set_where(active, xi, nxi);
    set_where(active, eta, neta);
    const M now = active && (abs_(dxi) + abs_(deta) < done);
    set_where(now, converged, true);
    set_where(now, active, false);
  }
  Foot<V, M> r;
  r.xi = xi;
  r.eta = eta;
  r.point = add(add(add(c, mul(a, xi)), mul(b, eta)), mul(d, xi * eta));
  const V3<V> t1 = add(a, mul(d, eta)), t2 = add(b, mul(d, xi));
  const V3<V> n = {t1.y * t2.z - t1.z * t2.y, t1.z * t2.x - t1.x * t2.z, t1.x * t2.y - t1.y * t2.x};
  const V len = sqrt_(dot3(n, n));
  r.normal = {V(0.0), V(0.0), V(0.0)};
  const M has = len > 0.0;
  if (any(has)) {
    const V inv = 1 / len;
    set_where(has, r.normal.x, n.x * inv);
    set_where(has, r.normal.y, n.y * inv);
    set_where(has, r.normal.z, n.z * inv);
  }
  r.gap = dot3(sub(p, r.point), r.normal);
  r.converged = converged;
  if (any(tri)) {
    const V3<V> e1 = sub(x[1], x[0]), e2 = sub(x[2], x[0]), w = sub(p, x[0]);
    const V3<V> nt = cross3(e1, e2);
    const V nn = dot3(nt, nt);
    const M flat = tri && nn > 0.0;
    V safe = nn;
    set_where(!flat, safe, V(1.0));
    const V lb = dot3(cross3(w, e2), nt) / safe, lc = dot3(cross3(e1, w), nt) / safe;
    const V la = (1.0 - lb) - lc, s = la + lb;
    // Within 5% of the apex (la + lb below 0.05) xi divides by 0.05 instead: la + lb, the
    // collapsed quadrilateral's width there, goes to 0 at the apex, and with it the
    // tolerance on xi, so a node on the apex that moved off it by round-off found its foot
    // at xi = 1e7 and lost the face it tracked (a wedge punch on a matching plate went
    // through it, QA round 35). Inside the triangle |xi| stays within 1.
    V ts = s;
    set_where(!(s > 0.05), ts, V(0.05));
    const V txi = (lb - la) / ts;
    const V3<V> pt = add(add(x[0], mul(e1, lb)), mul(e2, lc));
    const V inv = 1 / sqrt_(safe);
    const V3<V> nu = mul(nt, inv);
    set_where(flat, r.xi, txi);
    set_where(flat, r.eta, 2.0 * lc - 1.0);
    set_where(flat, r.point.x, pt.x);
    set_where(flat, r.point.y, pt.y);
    set_where(flat, r.point.z, pt.z);
    set_where(flat, r.normal.x, nu.x);
    set_where(flat, r.normal.y, nu.y);
    set_where(flat, r.normal.z, nu.z);
    set_where(flat, r.gap, dot3(sub(p, pt), nu));
    set_where(tri, r.converged, false);
    set_where(flat, r.converged, true);
  }
  if (any(!converged)) { // accept a foot where the gradient vanishes to round-off
    const V3<V> res = sub(r.point, p);
    const V g1 = dot3(res, t1), g2 = dot3(res, t2);
    const M flat = abs_(g1) + abs_(g2) <= 1e-9 * (sqrt_(dot3(res, res)) + 1e-300) * sqrt_(scale);
    set_where(!converged && !tri && flat, r.converged, true);
  }
  return r;
}

} // namespace

QuadProjection project_on_quad(const std::array<Vec3, 4>& x, const Vec3& p) {
  const V3<double> xs[4] = {{x[0].x, x[0].y, x[0].z},
                            {x[1].x, x[1].y, x[1].z},
                            {x[2].x, x[2].y, x[2].z},
                            {x[3].x, x[3].y, x[3].z}};
  const Foot<double, bool> f = foot<double, bool>(xs, {p.x, p.y, p.z});
  QuadProjection r;
  r.xi = f.xi;
  r.eta = f.eta;
  r.point = {f.point.x, f.point.y, f.point.z};
  r.normal = {f.normal.x, f.normal.y, f.normal.z};
  r.gap = f.gap;
  r.converged = f.converged;
  return r;
}

void project_on_quads(std::span<const QuadQuery> queries, std::span<QuadProjection> out) {
  constexpr int W = simd::width;
  const std::size_t n = queries.size();
  for (std::size_t k0 = 0; k0 < n; k0 += W) {
    // Lanes past the end repeat the last query.
    auto q = [&](int l) -> const QuadQuery& {
      return queries[std::min(k0 + static_cast<std::size_t>(l), n - 1)];
    };
    V3<vdouble> x[4], p;
    for (int a = 0; a < 4; ++a) {
      x[a].x = vdouble([&](auto l) { return q(l).x[a].x; });
      x[a].y = vdouble([&](auto l) { return q(l).x[a].y; });
      x[a].z = vdouble([&](auto l) { return q(l).x[a].z; });
    }
    p.x = vdouble([&](auto l) { return q(l).p.x; });
    p.y = vdouble([&](auto l) { return q(l).p.y; });
    p.z = vdouble([&](auto l) { return q(l).p.z; });
    const Foot<vdouble, vmask> f = foot<vdouble, vmask>(x, p);
    for (int l = 0; l < W && k0 + static_cast<std::size_t>(l) < n; ++l) {
      QuadProjection& r = out[k0 + static_cast<std::size_t>(l)];
      r.xi = f.xi[l];
      r.eta = f.eta[l];
      r.point = {f.point.x[l], f.point.y[l], f.point.z[l]};
      r.normal = {f.normal.x[l], f.normal.y[l], f.normal.z[l]};
      r.gap = f.gap[l];
      r.converged = f.converged[l];
    }
  }
}

} // namespace anvil
