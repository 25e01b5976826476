// elements_holding (solver/model.hpp): the element of the listed blocks that holds each
// point, the smallest id first; what the setup's initial-overlap warning and the particles'
// start inside elements use.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "anvil/mesh/generators.hpp"
#include "anvil/solver/model.hpp"

namespace {

using namespace anvil;

Vec3 centre(const Mesh& m, std::size_t b, std::size_t e) {
  Vec3 c{0, 0, 0};
  for (auto n : m.blocks[b].elements[e]) c = c + 0.125 * m.nodes[static_cast<std::size_t>(n)];
  return c;
}

// Reference: the geometry. A block of 20^3 elements of 0.3 mm beside a block of 2^3
// elements of 0.5 m (QA round 35: the grid's cells are the mean element's size, and each
// large element spanned 10^8 of them, so that `anvil check` took 17 s at 20^3 and more than
// 10 minutes at 60 x 60 x 55; now a large element visits the occupied cells in its box).
// Each element's centre is held by that element; points beyond both blocks by none, and
// so is a point where the blocks touch (z = 6 mm): they are separate meshes, and a point
// on a face that bounds a body touches it without being inside it.
TEST(ElementsHolding, ElementsOfVeryDifferentSizesSideBySide) {
  Mesh m = generate_box({{0, 0, 0}, {0.006, 0.006, 0.006}, {20, 20, 20}});
  m.append(generate_box({{-0.5, -0.5, 0.006}, {0.5, 0.5, 1.006}, {2, 2, 2}}), "big");
  const std::vector<std::size_t> blocks{0, 1};
  std::vector<Vec3> points;
  std::vector<std::int64_t> expected;
  for (std::size_t e = 0; e < m.blocks[0].elements.size(); e += 97) {
    points.push_back(centre(m, 0, e));
    expected.push_back(static_cast<std::int64_t>(e));
  }
  for (std::size_t e = 0; e < m.blocks[1].elements.size(); ++e) {
    points.push_back(centre(m, 1, e));
    expected.push_back(8000 + static_cast<std::int64_t>(e));
  }
  points.push_back({0.003, 0.003, -0.001}); // under the small block
  expected.push_back(-1);
  points.push_back({0.7, 0.0, 0.5}); // beside the large one
  expected.push_back(-1);
  points.push_back({0.003, 0.003, 0.006}); // on the face where the blocks touch
  expected.push_back(-1);
  EXPECT_EQ(elements_holding(m, blocks, points, {}), expected);
}

// Reference: the geometry. Two boxes of wedges and two of tetrahedra that touch exactly
// on a face (z = 3 mm), the meshes matching: every node of the upper box's lower face is
// on the surface of the lower box, not inside it, though it lies on a corner or an edge of
// lower elements that reach the surface there only by that corner or edge, with no face on
// it (QA round 36: 8 nodes of wedges and 32 of tetrahedra were reported inside). A point
// in the lower box's interior is still held, and so is one on a face between two of its
// elements (on the plane y = 2 mm between its cells).
TEST(ElementsHolding, TouchingMeshesOfWedgesAndTetrahedraAreNotInside) {
  for (const Shape shape : {Shape::wedge, Shape::tetrahedron}) {
    Mesh m = generate_box({{0, 0, 0}, {0.003, 0.003, 0.003}, {3, 3, 3}, shape});
    const Mesh upper = generate_box({{0, 0, 0.003}, {0.003, 0.003, 0.006}, {3, 3, 3}, shape});
    const auto lower_nodes = m.nodes.size();
    m.append(upper, "upper");
    const std::vector<std::size_t> blocks{0, 1};
    std::vector<Vec3> points;
    std::vector<std::int64_t> ids;
    for (std::size_t n = lower_nodes; n < m.nodes.size(); ++n)
      if (m.nodes[n].z < 0.003 + 1e-12) {
        points.push_back(m.nodes[n]);
        ids.push_back(static_cast<std::int64_t>(n));
      }
    ASSERT_EQ(points.size(), 16u);
    const auto touching = elements_holding(m, blocks, points, ids);
    for (std::size_t i = 0; i < points.size(); ++i)
      EXPECT_EQ(touching[i], -1) << shape_name(shape) << " node " << ids[i] << " at ("
                                 << points[i].x << ", " << points[i].y << ", " << points[i].z
                                 << ")";
    const std::vector<Vec3> inner{{0.0011, 0.0012, 0.0013}, {0.0011, 0.002, 0.0013}};
    for (const std::int64_t h : elements_holding(m, blocks, inner, {}))
      EXPECT_GE(h, 0) << shape_name(shape);
  }
}

} // namespace
