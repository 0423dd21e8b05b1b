#include "bvh/bvh.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cfloat>
#include <cmath>
#include <memory>
#include <string>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

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
// A range smaller than this is built by one task; a larger one is split by the parallel top part of
// the build, which hands its two halves to two tasks.
constexpr uint32_t kTaskSize = 4096;
// A range of at least two of these blocks bins its primitives block by block in parallel.
constexpr uint32_t kBinBlock = 32768;
// From this many primitives on, binning sets every bin up front rather than at its first primitive.
constexpr uint32_t kDenseBinning = 64;

// Throws Cancelled on an interrupt request or when the caller's `stop` is set.
void check_stop(const std::atomic<bool>* stop) {
  throw_if_interrupted();
  if (stop && stop->load(std::memory_order_relaxed)) throw Cancelled();
}

// A primitive's box and its index in the caller's list; the builder reorders these in place.
struct PrimRef {
  Aabb box;
  uint32_t index;
  glm::vec3 centroid() const { return 0.5f * (box.min + box.max); }
};

// primitives[begin, end) with the bounds of their boxes and of their centroids.
struct Range {
  uint32_t begin = 0, end = 0;
  Aabb box, centroids;
  uint32_t count() const { return end - begin; }
};

// The bin of a centroid coordinate, always in [0, kBins): scale and lo are finite for the boxes
// build_bvh() accepts, and a NaN (which cannot occur then) would still land in a valid bin.
int bin_of(float coordinate, float lo, float scale) {
  const float b = (coordinate - lo) * scale;
  return b >= 0.0f ? int(std::min(b, float(kBins - 1))) : 0;
}

// Four floats in one SSE register where there is SSE, four in a row elsewhere: the binning loop
// below, on x, y, z (and a fourth lane it ignores) at once. Each operation rounds exactly as its
// scalar counterpart, so the bins are the same either way.
#if defined(__SSE2__)
struct Float4 {
  __m128 v;
  static Float4 load(const float* p) { return {_mm_loadu_ps(p)}; }  // reads p[0..3]
  // x, y, z of a vec3 that is followed by 4 more bytes of its struct (read, then zeroed: an index's
  // bits there would be a denormal float, slow in every operation on some CPUs).
  static Float4 load3(const glm::vec3& v) {
    return {_mm_and_ps(_mm_loadu_ps(&v.x), _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1)))};
  }
  static Float4 splat(float x) { return {_mm_set1_ps(x)}; }
  friend Float4 operator+(Float4 a, Float4 b) { return {_mm_add_ps(a.v, b.v)}; }
  friend Float4 operator-(Float4 a, Float4 b) { return {_mm_sub_ps(a.v, b.v)}; }
  friend Float4 operator*(Float4 a, Float4 b) { return {_mm_mul_ps(a.v, b.v)}; }
  friend Float4 min4(Float4 a, Float4 b) { return {_mm_min_ps(a.v, b.v)}; }
  friend Float4 max4(Float4 a, Float4 b) { return {_mm_max_ps(a.v, b.v)}; }
  // bin_of() on each lane: clamped to [0, kBins - 1], NaN to 0.
  std::array<int32_t, 4> bins() const {
    const __m128 clamped = _mm_min_ps(_mm_max_ps(v, _mm_setzero_ps()), _mm_set1_ps(float(kBins - 1)));
    std::array<int32_t, 4> out;
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out.data()), _mm_cvttps_epi32(clamped));
    return out;
  }
  glm::vec3 xyz() const {
    alignas(16) float f[4];
    _mm_store_ps(f, v);
    return {f[0], f[1], f[2]};
  }
};
#else
struct Float4 {
  std::array<float, 4> v;
  static Float4 load(const float* p) { return {{p[0], p[1], p[2], p[3]}}; }
  static Float4 load3(const glm::vec3& v) { return {{v.x, v.y, v.z, 0.0f}}; }
  static Float4 splat(float x) { return {{x, x, x, x}}; }
  template <typename Op>
  static Float4 each(Float4 a, Float4 b, Op op) {
    return {{op(a.v[0], b.v[0]), op(a.v[1], b.v[1]), op(a.v[2], b.v[2]), op(a.v[3], b.v[3])}};
  }
  friend Float4 operator+(Float4 a, Float4 b) { return each(a, b, [](float x, float y) { return x + y; }); }
  friend Float4 operator-(Float4 a, Float4 b) { return each(a, b, [](float x, float y) { return x - y; }); }
  friend Float4 operator*(Float4 a, Float4 b) { return each(a, b, [](float x, float y) { return x * y; }); }
  friend Float4 min4(Float4 a, Float4 b) { return each(a, b, [](float x, float y) { return x < y ? x : y; }); }
  friend Float4 max4(Float4 a, Float4 b) { return each(a, b, [](float x, float y) { return x > y ? x : y; }); }
  std::array<int32_t, 4> bins() const {
    std::array<int32_t, 4> out;
    for (int i = 0; i < 4; ++i) out[size_t(i)] = bin_of(v[size_t(i)], 0.0f, 1.0f);
    return out;
  }
  glm::vec3 xyz() const { return {v[0], v[1], v[2]}; }
};
#endif

