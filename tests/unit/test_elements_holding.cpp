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

} // namespace
