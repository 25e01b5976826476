// Contact building blocks: exterior surfaces, the point-to-face projection against
// brute force, the detailed check's rules, and momentum conservation of penalty forces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "anvil/contact/capture.hpp"
#include "anvil/contact/geometry.hpp"
#include "anvil/contact/penalty.hpp"
#include "anvil/contact/rigid_wall.hpp"
#include "anvil/contact/search.hpp"
#include "anvil/contact/surface.hpp"
#include "anvil/mesh/generators.hpp"

namespace {

using namespace anvil;

TEST(Contact, ExteriorFacesOfBoxesAndCans) {
  Mesh m = generate_box({{0, 0, 0}, {1, 1, 1}, {2, 3, 4}});
  auto f = exterior_faces(m, {true});
  EXPECT_EQ(f.size(), 2u * (2 * 3 + 3 * 4 + 2 * 4));
  EXPECT_EQ(static_cast<std::int64_t>(f.contact_nodes.size()),
            m.num_nodes() - 1 * 2 * 3); // minus interior
  // Outward normals: the face's area vector points away from its element's centre.
  for (std::size_t i = 0; i < f.size(); ++i) {
    const auto& n = f.nodes[i];
    const Vec3 c = 0.25 * (m.nodes[n[0]] + m.nodes[n[1]] + m.nodes[n[2]] + m.nodes[n[3]]);
    const Vec3 a = cross(m.nodes[n[2]] - m.nodes[n[0]], m.nodes[n[3]] - m.nodes[n[1]]);
    EXPECT_GT(dot(a, c - Vec3{0.5, 0.5, 0.5}), 0.0);
  }
  // A can has no faces between its elements, only its four surfaces.
  Mesh can = generate_can({0.03, 0.1, 0.001, 2, {}, {12, 5, 2}});
  EXPECT_EQ(exterior_faces(can, {true}).size(), 2u * 12 * 5 + 2u * 12 * 2);
  // Unselected blocks give no faces.
  Mesh two;
  two.append(m, "a");
  two.append(can, "b");
  EXPECT_EQ(exterior_faces(two, {false, true}).size(), 2u * 12 * 5 + 2u * 12 * 2);
}

// The batched projection (simd::width faces at a time) is the scalar one, bit for bit, for
// every kind of query: near and far points, warped, flat, degenerate (two corners equal,
// all four equal) faces, feet inside and outside, and a count that leaves a partial
// vector.
// The faces erosion may expose: with an erodible block, every face between two of its
// elements is listed twice (once per element), `behind` naming the other element; the
// exterior faces have behind -1. Reference: counting on a 2 x 3 x 4 box.
TEST(Contact, FacesErosionMayExpose) {
  Mesh m = generate_box({{0, 0, 0}, {1, 1, 1}, {2, 3, 4}});
  const auto plain = exterior_faces(m, {true});
  const auto f = exterior_faces(m, {true}, {true});
  const std::size_t interior = 1 * 3 * 4 + 2 * 2 * 4 + 2 * 3 * 3; // x, y and z planes
  EXPECT_EQ(f.size(), plain.size() + 2 * interior);
  std::size_t exterior = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (f.behind[i] < 0) {
      ++exterior;
      continue;
    }
    // The element behind lists the same face, its own behind naming this element.
    std::array<std::int64_t, 4> a = f.nodes[i];
    std::sort(a.begin(), a.end());
    int twins = 0;
    for (std::size_t j = 0; j < f.size(); ++j) {
      std::array<std::int64_t, 4> b = f.nodes[j];
      std::sort(b.begin(), b.end());
      if (j != i && a == b) {
        ++twins;
        EXPECT_EQ(f.element[j], f.behind[i]);
        EXPECT_EQ(f.behind[j], f.element[i]);
      }
    }
    EXPECT_EQ(twins, 1);
  }
  EXPECT_EQ(exterior, plain.size());
  EXPECT_EQ(static_cast<std::int64_t>(f.contact_nodes.size()), m.num_nodes());
  for (std::size_t i = 1; i < f.size(); ++i) // ordered by (element, side): ids are positions
    EXPECT_TRUE(f.element[i - 1] < f.element[i] ||
                (f.element[i - 1] == f.element[i] && f.side[i - 1] < f.side[i]));
}

