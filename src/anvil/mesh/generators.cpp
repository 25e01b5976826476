#include "anvil/mesh/generators.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace anvil {

namespace {

// Rotates a z-axis construction onto `axis` by a cyclic permutation of the coordinates
// (which keeps the handedness, hence positive element volumes).
Vec3 orient(const Vec3& p, int axis) {
  switch (axis) {
  case 0:
    return {p.z, p.x, p.y};
  case 1:
    return {p.y, p.z, p.x};
  default:
    return p;
  }
}

// Extrudes a 2-D section (points and counter-clockwise quads) along z in `layers`
// equal layers of total length `length`; node id = layer * npts + section id.
Mesh extrude(const std::vector<std::array<double, 2>>& pts,
             const std::vector<std::array<std::int64_t, 4>>& quads, int layers, double length,
             int axis, const Vec3& origin, const std::string& name) {
  Mesh m;
  const auto np = static_cast<std::int64_t>(pts.size());
  m.nodes.reserve(static_cast<std::size_t>(np * (layers + 1)));
  for (int l = 0; l <= layers; ++l) {
    const double z = length * l / layers;
    for (const auto& p : pts) m.nodes.push_back(orient({p[0], p[1], z}, axis) + origin);
  }
  ElementBlock b{name, {}, {}};
  b.elements.reserve(quads.size() * static_cast<std::size_t>(layers));
  for (int l = 0; l < layers; ++l) {
    for (const auto& q : quads) {
      Hex h;
      for (int a = 0; a < 4; ++a) {
        h[a] = l * np + q[a];
        h[a + 4] = (l + 1) * np + q[a];
      }
      b.elements.push_back(h);
    }
  }
  m.blocks.push_back(std::move(b));
  auto& bottom = m.node_sets["bottom"];
  auto& top = m.node_sets["top"];
  for (std::int64_t i = 0; i < np; ++i) {
    bottom.push_back(i);
    top.push_back(layers * np + i);
  }
  return m;
}

void require(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(what);
}

} // namespace

Mesh generate_box(const BoxSpec& s) {
  // Plain names, not a structured binding: clang before 16 cannot capture one in a lambda.
  const int nx = s.divisions[0], ny = s.divisions[1], nz = s.divisions[2];
  require(nx > 0 && ny > 0 && nz > 0, "box divisions must be positive");
  require(s.max.x > s.min.x && s.max.y > s.min.y && s.max.z > s.min.z,
          "box max must exceed min in every direction");
  Mesh m;
  auto id = [&](int i, int j, int k) -> std::int64_t {
    return (static_cast<std::int64_t>(k) * (ny + 1) + j) * (nx + 1) + i;
  };
  m.nodes.resize(static_cast<std::size_t>((nx + 1)) * (ny + 1) * (nz + 1));
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        // Ends are set exactly so that box selections on the faces are reliable.
        auto lerp = [](double a, double b, int n, int i) {
          return i == n ? b : a + (b - a) * i / n;
        };
        m.nodes[id(i, j, k)] = {lerp(s.min.x, s.max.x, nx, i), lerp(s.min.y, s.max.y, ny, j),
                                lerp(s.min.z, s.max.z, nz, k)};
      }
  require(s.shape != Shape::pyramid, "a box is cut into hexahedra, wedges or tetrahedra");
  ElementBlock b{"box", {}, {}};
  b.elements.reserve(static_cast<std::size_t>(nx) * ny * nz);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const Hex c = {
            id(i, j, k),     id(i + 1, j, k),     id(i + 1, j + 1, k),     id(i, j + 1, k),
            id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)};
        if (s.shape == Shape::hexahedron) {
          b.elements.push_back(c);
        } else if (s.shape == Shape::wedge) {
          b.elements.push_back(wedge_hex(c[0], c[1], c[2], c[4], c[5], c[6]));
          b.elements.push_back(wedge_hex(c[0], c[2], c[3], c[4], c[6], c[7]));
        } else {
          // From corner 0 to corner 6 along the edges, x, y, z in each order: the corners
          // one and two steps along.
          constexpr int path[6][2] = {{1, 2}, {1, 5}, {3, 2}, {3, 7}, {4, 5}, {4, 7}};
          for (const auto& q : path) {
            const Vec3 a = m.nodes[c[0]], e1 = m.nodes[c[q[0]]] - a, e2 = m.nodes[c[q[1]]] - a,
                       e3 = m.nodes[c[6]] - a;
            // a b c counter-clockwise seen from d.
            if (dot(cross(e1, e2), e3) > 0)
              b.elements.push_back(tetrahedron_hex(c[0], c[q[0]], c[q[1]], c[6]));
            else
              b.elements.push_back(tetrahedron_hex(c[0], c[q[1]], c[q[0]], c[6]));
          }
        }
      }
  m.blocks.push_back(std::move(b));
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        const auto n = id(i, j, k);
        if (i == 0) m.node_sets["xmin"].push_back(n);
        if (i == nx) m.node_sets["xmax"].push_back(n);
        if (j == 0) m.node_sets["ymin"].push_back(n);
        if (j == ny) m.node_sets["ymax"].push_back(n);
        if (k == 0) m.node_sets["zmin"].push_back(n);
        if (k == nz) m.node_sets["zmax"].push_back(n);
      }
  return m;
}