// Maps centroids to bins along each axis of a range's centroid bounds. An axis along which every
// centroid is the same gets scale 0 (all in bin 0) and is never split.
struct BinMap {
  glm::vec4 lo, scale;  // w: 0, for the fourth lane of a Float4
  explicit BinMap(const Aabb& centroids) : lo(centroids.min, 0.0f), scale(0.0f) {
    for (int axis = 0; axis < 3; ++axis) {
      const float extent = centroids.max[axis] - lo[axis];
      if (extent > 0.0f) scale[axis] = float(kBins) / extent;
    }
  }
};

// A bin's bounds, of the boxes and of the centroids, in Float4 lanes x, y, z. Set by the first
// primitive to fall in it: a bin whose count is 0 holds no bounds at all.
struct BinBounds {
  Float4 min, max, centroid_min, centroid_max;
  void set(Float4 box_min, Float4 box_max, Float4 centroid) {
    min = box_min;
    max = box_max;
    centroid_min = centroid_max = centroid;
  }
  void grow(Float4 box_min, Float4 box_max, Float4 c_min, Float4 c_max) {
    min = min4(min, box_min);
    max = max4(max, box_max);
    centroid_min = min4(centroid_min, c_min);
    centroid_max = max4(centroid_max, c_max);
  }
  Aabb box() const { return {min.xyz(), max.xyz()}; }
  Aabb centroids() const { return {centroid_min.xyz(), centroid_max.xyz()}; }
  static BinBounds empty() {
    const Float4 big = Float4::splat(1e30f), small = Float4::splat(-1e30f);
    return {big, small, big, small};
  }
};

// Every primitive of a range counted into the bins of all three axes in one pass. Merging is exact
// (a union of boxes, a sum of counts), so the bins are the same however the range is cut up.
struct Bins {
  std::array<std::array<BinBounds, kBins>, 3> bounds;  // left unset: most bins of a small range stay empty
  std::array<std::array<uint32_t, kBins>, 3> count{};
  bool dense = false;  // every bin's bounds set, empty ones to BinBounds::empty()

