#include "bvh/bvh.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numeric>
#include <string>

#include "base/check.h"
#include "base/errors.h"
#include "base/interrupt.h"

namespace vkray {
namespace {

constexpr int kBins = 16;
// Past this depth the builder splits at the median, which halves the count at every level, so the
// depth stays below kMaxDepth for any count up to kMaxPrimitives (32 + 27 < 64).
constexpr uint32_t kSahDepth = 32;
// SAH costs, relative to one primitive test.
constexpr float kTraversalCost = 1.0f;
constexpr float kIntersectionCost = 1.0f;

// The bin of a centroid coordinate, always in [0, kBins): scale and lo are finite for the boxes
// build_bvh() accepts, and a NaN (which cannot occur then) would still land in a valid bin.
int bin_of(float coordinate, float lo, float scale) {
  const float b = (coordinate - lo) * scale;
  return b >= 0.0f ? int(std::min(b, float(kBins - 1))) : 0;
}

class Builder {
 public:
  explicit Builder(const std::vector<Aabb>& boxes) : boxes_(boxes), centroids_(boxes.size()) {
    for (size_t i = 0; i < boxes.size(); ++i) centroids_[i] = 0.5f * (boxes[i].min + boxes[i].max);
    bvh_.order.resize(boxes.size());
    std::iota(bvh_.order.begin(), bvh_.order.end(), 0u);
  }

  Bvh build() {
    if (boxes_.empty()) return std::move(bvh_);
    bvh_.nodes.emplace_back();
    const Aabb all = bounds(0, uint32_t(boxes_.size()));
    const uint32_t link = subtree(0, uint32_t(boxes_.size()), all, 1);
    if (is_leaf(link)) {  // everything fits one leaf: a root with one empty child
      bvh_.nodes[0].child[0] = all;
      bvh_.nodes[0].link[0] = link;
      bvh_.nodes[0].link[1] = leaf_link(0, 0);  // count 0: never entered, its box is empty
      bvh_.depth = 1;
    }
    return std::move(bvh_);
  }

 private:
  Aabb bounds(uint32_t begin, uint32_t end) const {
    Aabb b;
    for (uint32_t i = begin; i < end; ++i) b.grow(boxes_[bvh_.order[i]]);
    return b;
  }

  // Builds the subtree over order[begin, end) and returns its link. The root (depth 1) is written
  // into nodes[0]; other inner nodes are appended.
  uint32_t subtree(uint32_t begin, uint32_t end, const Aabb& box, uint32_t depth) {
    throw_if_interrupted();  // one relaxed load a node: a large build stops within milliseconds
    const uint32_t count = end - begin;
    // The GPU's traversal stack is sized for kMaxDepth levels (VKRAY_TRAVERSAL_STACK): deeper would
    // lose nodes silently there.
    VKRAY_CHECK(depth < kMaxDepth, "the BVH grew deeper than the GPU's traversal stack holds");
    VKRAY_CHECK(count >= 1, "the BVH builder made an empty subtree");
    bvh_.depth = std::max(bvh_.depth, depth);
    uint32_t mid = 0;
    if (count <= 2 || !split(begin, end, box, depth, mid)) {
      if (count <= kMaxLeafSize) return leaf_link(begin, count);
      mid = median_split(begin, end);
    }
    const uint32_t index = depth == 1 ? 0 : uint32_t(bvh_.nodes.size());
    if (depth > 1) bvh_.nodes.emplace_back();
    const Aabb left = bounds(begin, mid), right = bounds(mid, end);
    const uint32_t left_link = subtree(begin, mid, left, depth + 1);
    const uint32_t right_link = subtree(mid, end, right, depth + 1);
    BvhNode& node = bvh_.nodes[index];
    node.child[0] = left;
    node.child[1] = right;
    node.link[0] = left_link;
    node.link[1] = right_link;
    return index;
  }