TEST(Contact, BatchedProjectionIsTheScalarOneBitForBit) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.4, 0.4);
  std::vector<QuadQuery> queries;
  for (int trial = 0; trial < 403; ++trial) {
    QuadQuery q;
    q.x = {Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{1, 1, 0}, Vec3{0, 1, 0}};
    const double warp = trial % 3 == 0 ? 0.0 : 1.0;
    for (auto& c : q.x) c += Vec3{0.3 * u(rng), 0.3 * u(rng), warp * u(rng)};
    if (trial % 17 == 0) q.x[2] = q.x[1];
    if (trial % 29 == 0) q.x = {q.x[0], q.x[0], q.x[0], q.x[0]};
    const double far = trial % 5 == 0 ? 20.0 : 1.0;
    q.p = Vec3{0.5 + 2 * u(rng), 0.5 + 2 * u(rng), far * u(rng)};
    queries.push_back(q);
  }
  std::vector<QuadProjection> batched(queries.size());
  project_on_quads(queries, batched);
  auto same = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  int converged = 0;
  for (std::size_t k = 0; k < queries.size(); ++k) {
    const QuadProjection s = project_on_quad(queries[k].x, queries[k].p);
    const QuadProjection& b = batched[k];
    converged += s.converged ? 1 : 0;
    EXPECT_EQ(s.converged, b.converged) << k;
    for (auto [x, y] : {std::pair{s.xi, b.xi},
                        {s.eta, b.eta},
                        {s.gap, b.gap},
                        {s.point.x, b.point.x},
                        {s.point.y, b.point.y},
                        {s.point.z, b.point.z},
                        {s.normal.x, b.normal.x},
                        {s.normal.y, b.normal.y},
                        {s.normal.z, b.normal.z}})
      EXPECT_TRUE(same(x, y)) << k << ": " << x << " vs " << y;
  }
  EXPECT_GT(converged, 300); // most queries converge: the comparison covers the iteration
}

// The foot of the normal on a warped face is the closest point of the surface when it
// lies inside the face: compare with a brute-force minimisation over a 401 x 401 grid
// refined by a local search (tolerance 1e-9 of the face size on distance, 1e-6 on xi).
TEST(Contact, ProjectionMatchesBruteForceOnWarpedFaces) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.15, 0.15);
  for (int trial = 0; trial < 20; ++trial) {
    std::array<Vec3, 4> x = {Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{1, 1, 0}, Vec3{0, 1, 0}};
    for (auto& p : x) p += Vec3{u(rng), u(rng), 2 * u(rng)};
    const Vec3 p{0.5 + u(rng), 0.5 + u(rng), 0.3 * (trial % 2 ? 1 : -1) + u(rng)};
    const QuadProjection q = project_on_quad(x, p);
    ASSERT_TRUE(q.converged);
    auto at = [&](double xi, double eta) {
      const auto N = quad_shape(xi, eta);
      return N[0] * x[0] + N[1] * x[1] + N[2] * x[2] + N[3] * x[3];
    };
    double best = 1e300, bx = 0, by = 0;
    for (int i = 0; i <= 400; ++i)
      for (int j = 0; j <= 400; ++j) {
        const double xi = -1 + i / 200.0, eta = -1 + j / 200.0;
        const double d = norm(at(xi, eta) - p);
        if (d < best) {
          best = d;
          bx = xi;
          by = eta;
        }
      }
    if (std::abs(bx) > 0.99 || std::abs(by) > 0.99) continue; // foot outside: not comparable
    for (double h = 1e-3; h > 1e-12; h *= 0.5)
      for (int k = 0; k < 50; ++k)
        for (auto [dx, dy] : {std::pair{h, 0.0}, {-h, 0.0}, {0.0, h}, {0.0, -h}}) {
          const double d = norm(at(bx + dx, by + dy) - p);
          if (d < best) {
            best = d;
            bx += dx;
            by += dy;
          }
        }
    EXPECT_NEAR(std::abs(q.gap), best, 1e-9) << trial;
    EXPECT_NEAR(q.xi, bx, 1e-6) << trial;
    EXPECT_NEAR(q.eta, by, 1e-6) << trial;
    EXPECT_EQ(q.gap < 0, trial % 2 == 0) << trial; // behind when p is below the face
  }
}

