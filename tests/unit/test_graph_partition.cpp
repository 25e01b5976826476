// The static FE partition (METIS k-way on the element dual graph) balances work when the
// elements of the blocks cost differently: each element weighs its block's weight.
#include <gtest/gtest.h>

#include <vector>

#include "anvil/fe/hex_block.hpp"
#include "anvil/mesh/generators.hpp"
#include "anvil/parallel/graph_partition.hpp"

namespace anvil {
namespace {

// Two 8 x 8 x 4 blocks stacked in z (512 elements, 256 each), sharing the face z = 0.
Mesh two_blocks() {
  Mesh m = generate_box({{0, 0, 0}, {1, 1, 0.5}, {8, 8, 4}});
  m.append(generate_box({{0, 0, 0.5}, {1, 1, 1}, {8, 8, 4}}), "upper");
  return m;
}

// Per part: {elements, weighted sum}.
std::vector<std::array<long, 2>> loads(const Mesh& m, const std::vector<int>& owner, int parts,
                                       const std::vector<int>& weight) {
  std::vector<std::array<long, 2>> out(static_cast<std::size_t>(parts), {0, 0});
  std::size_t e = 0;
  for (std::size_t b = 0; b < m.blocks.size(); ++b)
    for (std::size_t i = 0; i < m.blocks[b].elements.size(); ++i, ++e) {
      auto& l = out[static_cast<std::size_t>(owner[e])];
      l[0] += 1;
      l[1] += weight[b];
    }
  return out;
}

TEST(GraphPartition, WeightsBalanceWorkNotCounts) {
  const Mesh m = two_blocks();
  ASSERT_EQ(m.blocks.size(), 2u);
  const std::vector<int> weight{3, 1}; // the lower block's elements cost three times more
  for (int parts : {2, 3, 4}) {
    const auto plain = loads(m, partition_elements(m, parts), parts, weight);
    const auto weighted = loads(m, partition_elements(m, parts, weight), parts, weight);
    long total = 0, most_plain = 0, most = 0, fewest_count = 1 << 30, most_count = 0;
    for (int p = 0; p < parts; ++p) {
      total += weighted[static_cast<std::size_t>(p)][1];
      most = std::max(most, weighted[static_cast<std::size_t>(p)][1]);
      most_plain = std::max(most_plain, plain[static_cast<std::size_t>(p)][1]);
      fewest_count = std::min(fewest_count, weighted[static_cast<std::size_t>(p)][0]);
      most_count = std::max(most_count, weighted[static_cast<std::size_t>(p)][0]);
    }
    const double mean = static_cast<double>(total) / parts;
    // METIS's default k-way balance tolerance is 3% (ufactor 30); allow 5% for the
    // coarse 512-element graph.
    EXPECT_LE(most, 1.05 * mean) << parts << " parts";
    // Unweighted, the counts balance and the work does not: the weights changed the cut.
    EXPECT_GT(most_plain, 1.10 * mean) << parts << " parts";
    EXPECT_GT(most_count, fewest_count + fewest_count / 5) << parts << " parts";
  }
}

TEST(GraphPartition, OneWeightPerBlock) {
  const Mesh m = two_blocks();
  EXPECT_THROW(partition_elements(m, 2, std::vector<int>{1}), std::invalid_argument);
}

// The thick shell costs more than the one-point element it is built on, and more with
// more points through the thickness (docs/performance.md).
TEST(GraphPartition, ElementCostsOrdered) {
  const HourglassControl viscous, stiffness{HourglassControl::Model::stiffness, 0.1},
      assumed{HourglassControl::Model::assumed_strain, 1.0};
  EXPECT_LT(element_cost(viscous, {}), element_cost(stiffness, {}));
  EXPECT_LT(element_cost(stiffness, {}), element_cost(assumed, {}));
  EXPECT_LT(element_cost(assumed, {}), element_cost(assumed, {2}));
  EXPECT_LT(element_cost(assumed, {2}), element_cost(assumed, {3}));
}

} // namespace
} // namespace anvil
