// Wedges, pyramids and tetrahedra as hexahedra whose nodes repeat (mesh.hpp, "Solids with
// fewer than eight corners"): the patterns read, their canonical forms, volumes and faces,
// the box generator's cuts, and contact's projection on a triangular face. References:
// the solids' exact volumes (tetrahedron abc/6, pyramid base x height / 3, wedge
// base x height), the exact foot of the normal on a plane triangle (barycentric
// coordinates). Tolerances: round-off (1e-14 relative).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "anvil/contact/geometry.hpp"
#include "anvil/contact/surface.hpp"
#include "anvil/mesh/generators.hpp"
#include "anvil/mesh/mesh.hpp"
#include "anvil/parallel/comm.hpp"
#include "anvil/solver/simulation.hpp"
#include "test_support.hpp"

namespace {

using namespace anvil;

std::array<Vec3, 8> corners(const std::vector<Vec3>& x, const Hex& h) {
  std::array<Vec3, 8> c;
  for (int a = 0; a < 8; ++a) c[a] = x[static_cast<std::size_t>(h[a])];
  return c;
}

// Every face that is a face points out of the solid, and the faces close: their vector
// areas add up to zero. Returns the number of faces.
int check_faces(const std::vector<Vec3>& x, const Hex& h) {
  Vec3 centroid, closure;
  std::vector<std::int64_t> distinct;
  for (auto n : h)
    if (std::find(distinct.begin(), distinct.end(), n) == distinct.end()) distinct.push_back(n);
  for (auto n : distinct) centroid += x[static_cast<std::size_t>(n)] * (1.0 / distinct.size());
  int faces = 0;
  for (int f = 0; f < 6; ++f) {
    if (!is_face(face_key(h, f))) continue;
    ++faces;
    const auto q = face_nodes(h, f);
    const bool triangle = face_key(h, f)[0] < 0;
    if (triangle) EXPECT_EQ(q[2], q[3]) << "face " << f;
    Vec3 p[4], c;
    for (int a = 0; a < 4; ++a) p[a] = x[static_cast<std::size_t>(q[a])];
    for (int a = 0; a < (triangle ? 3 : 4); ++a) c += p[a] * (1.0 / (triangle ? 3 : 4));
    const Vec3 area = cross(p[2] - p[0], p[3] - p[1]) * 0.5;
    EXPECT_GT(dot(area, c - centroid), 0) << "face " << f << " points in";
    closure += area;
  }
  EXPECT_LT(norm(closure), 1e-14);
  return faces;
}

// Unit solids: tetrahedron 0 1 2 3, pyramid on the unit square with apex at height 1,
// wedge on the right triangle of legs 1 with height 1.
const std::vector<Vec3> points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                  {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {0.5, 0.5, 1}};

TEST(DegenerateSolids, CanonicalFormsHaveTheSolidsVolumesAndOutwardFaces) {
  struct Case {
    Hex h;
    Shape shape;
    double volume;
    int faces;
  };
  const Case cases[] = {
      {tetrahedron_hex(0, 1, 3, 4), Shape::tetrahedron, 1.0 / 6, 4},
      {pyramid_hex(0, 1, 2, 3, 7), Shape::pyramid, 1.0 / 3, 5},
      {wedge_hex(0, 1, 3, 4, 5, 6), Shape::wedge, 0.5, 5},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(shape_name(c.shape));
    Hex h = c.h;
    EXPECT_EQ(canonical_hex(h, 1), "");
    EXPECT_EQ(h, c.h); // already canonical
    EXPECT_EQ(shape_of(h), c.shape);
    const auto x = corners(points, h);
    EXPECT_NEAR(hex_volume(x), c.volume, 1e-15);
    EXPECT_GT(hex_centre_jacobian(x), 0);
    EXPECT_EQ(check_faces(points, h), c.faces);
  }
}

TEST(DegenerateSolids, LsDynaPatternsAreRewrittenWithTheirVolume) {
  // *ELEMENT_SOLID's tetrahedron N1 N2 N3 N4 N4 N4 N4 N4: read as a hexahedron its
  // bottom "quadrilateral" N1 N2 N3 N4 passes through the apex, and the trilinear map
  // fills half the tetrahedron only; rewritten a b c c d d d d, it fills all of it.
  Hex tet = {0, 1, 3, 4, 4, 4, 4, 4};
  EXPECT_NEAR(hex_volume(corners(points, tet)), 1.0 / 12, 1e-15);
  EXPECT_EQ(canonical_hex(tet, 7), "");
  EXPECT_EQ(tet, tetrahedron_hex(0, 1, 3, 4));
  EXPECT_NEAR(hex_volume(corners(points, tet)), 1.0 / 6, 1e-15);
  // The pentahedron N1 N2 N3 N4 N5 N5 N6 N6: a wedge lying on its quadrilateral N1-N4,
  // its ridge N5-N6 above the edges N1-N2 and N3-N4.
  const std::vector<Vec3> roof = {{0, 0, 0}, {2, 0, 0},   {2, 3, 0},
                                  {0, 3, 0}, {1, 0, 1.5}, {1, 3, 1.5}};
  Hex penta = {0, 1, 2, 3, 4, 4, 5, 5};
  const double v_penta = hex_volume(corners(roof, penta));
  EXPECT_NEAR(v_penta, 0.5 * 2 * 1.5 * 3, 1e-14);
  EXPECT_EQ(canonical_hex(penta, 8), "");
  EXPECT_EQ(shape_of(penta), Shape::wedge);
  EXPECT_NEAR(hex_volume(corners(roof, penta)), v_penta, 1e-14);
  EXPECT_GT(hex_centre_jacobian(corners(roof, penta)), 0);
  EXPECT_EQ(check_faces(roof, penta), 5);
}

TEST(DegenerateSolids, OtherRepeatsAreRefusedNamingThem) {
  Hex h = {0, 1, 2, 3, 4, 5, 2, 7}; // N3 = N7
  int corner = -1;
  const std::string why = canonical_hex(h, 42, &corner);
  EXPECT_NE(why.find("element 42 repeats nodes"), std::string::npos) << why;
  EXPECT_NE(why.find("N3 = N7"), std::string::npos) << why;
  EXPECT_EQ(corner, 6);
  Hex wedge_twisted = {0, 1, 2, 2, 4, 4, 6, 6}; // N3 = N4 with N5 = N6 and N7 = N8
  EXPECT_NE(canonical_hex(wedge_twisted, 1), "");
}

// VTK's orders (vtkTetra, vtkPyramid, vtkWedge): the first face's normal by the right-hand
// rule points to the fourth point (tetrahedron), to the apex (pyramid), away from the
// other triangle (wedge).
TEST(DegenerateSolids, VtkCellsFollowVtkOrientation) {
  auto toward = [](const std::array<std::int64_t, 8>& c, int n_face, std::int64_t other) {
    const Vec3 a = points[c[0]], b = points[c[1]], d = points[c[2]];
    Vec3 centre;
    for (int k = 0; k < n_face; ++k) centre += points[c[k]] * (1.0 / n_face);
    return dot(cross(b - a, d - a), points[other] - centre);
  };
  std::array<std::int64_t, 8> c;
  int n = 0;
  EXPECT_EQ(vtk_cell(tetrahedron_hex(0, 1, 3, 4), c, n), 10);
  EXPECT_EQ(n, 4);
  EXPECT_GT(toward(c, 3, c[3]), 0);
  EXPECT_EQ(vtk_cell(pyramid_hex(0, 1, 2, 3, 7), c, n), 14);
  EXPECT_EQ(n, 5);
  EXPECT_GT(toward(c, 4, c[4]), 0);
  EXPECT_EQ(vtk_cell(wedge_hex(0, 1, 3, 4, 5, 6), c, n), 13);
  EXPECT_EQ(n, 6);
  EXPECT_LT(toward(c, 3, c[3]), 0);
  EXPECT_EQ((std::array<std::int64_t, 6>{c[0], c[1], c[2], c[3], c[4], c[5]}),
            (std::array<std::int64_t, 6>{0, 3, 1, 4, 6, 5}));
}

TEST(DegenerateSolids, FaceKeysMatchTrianglesWrittenEitherWay) {
  EXPECT_EQ(face_key({5, 9, 2, 2}), (FaceKey{-1, 2, 5, 9}));
  EXPECT_EQ(face_key({2, 5, 5, 9}), (FaceKey{-1, 2, 5, 9}));
  EXPECT_FALSE(is_face(face_key({3, 3, 8, 8})));
  EXPECT_TRUE(is_face(face_key({1, 2, 3, 4})));
  EXPECT_EQ(face_nodes(std::array<std::int64_t, 4>{7, 7, 3, 5}),
            (std::array<std::int64_t, 4>{3, 5, 7, 7}));
  EXPECT_EQ(face_nodes(std::array<std::int64_t, 4>{1, 2, 3, 4}),
            (std::array<std::int64_t, 4>{1, 2, 3, 4}));
}

// The box cut into wedges and tetrahedra: the cells' volumes add up to the box's, every
// element has positive volume, and the exterior faces are the box's six sides only (the
// cuts are conforming), with the area of the box.
TEST(DegenerateSolids, BoxCutIntoWedgesAndTetrahedraIsConforming) {
  for (const Shape s : {Shape::wedge, Shape::tetrahedron}) {
    SCOPED_TRACE(shape_name(s));
    BoxSpec spec{{0, 0, 0}, {0.2, 0.3, 0.4}, {2, 3, 4}};
    spec.shape = s;
    const Mesh m = generate_box(spec);
    const auto& el = m.blocks[0].elements;
    ASSERT_EQ(el.size(), (s == Shape::wedge ? 2u : 6u) * 24);
    double volume = 0;
    for (const Hex& h : el) {
      EXPECT_EQ(shape_of(h), s);
      const double v = hex_volume(corners(m.nodes, h));
      EXPECT_GT(v, 0);
      volume += v;
      check_faces(m.nodes, h);
    }
    EXPECT_NEAR(volume, 0.2 * 0.3 * 0.4, 1e-15);
    const ExteriorFaces ext = exterior_faces(m, {true});
    double area = 0;
    for (std::size_t f = 0; f < ext.size(); ++f) {
      Vec3 p[4];
      for (int a = 0; a < 4; ++a) p[a] = m.nodes[static_cast<std::size_t>(ext.nodes[f][a])];
      area += 0.5 * norm(cross(p[2] - p[0], p[3] - p[1]));
      if (s == Shape::tetrahedron) EXPECT_EQ(ext.nodes[f][2], ext.nodes[f][3]); // triangles
      EXPECT_LT(ext.behind[f], 0);
    }
    EXPECT_NEAR(area, 2 * (0.2 * 0.3 + 0.3 * 0.4 + 0.2 * 0.4), 1e-14);
  }
}

// The foot of the normal on a triangle stored as a collapsed quadrilateral (x2 = x3):
// the exact projection on its plane, with shape functions equal to the
// barycentric coordinates (foot_shape; within 5% of the corner x2, la + lb < 0.05, the
// foot's xi is (lb - la) / 0.05, finite: inside the triangle |xi| <= 1, and a little
// outside it near that corner too); one face at a time and `simd::width` at a time give
// the same bits.
TEST(DegenerateSolids, ProjectionOnATriangleIsExact) {
  const Vec3 a{0.01, -0.02, 0.003}, b{1.1, 0.05, -0.1}, c{0.3, 0.95, 0.2};
  const std::array<Vec3, 4> tri{a, b, c, c};
  const Vec3 n = cross(b - a, c - a) * (1 / norm(cross(b - a, c - a)));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<QuadQuery> queries;
  std::vector<std::array<double, 3>> lambda;
  for (int k = 0; k < 2000; ++k) {
    double lb = u(rng), lc = u(rng);
    if (k % 4 == 0) lc = 1 - 1e-4 * u(rng), lb = (1 - lc) * u(rng); // by the corner x2
    if (k % 7 == 0) lb = 1.2 * lb - 0.1, lc = 1.2 * lc - 0.1;       // and outside
    const double la = 1 - lb - lc;
    const Vec3 on = a * la + b * lb + c * lc;
    queries.push_back({tri, on + n * (0.2 * u(rng) - 0.1)});
    lambda.push_back({la, lb, lc});
  }
  std::vector<QuadProjection> out(queries.size());
  project_on_quads(queries, out);
  for (std::size_t k = 0; k < queries.size(); ++k) {
    const QuadProjection one = project_on_quad(queries[k].x, queries[k].p);
    ASSERT_TRUE(one.converged);
    const double mine[] = {one.xi,      one.eta,      one.gap,      one.point.x, one.point.y,
                           one.point.z, one.normal.x, one.normal.y, one.normal.z};
    const double lanes[] = {out[k].xi,       out[k].eta,      out[k].gap,
                            out[k].point.x,  out[k].point.y,  out[k].point.z,
                            out[k].normal.x, out[k].normal.y, out[k].normal.z};
    EXPECT_EQ(std::memcmp(mine, lanes, sizeof mine), 0) << k;
    const auto N = foot_shape(one.xi, one.eta, true);
    const auto& l = lambda[k];
    const double s_ab = l[0] + l[1];
    if (s_ab < 0.05) EXPECT_NEAR(one.xi, (l[1] - l[0]) / 0.05, 1e-9);
    EXPECT_NEAR(N[0], l[0], 1e-12);
    EXPECT_NEAR(N[1], l[1], 1e-12);
    EXPECT_NEAR(N[2] + N[3], l[2], 1e-12);
    const Vec3 exact = a * l[0] + b * l[1] + c * l[2];
    EXPECT_LT(norm(one.point - exact), 1e-14);
    EXPECT_NEAR(one.gap, dot(queries[k].p - exact, n), 1e-14);
    EXPECT_LT(norm(one.normal - n), 1e-14);
    const bool inside = l[0] >= 0 && l[1] >= 0 && l[2] >= 0;
    const bool in_range = std::abs(one.xi) <= 1 + 1e-12 && std::abs(one.eta) <= 1 + 1e-12;
    if (s_ab >= 0.05)
      EXPECT_EQ(inside, in_range) << k;
    else if (inside)
      EXPECT_TRUE(in_range) << k;
  }
}

// The deck's box `elements`, its errors, and the thick shell's refusal of other solids.
TEST(DegenerateSolids, DeckBoxElementsAndThickShellRefusal) {
  const std::string deck = R"(
termination: {time: 1.0e-6}
materials:
  steel: {model: elastic, density: 7850, youngs_modulus: 200.0e9, poissons_ratio: 0.3}
parts:
  plate:
    mesh: {generate: box, min: [0, 0, 0], max: [0.01, 0.01, 0.001], divisions: [4, 4, 1], elements: ELEMENTS}
    material: steel
)";
  auto with = [&](const std::string& elements, const std::string& extra = "") {
    std::string text = deck;
    text.replace(text.find("ELEMENTS"), 8, elements);
    return text + extra;
  };
  EXPECT_EQ(test::deck(with("tetrahedra")).parts[0].mesh.box.shape, Shape::tetrahedron);
  EXPECT_EQ(test::deck(with("wedges")).parts[0].mesh.box.shape, Shape::wedge);
  EXPECT_EQ(test::deck(with("hexahedra")).parts[0].mesh.box.shape, Shape::hexahedron);
  try {
    test::deck(with("pyramids"), "deck.yaml");
    ADD_FAILURE() << "pyramids accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("deck.yaml:7"), std::string::npos) << msg;
    EXPECT_NE(msg.find("unknown elements 'pyramids'"), std::string::npos) << msg;
  }
  // Thick shells are hexahedra (three points through one element's thickness).
  std::string shell_text = with("wedges");
  shell_text.replace(shell_text.find("material: steel"), 15,
                     "material: steel\n    thick_shell: {points: 3}");
  const Config shell = test::deck(shell_text, "deck.yaml");
  try {
    const Comm self = Comm::self();
    Simulation sim(shell, self);
    ADD_FAILURE() << "a thick shell of wedges was accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("part plate is a thick shell, and its element 1 is a wedge"),
              std::string::npos)
        << msg;
  }
}

} // namespace