  void add(const PrimRef* refs, uint32_t begin, uint32_t end, const BinMap& map) {
    if (end - begin < kDenseBinning && !dense) return add<false>(refs, begin, end, map);
    // Many primitives: every bin's bounds set to empty first (a union with them changes nothing), so
    // that the loop grows them without a branch.
    if (!dense) {
      for (size_t a = 0; a < 3; ++a)
        for (size_t b = 0; b < kBins; ++b)
          if (count[a][b] == 0) bounds[a][b] = BinBounds::empty();
      dense = true;
    }
    add<true>(refs, begin, end, map);
  }
  template <bool kDense>
  void add(const PrimRef* refs, uint32_t begin, uint32_t end, const BinMap& map) {
    const Float4 lo = Float4::load(&map.lo.x), scale = Float4::load(&map.scale.x), half = Float4::splat(0.5f);
    for (uint32_t i = begin; i < end; ++i) {
      const Float4 box_min = Float4::load3(refs[i].box.min), box_max = Float4::load3(refs[i].box.max);
      const Float4 centroid = half * (box_min + box_max);
      const std::array<int32_t, 4> bin = ((centroid - lo) * scale).bins();
      for (size_t a = 0; a < 3; ++a) {
        const size_t b = size_t(bin[a]);
        if (count[a][b]++ == 0 && !kDense)
          bounds[a][b].set(box_min, box_max, centroid);
        else
          bounds[a][b].grow(box_min, box_max, centroid, centroid);
      }
    }
  }
  void merge(const Bins& other) {
    for (size_t a = 0; a < 3; ++a)
      for (size_t b = 0; b < kBins; ++b) {
        if (other.count[a][b] == 0) continue;
        const BinBounds& theirs = other.bounds[a][b];
        if (count[a][b] == 0)
          bounds[a][b] = theirs;
        else
          bounds[a][b].grow(theirs.min, theirs.max, theirs.centroid_min, theirs.centroid_max);
        count[a][b] += other.count[a][b];
      }
  }
};

// Bounds grown box by box in Float4 lanes, with Aabb::half_area()'s arithmetic.
struct SweepBox {
  Float4 min = Float4::splat(1e30f), max = Float4::splat(-1e30f);
  void grow(const BinBounds& b) {
    min = min4(min, b.min);
    max = max4(max, b.max);
  }
  // Aabb::half_area()'s sum in the same order (a side of -0 where glm's max keeps -0 gives +0
  // here, which changes no sum's value).
  float half_area() const {
    const glm::vec3 d = max4(max - min, Float4::splat(0.0f)).xyz();
    return d.x * d.y + d.y * d.z + d.z * d.x;
  }
};

// Fills `bins` (which the caller keeps, to spare a copy of a few kB a node).
void bin_range(const PrimRef* refs, const Range& range, const BinMap& map, Bins& bins) {
  if (range.count() < 2 * kBinBlock) {
    bins.add(refs, range.begin, range.end, map);
    return;
  }
  bins = tbb::parallel_reduce(
      tbb::blocked_range<uint32_t>(range.begin, range.end, kBinBlock), Bins(),
      [&](const tbb::blocked_range<uint32_t>& block, Bins block_bins) {
        block_bins.add(refs, block.begin(), block.end(), map);
        return block_bins;
      },
      [](Bins a, const Bins& b) {
        a.merge(b);
        return a;
      });
}

// The bounds of primitives[begin, end) and of their centroids, for ranges not cut along bins.
void bound(const PrimRef* refs, Range& range) {
  range.box = range.centroids = Aabb();
  for (uint32_t i = range.begin; i < range.end; ++i) {
    range.box.grow(refs[i].box);
    range.centroids.grow(refs[i].centroid());
  }
}

// Bit b set for each bin b that holds something.
uint32_t filled_bins(const std::array<uint32_t, kBins>& counts) {
#if defined(__SSE2__)
  uint32_t filled = 0;
  for (int q = 0; q < kBins / 4; ++q) {
    const __m128i four = _mm_loadu_si128(reinterpret_cast<const __m128i*>(&counts[size_t(4 * q)]));
    const __m128i empty = _mm_cmpeq_epi32(four, _mm_setzero_si128());
    filled |= uint32_t(~_mm_movemask_ps(_mm_castsi128_ps(empty)) & 0xf) << (4 * q);
  }
  return filled;
#else
  uint32_t filled = 0;
  for (int b = 0; b < kBins; ++b) filled |= uint32_t(counts[size_t(b)] > 0) << b;
  return filled;
#endif
}

// Puts the primitives whose centroid falls in bins [0, last_left] of `axis` first, as std::partition
// does (the same order as before the builder was rewritten); returns where the right side begins.
// The axis is a template argument so that reading a centroid's coordinate compiles to a load.
template <int kAxis>
uint32_t partition_on(PrimRef* refs, const Range& range, const BinMap& map, int last_left) {
  const float lo = map.lo[kAxis], scale = map.scale[kAxis];
  return uint32_t(std::partition(refs + range.begin, refs + range.end, [&](const PrimRef& p) {
                    return bin_of(0.5f * (p.box.min[kAxis] + p.box.max[kAxis]), lo, scale) <= last_left;
                  }) -
                  refs);
}