  // Binned SAH over all three axes. Returns false when a leaf is cheaper than any split.
  bool split(uint32_t begin, uint32_t end, const Aabb& box, uint32_t depth, uint32_t& mid) {
    if (depth > kSahDepth) return false;
    Aabb centroid_box;
    for (uint32_t i = begin; i < end; ++i) centroid_box.grow(centroids_[bvh_.order[i]]);
    const uint32_t count = end - begin;
    float best_cost = kIntersectionCost * float(count);  // the cost of a leaf
    int best_axis = -1, best_bin = 0;
    for (int axis = 0; axis < 3; ++axis) {
      const float lo = centroid_box.min[axis], extent = centroid_box.max[axis] - lo;
      if (!(extent > 0.0f)) continue;
      const float scale = float(kBins) / extent;
      std::array<Aabb, kBins> bin_box;
      std::array<uint32_t, kBins> bin_count{};
      for (uint32_t i = begin; i < end; ++i) {
        const uint32_t p = bvh_.order[i];
        const int b = bin_of(centroids_[p][axis], lo, scale);
        bin_box[size_t(b)].grow(boxes_[p]);
        ++bin_count[size_t(b)];
      }
      // Sweep from the right, then from the left, to cost every plane between bins.
      std::array<float, kBins> right_area{};
      std::array<uint32_t, kBins> right_count{};
      Aabb acc;
      uint32_t n = 0;
      for (int b = kBins - 1; b > 0; --b) {
        acc.grow(bin_box[size_t(b)]);
        n += bin_count[size_t(b)];
        right_area[size_t(b)] = acc.half_area();
        right_count[size_t(b)] = n;
      }
      acc = Aabb();
      n = 0;
      const float parent_area = box.half_area();
      for (int b = 0; b < kBins - 1; ++b) {
        acc.grow(bin_box[size_t(b)]);
        n += bin_count[size_t(b)];
        if (n == 0 || right_count[size_t(b + 1)] == 0) continue;
        const float cost = kTraversalCost + kIntersectionCost *
                                                (acc.half_area() * float(n) + right_area[size_t(b + 1)] * float(right_count[size_t(b + 1)])) /
                                                std::max(parent_area, 1e-30f);
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = axis;
          best_bin = b;
        }
      }
    }
    if (best_axis < 0) return false;
    const float lo = centroid_box.min[best_axis];
    const float scale = float(kBins) / (centroid_box.max[best_axis] - lo);
    const auto first = bvh_.order.begin() + begin, last = bvh_.order.begin() + end;
    const auto middle = std::partition(first, last, [&](uint32_t p) {
      return bin_of(centroids_[p][best_axis], lo, scale) <= best_bin;
    });
    mid = uint32_t(middle - bvh_.order.begin());
    return mid != begin && mid != end;
  }

  uint32_t median_split(uint32_t begin, uint32_t end) {
    Aabb centroid_box;
    for (uint32_t i = begin; i < end; ++i) centroid_box.grow(centroids_[bvh_.order[i]]);
    const glm::vec3 extent = centroid_box.max - centroid_box.min;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
    const uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(bvh_.order.begin() + begin, bvh_.order.begin() + mid, bvh_.order.begin() + end,
                     [&](uint32_t a, uint32_t b) { return centroids_[a][axis] < centroids_[b][axis]; });
    return mid;
  }

  const std::vector<Aabb>& boxes_;
  std::vector<glm::vec3> centroids_;
  Bvh bvh_;
};

}  // namespace

Bvh build_bvh(const std::vector<Aabb>& boxes) {
  if (boxes.size() > kMaxScenePrimitives)
    throw LimitError("too many primitives for the BVH: " + std::to_string(boxes.size()) + " (at most " +
                     std::to_string(kMaxScenePrimitives) + ")");
  // The scene keeps every coordinate within kMaxCoordinate (scene/scene.h); a caller that does not
  // would make the SAH's sums overflow. Refused here too, so no input reaches the arithmetic below.
  for (size_t i = 0; i < boxes.size(); ++i)
    for (int axis = 0; axis < 3; ++axis)
      if (!(boxes[i].min[axis] <= boxes[i].max[axis] && std::abs(boxes[i].min[axis]) <= kMaxCoordinate &&
            std::abs(boxes[i].max[axis]) <= kMaxCoordinate))
        throw LimitError("primitive " + std::to_string(i) + "'s bounds lie outside the coordinates vkray renders (+-1e9)");
  const auto start = std::chrono::steady_clock::now();
  Bvh bvh = Builder(boxes).build();
  bvh.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return bvh;
}

std::vector<Aabb> primitive_boxes(const Scene& scene) {
  std::vector<Aabb> boxes;
  boxes.reserve(scene.triangles.size() + scene.spheres.size());
  for (const Triangle& t : scene.triangles) {
    Aabb& b = boxes.emplace_back();
    for (const glm::vec3& v : t.v) b.grow(v);
  }
  for (const Sphere& s : scene.spheres) boxes.push_back({s.center - s.radius, s.center + s.radius});
  return boxes;
}

}  // namespace vkray