Mesh generate_cylinder(const CylinderSpec& s) {
  require(s.radius > 0 && s.length > 0, "cylinder radius and length must be positive");
  require(s.divisions[0] >= 2 && s.divisions[1] >= 1,
          "cylinder needs divisions[0] >= 2 (radius) and divisions[1] >= 1 (axis)");
  const int c = std::max(1, s.divisions[0] / 2); // half-count of the central block
  const int ring = s.divisions[0] - c;           // layers of the outer ring
  const int n = 2 * c;                           // central block is n x n
  const int perim = 4 * n;                       // nodes around the block boundary
  const double R = s.radius;
  const double half = R * c / s.divisions[0]; // half-side of the straight block
  const double pi = std::numbers::pi;

  // Boundary of the central block at polar angle phi: a square bulged part-way towards
  // a circle, which keeps the ring elements at the block corners from becoming thin.
  auto inner = [&](double phi) -> std::array<double, 2> {
    double local = std::fmod(phi + pi / 4 + 4 * pi, pi / 2) - pi / 4; // angle from edge normal
    const double beta = 0.4;
    const double r = half * ((1 - beta) / std::cos(local) + beta * 1.2);
    return {r * std::cos(phi), r * std::sin(phi)};
  };

  std::vector<std::array<double, 2>> pts;
  std::vector<std::array<std::int64_t, 4>> quads;
  // Central block: nodes (i, j), i, j in [0, n], Coons patch between the four edges.
  auto bid = [&](int i, int j) -> std::int64_t {
    return static_cast<std::int64_t>(i) * (n + 1) + j;
  };
  auto edge_r = [&](double eta) { return inner(pi / 4 * eta); };         // xi = +1
  auto edge_t = [&](double xi) { return inner(pi / 2 - pi / 4 * xi); };  // eta = +1
  auto edge_l = [&](double eta) { return inner(pi - pi / 4 * eta); };    // xi = -1
  auto edge_b = [&](double xi) { return inner(-pi / 2 + pi / 4 * xi); }; // eta = -1
  pts.resize(static_cast<std::size_t>((n + 1) * (n + 1)));
  const auto p00 = edge_b(-1), p10 = edge_b(1), p01 = edge_t(-1), p11 = edge_t(1);
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double xi = -1.0 + 2.0 * i / n, eta = -1.0 + 2.0 * j / n;
      const double u = 0.5 * (xi + 1), v = 0.5 * (eta + 1);
      const auto L = edge_l(eta), Rr = edge_r(eta), B = edge_b(xi), T = edge_t(xi);
      std::array<double, 2> p;
      for (int d = 0; d < 2; ++d)
        p[d] = (1 - u) * L[d] + u * Rr[d] + (1 - v) * B[d] + v * T[d] -
               ((1 - u) * (1 - v) * p00[d] + u * (1 - v) * p10[d] + (1 - u) * v * p01[d] +
                u * v * p11[d]);
      pts[bid(i, j)] = p;
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      quads.push_back({bid(i, j), bid(i + 1, j), bid(i + 1, j + 1), bid(i, j + 1)});

  // Block boundary counter-clockwise from the corner (n, 0), at phi = -pi/4.
  std::vector<std::int64_t> boundary(perim);
  for (int k = 0; k < n; ++k) {
    boundary[k] = bid(n, k);             // right edge, upwards
    boundary[n + k] = bid(n - k, n);     // top edge, leftwards
    boundary[2 * n + k] = bid(0, n - k); // left edge, downwards
    boundary[3 * n + k] = bid(k, 0);     // bottom edge, rightwards
  }
  // Ring: layer 0 is the block boundary, layer `ring` the circle.
  std::vector<std::int64_t> ring_id(static_cast<std::size_t>(perim) * (ring + 1));
  auto rid = [&](int k, int j) -> std::int64_t& {
    return ring_id[static_cast<std::size_t>(j) * perim + (k % perim)];
  };
  for (int k = 0; k < perim; ++k) {
    rid(k, 0) = boundary[k];
    const double phi = -pi / 4 + 2 * pi * k / perim;
    const auto a = pts[boundary[k]];
    for (int j = 1; j <= ring; ++j) {
      const double t = static_cast<double>(j) / ring;
      std::array<double, 2> p = {(1 - t) * a[0] + t * R * std::cos(phi),
                                 (1 - t) * a[1] + t * R * std::sin(phi)};
      rid(k, j) = static_cast<std::int64_t>(pts.size());
      pts.push_back(p);
    }
  }
  for (int k = 0; k < perim; ++k)
    for (int j = 0; j < ring; ++j)
      quads.push_back({rid(k, j), rid(k, j + 1), rid(k + 1, j + 1), rid(k + 1, j)});

  Mesh m = extrude(pts, quads, s.divisions[1], s.length, s.axis, s.origin, "cylinder");
  const auto np = static_cast<std::int64_t>(pts.size());
  auto& outer = m.node_sets["outer"];
  for (int l = 0; l <= s.divisions[1]; ++l)
    for (int k = 0; k < perim; ++k) outer.push_back(l * np + rid(k, ring));
  std::sort(outer.begin(), outer.end());
  return m;
}