// compute_captures() (structure of arrays, vectorised across faces) gives set_capture()'s
// bits, for a face count that is not a whole number of vectors.
TEST(Contact, ComputeCapturesMatchesSetCaptureBitwise) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  const std::size_t n = 15;
  std::vector<ContactFaceItem> one(n);
  std::vector<double> px[3];
  std::vector<int> corner[4];
  std::vector<double> depth;
  for (std::size_t f = 0; f < n; ++f) {
    auto& it = one[f];
    it = {};
    const double s = std::pow(10.0, -static_cast<double>(f % 5));
    const double xs[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int a = 0; a < 4; ++a) {
      it.x[a][0] = s * (xs[a][0] + 0.2 * u(rng)) + u(rng);
      it.x[a][1] = s * (xs[a][1] + 0.2 * u(rng));
      it.x[a][2] = s * 0.3 * u(rng);
      if (f == 6) it.x[a][0] = it.x[a][1] = it.x[a][2] = 0.25; // degenerate: zero area
      corner[a].push_back(static_cast<int>(px[0].size()));
      for (int i = 0; i < 3; ++i) px[i].push_back(it.x[a][i]);
    }
    it.depth = 0.1 * s;
    depth.push_back(it.depth);
  }
  for (int a = 0; a < 4; ++a) corner[a].resize(n + 16, 0);
  depth.resize(n + 16, 0.0);
  FaceCaptures cap;
  compute_captures({{px[0].data(), px[1].data(), px[2].data()},
                    {corner[0].data(), corner[1].data(), corner[2].data(), corner[3].data()},
                    depth.data(),
                    n},
                   cap);
  auto same = [](double a, double b) { return std::memcmp(&a, &b, 8) == 0; };
  for (std::size_t f = 0; f < n; ++f) {
    const FacePlane p = set_capture(one[f]);
    for (int i = 0; i < 3; ++i) {
      EXPECT_TRUE(same(one[f].normal[i], cap.normal[i][f])) << f;
      EXPECT_TRUE(same(one[f].lo[i], cap.lo[i][f])) << f;
      EXPECT_TRUE(same(one[f].hi[i], cap.hi[i][f])) << f;
      EXPECT_TRUE(same(p.centre[i], cap.centre[i][f])) << f;
    }
    EXPECT_TRUE(same(one[f].offset, cap.offset[f])) << f;
    EXPECT_TRUE(same(one[f].warp, cap.warp[f])) << f;
    // The diagonals' cross product (the size's square, twice) and lengths.
    const auto& x = one[f].x;
    const Vec3 d1{x[2][0] - x[0][0], x[2][1] - x[0][1], x[2][2] - x[0][2]};
    const Vec3 d2{x[3][0] - x[1][0], x[3][1] - x[1][1], x[3][2] - x[1][2]};
    EXPECT_NEAR(cap.len[f], 2 * p.size * p.size, 1e-12 * (1 + cap.len[f])) << f;
    EXPECT_NEAR(cap.diag[f], norm(d1) + norm(d2), 1e-12 * cap.diag[f]) << f;
  }
  // The faces of an index list only, in any order: the same bits, the others untouched.
  FaceCaptures part;
  part.resize(n);
  for (auto& v : part.lo) std::fill(v.begin(), v.end(), -7.0);
  const std::vector<int> which = {9, 2, 14, 6, 0};
  compute_captures({{px[0].data(), px[1].data(), px[2].data()},
                    {corner[0].data(), corner[1].data(), corner[2].data(), corner[3].data()},
                    depth.data(),
                    n},
                   which, part);
  for (std::size_t f = 0; f < n; ++f) {
    const bool listed = std::find(which.begin(), which.end(), static_cast<int>(f)) != which.end();
    for (int i = 0; i < 3; ++i) {
      if (!listed) {
        EXPECT_EQ(part.lo[i][f], -7.0) << f;
        continue;
      }
      EXPECT_TRUE(same(cap.lo[i][f], part.lo[i][f])) << f;
      EXPECT_TRUE(same(cap.hi[i][f], part.hi[i][f])) << f;
      EXPECT_TRUE(same(cap.normal[i][f], part.normal[i][f])) << f;
    }
    if (listed) EXPECT_TRUE(same(cap.warp[f], part.warp[f])) << f;
  }
}