uint32_t partition(PrimRef* refs, const Range& range, const BinMap& map, int axis, int last_left) {
  switch (axis) {
    case 0: return partition_on<0>(refs, range, map, last_left);
    case 1: return partition_on<1>(refs, range, map, last_left);
    default: return partition_on<2>(refs, range, map, last_left);
  }
}

// Splits a range in two, by binned SAH over all three axes or, past kSahDepth or where SAH finds
// no split cheaper than a leaf too large for the leaf encoding, at the median. Returns false where
// the range becomes a leaf.
bool split(PrimRef* refs, const Range& range, uint32_t depth, uint32_t max_leaf, Range& left, Range& right) {
  const uint32_t count = range.count();
  if (count <= std::min(2u, max_leaf)) return false;
  if (depth <= kSahDepth) {
    const BinMap map(range.centroids);
    Bins bins;
    bin_range(refs, range, map, bins);
    // The cost of a leaf; where the range is too large for one, any split is better.
    float best_cost = count <= max_leaf ? kIntersectionCost * float(count) : FLT_MAX;
    int best_axis = -1, best_bin = 0;
    const float parent_area = std::max(range.box.half_area(), 1e-30f);
    for (int axis = 0; axis < 3; ++axis) {
      if (map.scale[axis] == 0.0f) continue;
      const auto& bounds = bins.bounds[size_t(axis)];
      const auto& counts = bins.count[size_t(axis)];
      // Sweep from the right, then from the left, to cost every plane between bins. A plane after
      // an empty bin costs what the plane before it did, so it never wins: only the bins that hold
      // something are visited, as the bits of `filled`.
      const uint32_t filled = filled_bins(counts);
      std::array<float, kBins> right_area;     // of bins b.. for a filled bin b > 0
      std::array<uint32_t, kBins> right_count;
      SweepBox acc;
      uint32_t n = 0;
      for (uint32_t m = filled & ~1u; m != 0;) {
        const int b = 31 - std::countl_zero(m);
        m &= ~(1u << b);
        acc.grow(bounds[size_t(b)]);
        n += counts[size_t(b)];
        right_area[size_t(b)] = acc.half_area();
        right_count[size_t(b)] = n;
      }
      acc = SweepBox();
      n = 0;
      for (uint32_t m = filled; m != 0;) {
        const int b = std::countr_zero(m);
        m &= m - 1;
        if (m == 0) break;  // the last filled bin: nothing to its right
        const size_t next = size_t(std::countr_zero(m));
        acc.grow(bounds[size_t(b)]);
        n += counts[size_t(b)];
        const float cost = kTraversalCost + kIntersectionCost * (acc.half_area() * float(n) + right_area[next] * float(right_count[next])) /
                                                parent_area;
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = axis;
          best_bin = b;
        }
      }
    }
    if (best_axis >= 0) {
      const uint32_t mid = partition(refs, range, map, best_axis, best_bin);
      if (mid != range.begin && mid != range.end) {
        left = {range.begin, mid, {}, {}};
        right = {mid, range.end, {}, {}};
        BinBounds sides[2];  // the union of the bins on each side, set by the first
        bool empty[2] = {true, true};
        for (uint32_t m = filled_bins(bins.count[size_t(best_axis)]); m != 0; m &= m - 1) {
          const int b = std::countr_zero(m);
          const BinBounds& bin = bins.bounds[size_t(best_axis)][size_t(b)];
          const int side = b <= best_bin ? 0 : 1;
          if (empty[side])
            sides[side] = bin;
          else
            sides[side].grow(bin.min, bin.max, bin.centroid_min, bin.centroid_max);
          empty[side] = false;
        }
        left.box = sides[0].box();
        left.centroids = sides[0].centroids();
        right.box = sides[1].box();
        right.centroids = sides[1].centroids();
        return true;
      }
    }
  }
  if (count <= max_leaf) return false;
  // The median along the centroids' longest axis.
  const glm::vec3 extent = range.centroids.max - range.centroids.min;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
  const uint32_t mid = range.begin + count / 2;
  std::nth_element(refs + range.begin, refs + mid, refs + range.end,
                   [&](const PrimRef& a, const PrimRef& b) { return a.centroid()[axis] < b.centroid()[axis]; });
  left = {range.begin, mid, {}, {}};
  right = {mid, range.end, {}, {}};
  bound(refs, left);
  bound(refs, right);
  return true;
}

