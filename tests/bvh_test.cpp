// The BVH builder's invariants: every primitive once, boxes that contain what is below them,
// bounded depth even for the worst input.
#include <cmath>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "base/errors.h"
#include "bvh/bvh.h"

namespace vkray {
namespace {

bool contains(const Aabb& outer, const Aabb& inner) {
  return glm::all(glm::lessThanEqual(outer.min, inner.min)) && glm::all(glm::greaterThanEqual(outer.max, inner.max));
}

// Checks the subtree under `link` against `box` and collects its primitives.
void check(const Bvh& bvh, const std::vector<Aabb>& boxes, uint32_t link, const Aabb& box, std::multiset<uint32_t>& seen,
           uint32_t depth) {
  ASSERT_LE(depth, kMaxDepth);
  if (is_leaf(link)) {
    ASSERT_GE(leaf_count(link), 1u);
    for (uint32_t slot = leaf_first(link); slot < leaf_first(link) + leaf_count(link); ++slot) {
      ASSERT_LT(slot, bvh.order.size());
      seen.insert(bvh.order[slot]);
      EXPECT_TRUE(contains(box, boxes[bvh.order[slot]])) << "primitive " << bvh.order[slot] << " outside its leaf";
    }
    return;
  }
  ASSERT_LT(link, bvh.nodes.size());
  const BvhNode& node = bvh.nodes[link];
  for (int c = 0; c < 2; ++c) {
    EXPECT_TRUE(contains(box, node.child[c])) << "child box outside its parent";
    check(bvh, boxes, node.link[c], node.child[c], seen, depth + 1);
  }
}

void check_tree(const std::vector<Aabb>& boxes) {
  const Bvh bvh = build_bvh(boxes);
  ASSERT_FALSE(bvh.nodes.empty());
  std::multiset<uint32_t> seen;
  Aabb all;
  for (const auto& b : boxes) all.grow(b);
  const BvhNode& root = bvh.nodes[0];
  for (int c = 0; c < 2; ++c) {
    if (is_leaf(root.link[c]) && leaf_count(root.link[c]) == 0) continue;  // the empty side of a one-leaf tree
    EXPECT_TRUE(contains(all, root.child[c]));
    check(bvh, boxes, root.link[c], root.child[c], seen, 1);
  }
  ASSERT_EQ(seen.size(), boxes.size());
  for (uint32_t i = 0; i < boxes.size(); ++i) EXPECT_EQ(seen.count(i), 1u) << "primitive " << i;
  EXPECT_LT(bvh.depth, kMaxDepth);
}

std::vector<Aabb> random_boxes(size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-100, 100), size(0, 2);
  std::vector<Aabb> boxes(n);
  for (auto& b : boxes) {
    // One draw a statement: the order of a call's arguments is the compiler's choice (GCC goes
    // right to left, clang left to right), and the boxes must not depend on it. This is GCC's order,
    // in which the hash in TheTreeIsTheOneTheEarlierBuilderBuilt was taken.
    const float pz = pos(rng), py = pos(rng), px = pos(rng);
    const float sz = size(rng), sy = size(rng), sx = size(rng);
    const glm::vec3 p(px, py, pz);
    b = {p, p + glm::vec3(sx, sy, sz)};
  }
  return boxes;
}

TEST(BvhTest, RandomBoxes) {
  for (size_t n : {1u, 2u, 3u, 15u, 16u, 17u, 1000u, 50000u}) {
    SCOPED_TRACE(n);
    check_tree(random_boxes(n, unsigned(n)));
  }
}

TEST(BvhTest, NoPrimitivesNoNodes) { EXPECT_TRUE(build_bvh({}).nodes.empty()); }

TEST(BvhTest, IdenticalBoxesStillGiveABoundedTree) {
  // SAH cannot split these at all: the builder must fall back to median splits, not recurse forever.
  check_tree(std::vector<Aabb>(20000, Aabb{glm::vec3(1), glm::vec3(2)}));
}

TEST(BvhTest, FlatBoxesOfAxisAlignedWalls) {
  std::vector<Aabb> boxes;
  for (int i = 0; i < 64; ++i) boxes.push_back({glm::vec3(float(i), 0, 0), glm::vec3(float(i) + 1, 1, 0)});
  check_tree(boxes);
}

// Boxes whose sums overflow a float (coordinates near FLT_MAX, all finite) made the SAH's bin index
// undefined and the builder write out of bounds. The scene refuses such coordinates; the builder
// refuses them too, whoever calls it.
TEST(BvhTest, BoundsPastTheCoordinateLimitAreRefused) {
  const std::vector<Aabb> far_apart = {{glm::vec3(-3e38f), glm::vec3(-3e38f)}, {glm::vec3(3e38f), glm::vec3(3e38f)},
                                       {glm::vec3(0.0f), glm::vec3(1.0f)}};
  EXPECT_THROW(build_bvh(far_apart), LimitError);
  const std::vector<Aabb> not_finite = {{glm::vec3(0.0f), glm::vec3(INFINITY)}, {glm::vec3(0.0f), glm::vec3(1.0f)}};
  EXPECT_THROW(build_bvh(not_finite), LimitError);
  // At the limit itself the tree is built, and every box is in it.
  std::vector<Aabb> at_limit;
  for (int i = 0; i < 64; ++i) {
    const float x = (i % 2 ? 1.0f : -1.0f) * kMaxCoordinate * float(i + 1) / 64.0f;
    at_limit.push_back({glm::vec3(x, -kMaxCoordinate, 0.0f), glm::vec3(x, kMaxCoordinate, 1.0f)});
  }
  const Bvh bvh = build_bvh(at_limit);
  EXPECT_EQ(bvh.order.size(), at_limit.size());
}

// The build splits large ranges across threads and bins them in parallel blocks; the tree must not
// depend on how many threads did it, since nothing a pixel depends on may (docs/rendering.md, "What a
// pixel depends on"). 200,000 boxes go through both the parallel top and the parallel binning.
// FNV-1a over every node's boxes and links and the leaf order: a tree's identity, to the bit.
uint64_t tree_hash(const Bvh& bvh) {
  uint64_t h = 1469598103934665603ull;
  const auto add = [&h](const void* data, size_t size) {
    for (size_t i = 0; i < size; ++i) h = (h ^ static_cast<const unsigned char*>(data)[i]) * 1099511628211ull;
  };
  for (const BvhNode& n : bvh.nodes) {
    add(n.child, sizeof n.child);
    add(n.link, sizeof n.link);
  }
  add(bvh.order.data(), bvh.order.size() * sizeof(uint32_t));
  return h;
}

TEST(BvhTest, TheTreeIsTheSameOnAnyNumberOfThreads) {
  // Some coordinates -0 and some +0: SSE's min and max pick between zeros by operand order, so
  // the builder makes every zero +0 (bvh.cpp); the comparison is bitwise.
  std::vector<Aabb> boxes = random_boxes(200000, 5);
  for (size_t i = 0; i < boxes.size(); i += 7) {
    boxes[i].min.x = (i % 2 ? -0.0f : 0.0f);
    boxes[i].max.x = (i % 3 ? -0.0f : 0.0f);  // flat at x = 0, a side of either sign
  }
  const Bvh one = build_bvh(boxes, 1);
  check_tree(boxes);
  for (const BvhNode& n : one.nodes)
    for (const Aabb& b : n.child)
      for (int axis = 0; axis < 3; ++axis)
        for (const float side : {b.min[axis], b.max[axis]}) ASSERT_FALSE(side == 0.0f && std::signbit(side));
  for (unsigned threads : {2u, 3u, 8u}) {
    SCOPED_TRACE(threads);
    const Bvh other = build_bvh(boxes, threads);
    EXPECT_EQ(other.depth, one.depth);
    EXPECT_EQ(tree_hash(other), tree_hash(one));
  }
}

// The parallel builder (2026-11-23) builds the tree the single-threaded builder before it built,
// node for node: the hash below is that builder's, for these boxes. A change here changes the
// tree every scene is traced through (and should say why).
TEST(BvhTest, TheTreeIsTheOneTheEarlierBuilderBuilt) {
  const Bvh bvh = build_bvh(random_boxes(50000, 7));
  EXPECT_EQ(bvh.nodes.size(), 29669u);
  EXPECT_EQ(bvh.depth, 19u);
  EXPECT_EQ(tree_hash(bvh), 0x3582a390b532f45full);
}

// Two clusters of four unit cubes, far apart along x: SAH separates the clusters first, then each
// cluster into its halves. The cost follows from the boxes by hand.
TEST(BvhTest, SahCostOfATreeWorkedOutByHand) {
  std::vector<Aabb> boxes;
  for (float x : {0.0f, 100.0f})
    for (float y : {0.0f, 10.0f})
      for (float z : {0.0f, 10.0f}) boxes.push_back({glm::vec3(x, y, z), glm::vec3(x + 1, y + 1, z + 1)});
  const Bvh bvh = build_bvh(boxes);
  // Expected shape: the root splits x; each cluster (1 x 11 x 11) splits in y or z into two leaves
  // of two cubes (1 x 1 x 11 each).
  const double root = 101.0 * 11 + 11 * 11 + 11 * 101.0, cluster = 1 * 11 + 11 * 11 + 11 * 1, pair = 1 * 1 + 1 * 11 + 11 * 1;
  const double expected = (root + 2 * cluster + 4 * 2 * pair) / root;
  EXPECT_EQ(bvh.nodes.size(), 3u);
  EXPECT_NEAR(sah_cost(bvh), expected, 1e-6);
  // A single leaf would cost one test a box: the tree is cheaper.
  EXPECT_LT(sah_cost(bvh), double(boxes.size()));
}

TEST(BvhTest, SahCostOfNoTreeIsZero) { EXPECT_EQ(sah_cost(build_bvh({})), 0.0); }

}  // namespace
}  // namespace vkray