// Two faces of a block's top and a node: the rules of the detailed check.
struct Scene {
  std::vector<ContactNodeItem> nodes;
  std::vector<ContactFaceItem> faces;
  SearchWorkspace work;
  std::vector<ContactPair> pairs;

  // A unit face at height z in the x-y plane over [x0, x0 + 1] x [0, 1], normal +z.
  void face(std::int64_t gid, double x0, double z, std::int64_t first_node) {
    ContactFaceItem f{};
    f.gid = gid;
    const double xs[4][2] = {{x0, 0}, {x0 + 1, 0}, {x0 + 1, 1}, {x0, 1}};
    for (int a = 0; a < 4; ++a) {
      f.node[a] = first_node + a;
      f.opposite[a] = first_node + 4 + a;
      f.holders[a] = 0;
      f.x[a][0] = xs[a][0];
      f.x[a][1] = xs[a][1];
      f.x[a][2] = z;
      f.mass[a] = 1;
    }
    f.stiffness = 1e6;
    f.depth = 0.2;
    set_capture(f);
    faces.push_back(f);
  }
  // A node at p whose own face (a small downward-facing face, gid 900 + index) opposes +z.
  void node(std::int64_t gid, Vec3 p, std::int64_t last = -1) {
    ContactNodeItem n{};
    n.gid = gid;
    n.x[0] = p.x;
    n.x[1] = p.y;
    n.x[2] = p.z;
    n.mass = 1;
    n.last_face = last;
    nodes.push_back(n);
    ContactFaceItem own{};
    own.gid = 900 + gid;
    const double d = 0.05;
    const double xs[4][2] = {{0, 0}, {0, d}, {d, d}, {d, 0}}; // clockwise from above: normal -z
    for (int a = 0; a < 4; ++a) {
      own.node[a] = a == 0 ? gid : 10000 + 10 * gid + a;
      own.opposite[a] = 20000 + 10 * gid + a;
      own.x[a][0] = p.x + xs[a][0];
      own.x[a][1] = p.y + xs[a][1];
      own.x[a][2] = p.z;
      own.mass[a] = 1;
    }
    own.stiffness = 1e6;
    own.depth = 0.01;
    set_capture(own);
    faces.push_back(own);
  }
  // A face with the given corners (counter-clockwise seen from outside) and node ids.
  void quad(std::int64_t gid, const std::array<Vec3, 4>& x, const std::array<std::int64_t, 4>& id) {
    ContactFaceItem f{};
    f.gid = gid;
    for (int a = 0; a < 4; ++a) {
      f.node[a] = id[static_cast<std::size_t>(a)];
      f.opposite[a] = 5000 + 10 * gid + a;
      for (int i = 0; i < 3; ++i) f.x[a][i] = x[static_cast<std::size_t>(a)][i];
      f.mass[a] = 1;
    }
    f.stiffness = 1e6;
    f.depth = 0.2;
    set_capture(f);
    faces.push_back(f);
  }
  // The four faces of a shallow cone z = s (|x| + |y|) over [-1, 1]^2 (s = 0.1: a dish,
  // -0.1: a peak), its vertex node 4 at the origin (nodes 0..8 row by row from (-1, -1)),
  // face ids in `ids` (quadrants -x-y, +x-y, +x+y, -x+y).
  void cone(const std::array<std::int64_t, 4>& ids, double slope = 0.1) {
    auto at = [slope](int i, int j) {
      return Vec3{i - 1.0, j - 1.0, slope * (std::abs(i - 1.0) + std::abs(j - 1.0))};
    };
    auto node_id = [](int i, int j) { return std::int64_t{3 * j + i}; };
    const int lo[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int q = 0; q < 4; ++q) {
      const int i = lo[q][0], j = lo[q][1];
      quad(ids[static_cast<std::size_t>(q)],
           {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)},
           {node_id(i, j), node_id(i + 1, j), node_id(i + 1, j + 1), node_id(i, j + 1)});
    }
  }
  void run() { find_contacts(nodes, faces, SearchOptions{}, work, pairs); }
};