// The work of one task: the subtree over a range, its nodes numbered from 0 in depth-first order,
// parent before children and left before right.
class SubtreeBuilder {
 public:
  SubtreeBuilder(PrimRef* refs, const std::atomic<bool>* stop, uint32_t max_leaf) : refs_(refs), stop_(stop), max_leaf_(max_leaf) {}

  // Returns the subtree's link: a leaf, or 0 for nodes()[0].
  uint32_t build(const Range& range, uint32_t depth) {
    check_stop(stop_);  // two relaxed loads a node: a large build stops within milliseconds
    // The GPU's traversal stack is sized for kMaxDepth levels (VKRAY_TRAVERSAL_STACK): deeper would
    // lose nodes silently there.
    VKRAY_CHECK(depth < kMaxDepth, "the BVH grew deeper than the GPU's traversal stack holds");
    VKRAY_CHECK(range.count() >= 1, "the BVH builder made an empty subtree");
    depth_ = std::max(depth_, depth);
    Range left, right;
    if (!split(refs_, range, depth, max_leaf_, left, right)) return leaf_link(range.begin, range.count());
    const uint32_t index = uint32_t(nodes_.size());
    nodes_.emplace_back();
    const uint32_t left_link = build(left, depth + 1);
    const uint32_t right_link = build(right, depth + 1);
    nodes_[index] = {{left.box, right.box}, {left_link, right_link}};
    return index;
  }

  std::vector<BvhNode>& nodes() { return nodes_; }
  uint32_t depth() const { return depth_; }

 private:
  PrimRef* refs_;
  const std::atomic<bool>* stop_;
  uint32_t max_leaf_;
  std::vector<BvhNode> nodes_;
  uint32_t depth_ = 0;
};

// The parallel build: ranges of kTaskSize or more become nodes of a small top tree, each splitting
// its range (binning in parallel where large) and building its halves in two tasks; smaller ranges
// become subtrees of their own. Numbering them all at the end, the top in depth-first order and
// each subtree's nodes shifted to where that order puts them, gives the tree a single thread would
// have built, node for node, whatever the number of threads.
class ParallelBuilder {
 public:
  ParallelBuilder(PrimRef* refs, const std::atomic<bool>* stop, uint32_t max_leaf) : refs_(refs), stop_(stop), max_leaf_(max_leaf) {}

  Bvh build(const Range& all) {
    Bvh bvh;
    const Part root = part(all, 1);
    bvh.depth = root.depth;
    if (!root.top && root.nodes.empty()) {  // everything fits one leaf: a root with one empty child
      bvh.nodes.resize(1);
      bvh.nodes[0].child[0] = all.box;
      bvh.nodes[0].link[0] = root.link;
      bvh.nodes[0].link[1] = leaf_link(0, 0);  // count 0: never entered, its box is empty
      return bvh;
    }
    bvh.nodes.resize(root.node_count);
    std::vector<std::pair<uint32_t, const Part*>> subtrees;  // where each subtree's nodes go
    uint32_t next = 0;
    place(root, bvh.nodes, next, subtrees);
    const auto copy = [&](size_t s) {
      const auto [base, subtree] = subtrees[s];
      for (size_t i = 0; i < subtree->nodes.size(); ++i) {
        BvhNode node = subtree->nodes[i];
        for (uint32_t& link : node.link)
          if (!is_leaf(link)) link += base;
        bvh.nodes[base + i] = node;
      }
    };
    if (subtrees.size() > 1)
      tbb::parallel_for(size_t(0), subtrees.size(), copy);
    else if (!subtrees.empty())
      copy(0);  // a small tree, built on the caller's thread: so is its copy
    return bvh;
  }

