// The 4-wide, quantized BVH the shader reads (packing/scene_packing.h): every primitive reachable once,
// every decoded child box containing what is below it, and no more than two quantization steps
// looser than it, whatever the scale and offset of the scene.
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "packing/scene_packing.h"

namespace vkray::gpu {
namespace {

bool contains(const Aabb& outer, const Aabb& inner) {
  return glm::all(glm::lessThanEqual(outer.min, inner.min)) && glm::all(glm::greaterThanEqual(outer.max, inner.max));
}

struct Walk {
  const Bvh& bvh;
  const std::vector<Aabb>& boxes;
  const std::vector<glm::uvec4>& nodes;
  std::multiset<uint32_t> seen;
  uint32_t max_depth = 0;

  // Returns the exact bounds of everything under `link`, checking each node on the way.
  Aabb visit(uint32_t link, uint32_t depth) {
    Aabb bounds;
    if (is_leaf(link)) {
      for (uint32_t slot = leaf_first(link); slot < leaf_first(link) + leaf_count(link); ++slot) {
        seen.insert(bvh.order.at(slot));
        bounds.grow(boxes[bvh.order[slot]]);
      }
      return bounds;
    }
    max_depth = std::max(max_depth, depth);
    EXPECT_LT(size_t(link) * VKRAY_TEXELS_PER_NODE, nodes.size());
    const glm::uvec4* node = &nodes[size_t(link) * VKRAY_TEXELS_PER_NODE];
    int children = 0;
    for (int c = 0; c < VKRAY_NODE_WIDTH; ++c) {
      if (node[1][c] == 0) continue;
      ++children;
      const Aabb exact = visit(node[1][c], depth + 1);
      const Aabb decoded = unpack_child_box(node, c);
      EXPECT_TRUE(contains(decoded, exact)) << "node " << link << " child " << c;
      // Rounding outward costs at most one step a side (plus the rounding of the sum).
      for (int axis = 0; axis < 3; ++axis) {
        const float step = std::bit_cast<float>(((node[0].w >> (8 * axis)) & 0xffu) << 23);
        EXPECT_LE(exact.min[axis] - decoded.min[axis], 2 * step) << "node " << link << " child " << c;
        EXPECT_LE(decoded.max[axis] - exact.max[axis], 2 * step) << "node " << link << " child " << c;
      }
      bounds.grow(exact);
    }
    EXPECT_GE(children, 1) << "node " << link;
    return bounds;
  }
};

void check_packing(const std::vector<Aabb>& boxes) {
  const Bvh bvh = build_bvh(boxes);
  const std::vector<glm::uvec4> nodes = pack_nodes(bvh);
  ASSERT_FALSE(nodes.empty());
  ASSERT_EQ(nodes.size() % VKRAY_TEXELS_PER_NODE, 0u);
  Walk walk{bvh, boxes, nodes, {}, 0};
  walk.visit(0, 1);
  ASSERT_EQ(walk.seen.size(), boxes.size());
  for (uint32_t i = 0; i < boxes.size(); ++i) EXPECT_EQ(walk.seen.count(i), 1u) << "primitive " << i;
  // The shader's stack holds (VKRAY_NODE_WIDTH - 1) entries a level.
  EXPECT_LE(walk.max_depth * (VKRAY_NODE_WIDTH - 1), uint32_t(VKRAY_TRAVERSAL_STACK));
}

std::vector<Aabb> random_boxes(size_t n, unsigned seed, float offset, float spread, float size) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-spread, spread), extent(0, size);
  std::vector<Aabb> boxes(n);
  for (auto& b : boxes) {
    const glm::vec3 p = glm::vec3(offset) + glm::vec3(pos(rng), pos(rng), pos(rng));
    b = {p, p + glm::vec3(extent(rng), extent(rng), extent(rng))};
  }
  return boxes;
}

TEST(NodePackingTest, RandomBoxesAtManyScales) {
  for (float offset : {0.0f, 1e6f, -3e4f})
    for (float spread : {1e-3f, 1.0f, 1e4f})
      for (size_t n : {1u, 2u, 5u, 17u, 3000u}) {
        SCOPED_TRACE(testing::Message() << "offset " << offset << " spread " << spread << " n " << n);
        check_packing(random_boxes(n, unsigned(n), offset, spread, spread / 10));
      }
}

TEST(NodePackingTest, FlatAndPointBoxes) {
  std::vector<Aabb> boxes;
  for (int i = 0; i < 40; ++i) boxes.push_back({glm::vec3(float(i), 0, 0), glm::vec3(float(i) + 1, 1, 0)});
  for (int i = 0; i < 40; ++i) boxes.push_back({glm::vec3(0.5f, float(i), 2), glm::vec3(0.5f, float(i), 2)});
  check_packing(boxes);
}

TEST(NodePackingTest, DeepTreeFitsTheStack) {
  // Identical boxes force median splits all the way down: the deepest tree the builder makes.
  check_packing(std::vector<Aabb>(20000, Aabb{glm::vec3(1), glm::vec3(2)}));
}

TEST(NodePackingTest, NoPrimitivesNoNodes) { EXPECT_TRUE(pack_nodes(build_bvh({})).empty()); }

}  // namespace
}  // namespace vkray::gpu