TEST(Contact, DetailedCheckRules) {
  { // behind the face within its depth: a pair, with the face's normal
    Scene s;
    s.face(1, 0, 0, 100);
    s.node(7, {0.3, 0.4, -0.05});
    s.run();
    ASSERT_EQ(s.pairs.size(), 1u);
    EXPECT_EQ(s.faces[static_cast<std::size_t>(s.pairs[0].face)].gid, 1);
    EXPECT_NEAR(s.pairs[0].gap, -0.05, 1e-14);
    EXPECT_NEAR(s.pairs[0].normal.z, 1.0, 1e-14);
    EXPECT_NEAR(s.pairs[0].allowance, 0.05, 1e-14); // found already penetrating
  }
  { // in front, or deeper than the face's depth: nothing
    Scene s;
    s.face(1, 0, 0, 100);
    s.node(7, {0.3, 0.4, 0.01});
    s.node(8, {0.6, 0.4, -0.3});
    s.run();
    EXPECT_TRUE(s.pairs.empty());
  }
  { // a node never contacts its own element's faces
    Scene s;
    s.face(1, 0, 0, 100);
    s.node(104, {0.3, 0.4, -0.05}); // node 104 is one of face 1's element's other nodes
    s.run();
    EXPECT_TRUE(s.pairs.empty());
  }
  { // two candidates: the least penetration wins; a tracked face is kept
    Scene s;
    s.face(1, 0, 0, 100);
    s.face(2, 0, -0.1, 200); // a second face under the first
    s.node(7, {0.3, 0.4, -0.12});
    s.run();
    ASSERT_EQ(s.pairs.size(), 1u);
    EXPECT_EQ(s.faces[static_cast<std::size_t>(s.pairs[0].face)].gid, 2); // 0.02 behind face 2
    Scene t;
    t.face(1, 0, 0, 100);
    t.face(2, 0, -0.1, 200);
    t.node(7, {0.3, 0.4, -0.12}, /*last=*/1);
    t.run();
    ASSERT_EQ(t.pairs.size(), 1u);
    EXPECT_EQ(t.faces[static_cast<std::size_t>(t.pairs[0].face)].gid, 1); // tracked
  }
  { // equal penetrations: the lower face id wins, whatever the order given
    for (bool reversed : {false, true}) {
      Scene s;
      if (reversed) {
        s.face(6, 1, 0, 300);
        s.face(5, 0, 0, 100);
      } else {
        s.face(5, 0, 0, 100);
        s.face(6, 1, 0, 300);
      }
      s.node(7, {1.0, 0.5, -0.05}); // on the shared edge of the two faces
      s.run();
      ASSERT_EQ(s.pairs.size(), 1u);
      EXPECT_EQ(s.faces[static_cast<std::size_t>(s.pairs[0].face)].gid, 5);
    }
  }
}