Mesh generate_can(const CanSpec& s) {
  require(s.radius > 0 && s.height > 0 && s.thickness > 0,
          "can radius, height and thickness must be positive");
  require(s.thickness < 2 * s.radius, "can wall thickness must be less than its diameter");
  const int na = s.divisions[0], nh = s.divisions[1], nt = s.divisions[2];
  require(na >= 3 && nh >= 1 && nt >= 1,
          "can divisions need >= 3 around, >= 1 along the axis, >= 1 through the wall");
  std::vector<std::array<double, 2>> pts;
  std::vector<std::array<std::int64_t, 4>> quads;
  auto id = [&](int k, int j) -> std::int64_t {
    return static_cast<std::int64_t>(k % na) * (nt + 1) + j;
  };
  const double pi = std::numbers::pi;
  for (int k = 0; k < na; ++k) {
    const double phi = 2 * pi * k / na;
    for (int j = 0; j <= nt; ++j) {
      const double r = s.radius - 0.5 * s.thickness + s.thickness * j / nt;
      pts.push_back({r * std::cos(phi), r * std::sin(phi)});
    }
  }
  for (int k = 0; k < na; ++k)
    for (int j = 0; j < nt; ++j)
      quads.push_back({id(k, j), id(k, j + 1), id(k + 1, j + 1), id(k + 1, j)});
  Mesh m = extrude(pts, quads, nh, s.height, s.axis, s.origin, "can");
  const auto np = static_cast<std::int64_t>(pts.size());
  auto& inner = m.node_sets["inner"];
  auto& outer = m.node_sets["outer"];
  for (int l = 0; l <= nh; ++l)
    for (int k = 0; k < na; ++k) {
      inner.push_back(l * np + id(k, 0));
      outer.push_back(l * np + id(k, nt));
    }
  std::sort(inner.begin(), inner.end());
  std::sort(outer.begin(), outer.end());
  return m;
}

} // namespace anvil