 private:
  // A node of the top tree, or a subtree built by one task (link: a leaf, or 0 for nodes[0]).
  struct Part {
    Aabb box;
    std::unique_ptr<std::array<Part, 2>> top;
    std::vector<BvhNode> nodes;
    uint32_t link = 0;
    uint32_t depth = 0;       // the deepest level in it
    uint32_t node_count = 0;  // inner nodes in it
  };

  Part part(const Range& range, uint32_t depth) {
    Part p;
    p.box = range.box;
    if (range.count() < kTaskSize) {
      SubtreeBuilder subtree(refs_, stop_, max_leaf_);
      p.link = subtree.build(range, depth);
      p.nodes = std::move(subtree.nodes());
      p.depth = subtree.depth();
      p.node_count = uint32_t(p.nodes.size());
      return p;
    }
    check_stop(stop_);
    VKRAY_CHECK(depth < kMaxDepth, "the BVH grew deeper than the GPU's traversal stack holds");
    Range left, right;
    // kTaskSize > kMaxLeafSize: a range this large always splits.
    VKRAY_CHECK(split(refs_, range, depth, max_leaf_, left, right), "the BVH builder left a large range unsplit");
    p.top = std::make_unique<std::array<Part, 2>>();
    tbb::parallel_invoke([&] { (*p.top)[0] = part(left, depth + 1); }, [&] { (*p.top)[1] = part(right, depth + 1); });
    p.depth = std::max((*p.top)[0].depth, (*p.top)[1].depth);
    p.node_count = 1 + (*p.top)[0].node_count + (*p.top)[1].node_count;
    return p;
  }

  // Numbers a part's nodes from `next` on in depth-first order and returns its link: top nodes are
  // written here, subtrees are listed to be copied.
  static uint32_t place(const Part& p, std::vector<BvhNode>& nodes, uint32_t& next,
                        std::vector<std::pair<uint32_t, const Part*>>& subtrees) {
    if (!p.top) {
      if (p.nodes.empty()) return p.link;
      subtrees.emplace_back(next, &p);
      next += uint32_t(p.nodes.size());
      return next - uint32_t(p.nodes.size());
    }
    const uint32_t index = next++;
    const uint32_t left = place((*p.top)[0], nodes, next, subtrees);
    const uint32_t right = place((*p.top)[1], nodes, next, subtrees);
    nodes[index] = {{(*p.top)[0].box, (*p.top)[1].box}, {left, right}};
    return index;
  }

  PrimRef* refs_;
  const std::atomic<bool>* stop_;
  uint32_t max_leaf_;
};

}  // namespace

Bvh build_bvh(const std::vector<Aabb>& boxes, unsigned threads, const std::atomic<bool>* stop, uint32_t max_leaf) {
  VKRAY_CHECK(max_leaf >= 1 && max_leaf <= kMaxLeafSize, "a BVH leaf size out of range");
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
  Bvh bvh;
  if (!boxes.empty()) {
    const uint32_t count = uint32_t(boxes.size());
    std::vector<PrimRef> refs(count);
    Range all{0, count, {}, {}};
    // Small inputs stay on this thread: starting oneTBB's workers costs more than their build.
    const bool parallel = count >= kTaskSize;
    const auto for_each_block = [&](auto&& body) {
      if (parallel)
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, count, kBinBlock), [&](const tbb::blocked_range<uint32_t>& block) {
          body(block.begin(), block.end());
        });
      else
        body(0u, count);
    };
    const auto build = [&] {
      for_each_block([&](uint32_t begin, uint32_t end) {
        // + 0.0f turns -0 into +0: SSE's min and max pick between zeros of either sign by operand
        // order, so without it a node box's zero could take either sign, whatever the thread count.
        for (uint32_t i = begin; i < end; ++i) refs[i] = {{boxes[i].min + 0.0f, boxes[i].max + 0.0f}, i};
      });
      bound(refs.data(), all);
      bvh = ParallelBuilder(refs.data(), stop, max_leaf).build(all);
      bvh.order.resize(count);
      for_each_block([&](uint32_t begin, uint32_t end) {
        for (uint32_t i = begin; i < end; ++i) bvh.order[i] = refs[i].index;
      });
    };
    if (parallel) {
      tbb::task_arena arena(threads > 0 ? int(threads) : tbb::task_arena::automatic);
      arena.execute(build);
    } else {
      build();
    }
  }
  bvh.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return bvh;
}