// Near an edge or corner of its face a pair's normal and gap blend with those of the faces
// sharing it (docs/contact.md, item 4). Reference: the geometry of a cone z = 0.1 (|x| +
// |y|) whose four faces meet at its vertex, each tilted by atan(0.1 sqrt 2) (normal z
// component 1 / sqrt(1.02)). A node 0.05 under the vertex lies behind all four: whichever
// wins (the lower id, which the face ids here move round the quadrants), the normal is
// their mean, +z, and the gap the mean of theirs, -0.05 / sqrt(1.02) (to 1e-12). Before,
// it was the winning face's normal, tilted 0.1 / sqrt(1.02) towards the vertex in x and y.
// Over the middle of a face, nothing blends; near an edge, the face across it weighs the
// ramp of the foot's distance from the edge (1 at the edge, 0 at 5% of the parent
// coordinates inside); a tracked node whose foot crosses the edge moves to that face.
TEST(Contact, NormalsBlendAtEdgesAndCorners) {
  const double nz = 1 / std::sqrt(1.02), nt = 0.1 / std::sqrt(1.02);
  for (const std::array<std::int64_t, 4>& ids :
       {std::array<std::int64_t, 4>{1, 2, 3, 4}, std::array<std::int64_t, 4>{3, 4, 1, 2},
        std::array<std::int64_t, 4>{4, 1, 2, 3}}) {
    Scene s;
    s.cone(ids);
    s.node(70, {0, 0, -0.05});
    s.run();
    ASSERT_EQ(s.pairs.size(), 1u);
    EXPECT_NEAR(s.pairs[0].normal.x, 0, 1e-12);
    EXPECT_NEAR(s.pairs[0].normal.y, 0, 1e-12);
    EXPECT_NEAR(s.pairs[0].normal.z, 1, 1e-12);
    EXPECT_NEAR(s.pairs[0].gap, -0.05 * nz, 1e-12);
  }
  { // over the middle of the +x+y face: its own normal (-nt, -nt, nz)
    Scene s;
    s.cone({1, 2, 3, 4});
    s.node(70, {0.5, 0.5, 0.1 - 0.01});
    s.run();
    ASSERT_EQ(s.pairs.size(), 1u);
    EXPECT_EQ(s.faces[static_cast<std::size_t>(s.pairs[0].face)].gid, 3);
    EXPECT_NEAR(s.pairs[0].normal.x, -nt, 1e-12);
    EXPECT_NEAR(s.pairs[0].normal.z, nz, 1e-12);
  }
  { // on the peak z = -0.1 (|x| + |y|), over the +x+y face (id 3) 0.005 from its edge x =
    // 0, 0.001 behind it: behind the -x+y face (id 4) too, whose foot lies just past that
    // edge. Face 4 weighs the ramp of face 3's foot, r = (|xi| - 0.95) / 0.05 with xi =
    // 2 x_foot - 1, and the normal and gap are (n3 + r n4) / |..| and (g3 + r g4) / (1 + r)
    Scene s;
    s.cone({1, 2, 3, 4}, -0.1);
    const double x = 0.005, y = 0.5;
    const Vec3 p{x, y, -0.1 * (x + y) - 0.001};
    s.node(70, p);
    s.run();
    ASSERT_EQ(s.pairs.size(), 1u);
    EXPECT_EQ(s.faces[static_cast<std::size_t>(s.pairs[0].face)].gid, 3);
    const double len = std::sqrt(1.02);
    const Vec3 n3{0.1 / len, 0.1 / len, 1 / len}, n4{-0.1 / len, 0.1 / len, 1 / len};
    const double g3 = dot(p, n3), g4 = dot(p, n4); // both planes pass through the origin
    const Vec3 foot3 = p - g3 * n3;
    const double r = (std::abs(2 * foot3.x - 1) - 0.95) / 0.05;
    ASSERT_GT(r, 0.0);
    ASSERT_LT(r, 1.0);
    const Vec3 sum = n3 + r * n4, n = sum * (1 / norm(sum));
    EXPECT_NEAR(s.pairs[0].normal.x, n.x, 1e-12);
    EXPECT_NEAR(s.pairs[0].normal.y, n.y, 1e-12);
    EXPECT_NEAR(s.pairs[0].normal.z, n.z, 1e-12);
    EXPECT_NEAR(s.pairs[0].gap, (g3 + r * g4) / (1 + r), 1e-12);
    // Tracked on face 4, whose foot has crossed onto face 3: the pair moves to face 3.
    Scene t;
    t.cone({1, 2, 3, 4}, -0.1);
    t.node(70, p, /*last=*/4);
    t.run();
    ASSERT_EQ(t.pairs.size(), 1u);
    EXPECT_EQ(t.faces[static_cast<std::size_t>(t.pairs[0].face)].gid, 3);
  }
}

// Penalty forces of a pair sum to zero (momentum conserved to round-off) with and without
// friction; the normal force is k times the penetration beyond the allowance; a node held
// by several ranks gets the same item addressed to each of them.
TEST(Contact, PenaltyForcesConserveMomentum) {
  Scene s;
  s.face(1, 0, 0, 100);
  s.node(7, {0.3, 0.4, -0.05});
  s.nodes[0].v[0] = 2.0; // sliding
  s.run();
  ASSERT_EQ(s.pairs.size(), 1u);
  s.pairs[0].allowance = 0.01;
  const int one_start[] = {0, 1}, one_rank[] = {0}; // group 0: rank 0 alone
  for (double mu : {0.0, 0.3}) {
    std::vector<ContactForceItem> items;
    std::vector<int> dest;
    penalty_forces(s.nodes, s.faces, s.pairs, {mu, 1e-6}, {one_start, one_rank}, items, dest);
    ASSERT_EQ(items.size(), 5u);
    double sum[3] = {0, 0, 0};
    for (const auto& it : items)
      for (int i = 0; i < 3; ++i) sum[i] += it.f[i];
    for (double v : sum) EXPECT_NEAR(v, 0.0, 1e-9);
    EXPECT_NEAR(items[0].f[2], 1e6 * 0.04, 1e-6);
    if (mu > 0)
      EXPECT_LT(items[0].f[0], 0.0); // friction opposes the sliding
    else
      EXPECT_EQ(items[0].f[0], 0.0);
  }
  // A node held by two ranks gets the same item at each: group 1 = ranks 1 and 3.
  const int start[] = {0, 1, 3}, ranks[] = {0, 1, 3};
  s.faces[0].holders[2] = 1;
  std::vector<ContactForceItem> items;
  std::vector<int> dest;
  penalty_forces(s.nodes, s.faces, s.pairs, {0.0, 1e-6}, {start, ranks}, items, dest);
  ASSERT_EQ(items.size(), 6u);
  ASSERT_EQ(dest.size(), 6u);
  int copies = 0;
  for (std::size_t j = 0; j < items.size(); ++j)
    if (items[j].target == s.faces[0].node[2]) {
      EXPECT_EQ(dest[j], copies == 0 ? 1 : 3);
      EXPECT_EQ(items[j].f[2], items[j - static_cast<std::size_t>(copies)].f[2]);
      ++copies;
    } else {
      EXPECT_EQ(dest[j], 0);
    }
  EXPECT_EQ(copies, 2);
}

// The stiffness cap (penalty.hpp): a pair's stiffness never exceeds
// stable_stiffness_fraction m / dt^2, m the node against the face's nodes at the foot
// (1 / m = 1 / m_node + sum N_a^2 / m_face_a). Reference: that formula, to round-off.
TEST(Contact, PenaltyStiffnessCappedForLightNodes) {
  Scene s;
  s.face(1, 0, 0, 100);
  s.node(7, {0.3, 0.4, -0.05});
  s.run();
  ASSERT_EQ(s.pairs.size(), 1u);
  s.pairs[0].allowance = 0.0;
  const int one_start[] = {0, 1}, one_rank[] = {0};
  auto force = [&](double node_mass, double dt) {
    s.nodes[0].mass = node_mass;
    std::vector<ContactForceItem> items;
    std::vector<int> dest;
    penalty_forces(s.nodes, s.faces, s.pairs, {0.0, dt}, {one_start, one_rank}, items, dest);
    return items.at(0).f[2];
  };
  const double pen = -s.pairs[0].gap;
  // Heavy node, short step: the face's stiffness (1e6 N/m).
  EXPECT_NEAR(force(1.0, 1e-6), 1e6 * pen, 1e-9);
  // A light node (1e-9 kg) at 1e-6 s: the cap, 0.5 m / dt^2 with the faces' unit masses.
  const auto N = quad_shape(s.pairs[0].xi, s.pairs[0].eta);
  double inv_m = 1e9;
  for (int a = 0; a < 4; ++a) inv_m += N[a] * N[a];
  const double k = stable_stiffness_fraction / (inv_m * 1e-12);
  EXPECT_LT(k, 1e6);
  EXPECT_NEAR(force(1e-9, 1e-6), k * pen, 1e-12 * k * pen);
}