double sah_cost(const Bvh& bvh) {
  if (bvh.nodes.empty()) return 0;
  double cost = 0;
  const auto area = [](const Aabb& b) { return double(b.half_area()); };
  Aabb root;
  for (const Aabb& b : bvh.nodes[0].child) root.grow(b);
  for (const BvhNode& node : bvh.nodes) {
    Aabb box;
    for (int c = 0; c < 2; ++c) {
      box.grow(node.child[c]);
      if (is_leaf(node.link[c])) cost += double(kIntersectionCost) * leaf_count(node.link[c]) * area(node.child[c]);
    }
    cost += double(kTraversalCost) * area(box);
  }
  return cost / std::max(area(root), 1e-30);
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

namespace vkray {

std::vector<Aabb> instance_boxes(const Scene& scene, const std::vector<Bvh>& meshes) {
  std::vector<Aabb> boxes;
  boxes.reserve(scene.instances.size());
  for (const Instance& instance : scene.instances) {
    const Bvh& mesh = meshes[instance.mesh];
    VKRAY_CHECK(!mesh.nodes.empty(), "an instance places a mesh without triangles");
    Aabb local = mesh.nodes[0].child[0];
    if (leaf_count(mesh.nodes[0].link[1]) > 0 || !is_leaf(mesh.nodes[0].link[1])) local.grow(mesh.nodes[0].child[1]);
    // In double, then rounded outward by a float step: the box holds every vertex as the GPU moves
    // the ray, whatever the rounding.
    Aabb& world = boxes.emplace_back();
    const glm::dmat4 m(instance.to_world);
    for (int corner = 0; corner < 8; ++corner) {
      const glm::dvec3 p((corner & 1) ? local.max.x : local.min.x, (corner & 2) ? local.max.y : local.min.y,
                         (corner & 4) ? local.max.z : local.min.z);
      const glm::dvec3 q(m * glm::dvec4(p, 1.0));
      // (Held within the coordinates vkray renders, where the loader holds every placed corner.)
      for (int a = 0; a < 3; ++a) {
        world.min[a] = std::min(world.min[a], std::max(std::nextafter(float(q[a]), -FLT_MAX), -kMaxCoordinate));
        world.max[a] = std::max(world.max[a], std::min(std::nextafter(float(q[a]), FLT_MAX), kMaxCoordinate));
      }
    }
  }
  return boxes;
}

SceneBvh build_scene_bvh(const Scene& scene, unsigned threads, const std::atomic<bool>* stop) {
  SceneBvh bvh;
  bvh.primitives = build_bvh(primitive_boxes(scene), threads, stop);
  bvh.build_seconds = bvh.primitives.build_seconds;
  bvh.meshes.reserve(scene.meshes.size());
  for (const SharedMesh& mesh : scene.meshes) {
    std::vector<Aabb> boxes;
    boxes.reserve(mesh.triangles.size());
    for (const Triangle& t : mesh.triangles) {
      Aabb& b = boxes.emplace_back();
      for (const glm::vec3& v : t.v) b.grow(v);
    }
    bvh.meshes.push_back(build_bvh(boxes, threads, stop));
    bvh.build_seconds += bvh.meshes.back().build_seconds;
  }
  if (!scene.instances.empty()) {
    if (scene.instances.size() > kMaxInstances)
      throw LimitError("too many instances: " + std::to_string(scene.instances.size()) + " (at most " + std::to_string(kMaxInstances) + ")");
    bvh.instances = build_bvh(instance_boxes(scene, bvh.meshes), threads, stop, 1);
    bvh.build_seconds += bvh.instances.build_seconds;
  }
  return bvh;
}

}  // namespace vkray