// A rigid wall (kinematic: the node lands on the wall at the end of the step) on nodes
// with constrained components. Reference: the constraint itself, exact to round-off:
// constrained components keep their value; the free ones put the node on the wall
// (a wedge); the impulse reported is the one applied, m (v' - v).n.
TEST(RigidWall, ConstrainedComponentsAndTheImpulseApplied) {
  const double dt = 1e-6, m = 2.0;
  auto run = [&](Vec3 normal, std::uint8_t fixed, Vec3 v0, Vec3& v1, double& impulse) {
    const double x[3] = {0.0, 0.0, 1e-6}; // 1 um above the wall's point
    double v[3] = {v0.x, v0.y, v0.z};
    const double v_start[3] = {v0.x, v0.y, v0.z};
    const double mass = m;
    const std::uint8_t owned = 1;
    const std::int64_t gid = 5;
    const WallNodes nd{{&x[0], &x[1], &x[2]},
                       {&v[0], &v[1], &v[2]},
                       {&v_start[0], &v_start[1], &v_start[2]},
                       &mass,
                       &fixed,
                       &owned,
                       &gid,
                       100,
                       1};
    std::vector<WallHit> hits;
    const RigidWallConfig wall{{0, 0, 0}, normal * (1 / norm(normal)), 0.0};
    apply_rigid_walls({wall}, dt, nd, hits);
    v1 = {v[0], v[1], v[2]};
    impulse = hits.empty() ? 0.0 : hits[0].impulse;
    if (!hits.empty()) EXPECT_EQ(hits[0].key, 105);
    return Vec3{x[0], x[1], x[2]} + dt * v1; // the position at the end of the step
  };
  Vec3 v1;
  double impulse;
  // Free node: lands on the wall; impulse m dv.n.
  Vec3 xe = run({0, 0, 1}, 0u, {0, 0, -20}, v1, impulse);
  EXPECT_NEAR(xe.z, 0.0, 1e-18);
  EXPECT_NEAR(impulse, m * (v1.z + 20), 1e-12);
  // z prescribed (driven into a flat wall): the wall cannot move it and applies nothing.
  xe = run({0, 0, 1}, 4u, {0, 0, -20}, v1, impulse);
  EXPECT_EQ(v1.z, -20.0);
  EXPECT_EQ(v1.x, 0.0);
  EXPECT_EQ(impulse, 0.0);
  // z prescribed, oblique wall: x alone brings the node onto the wall in one step.
  const Vec3 n = Vec3{0.2, 0, 1} * (1 / norm(Vec3{0.2, 0, 1}));
  xe = run({0.2, 0, 1}, 4u, {0, 0, -20}, v1, impulse);
  EXPECT_EQ(v1.z, -20.0);
  EXPECT_NEAR(dot(xe, n), 0.0, 1e-18);
  EXPECT_GT(v1.x, 0.0);
  EXPECT_NEAR(impulse, m * dot(v1 - Vec3{0, 0, -20}, n), 1e-12);
  // A wall's force sums its hits in ascending key, whatever order they come in.
  std::vector<WallHit> a = {{3, 0, 0.1}, {1, 1, 5.0}, {2, 0, 1e16}, {1, 0, -1e16}},
                       b = {a[2], a[1], a[3], a[0]};
  std::vector<double> fa(2), fb(2);
  wall_forces(a, 0.5, fa);
  wall_forces(b, 0.5, fb);
  EXPECT_EQ(fa[0], ((-1e16 + 1e16) + 0.1) / 0.5);
  EXPECT_EQ(fa[1], 10.0);
  EXPECT_EQ(fa, fb);
}

} // namespace
