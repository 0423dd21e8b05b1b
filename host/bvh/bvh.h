// A bounding volume hierarchy over the scene's primitives, built on the host with binned SAH (in
// parallel, with Intel oneTBB) and binary nodes that hold both children's boxes. The CPU reference traverses it as it is; the GPU
// path reads a 4-wide, quantized copy of it (packing/scene_packing.h).
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"
#include "shared/scene_layout.h"

namespace vkray {

struct Aabb {
  glm::vec3 min{1e30f};
  glm::vec3 max{-1e30f};  // empty: min > max
  void grow(const glm::vec3& p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
  void grow(const Aabb& b) {
    min = glm::min(min, b.min);
    max = glm::max(max, b.max);
  }
  float half_area() const {
    const glm::vec3 d = glm::max(max - min, glm::vec3(0.0f));
    return d.x * d.y + d.y * d.z + d.z * d.x;
  }
};

// A child link: an inner node's index, or a leaf naming its first primitive in Bvh::order and its
// count, 1..kMaxLeafSize. The encoding is the one the shader decodes (shared/scene_layout.h).
using gpu::is_leaf;
using gpu::leaf_count;
using gpu::leaf_first;
using gpu::leaf_link;
constexpr uint32_t kMaxLeafSize = (1u << VKRAY_LEAF_COUNT_BITS) - 1;
constexpr uint32_t kMaxPrimitives = 1u << (31 - VKRAY_LEAF_COUNT_BITS);
static_assert(kMaxScenePrimitives == kMaxPrimitives - 1, "the scene's limit is the leaf encoding's");
// The builder keeps the depth (levels of inner nodes) below this; the GPU's traversal stack is sized
// for it (VKRAY_TRAVERSAL_STACK).
constexpr uint32_t kMaxDepth = 64;

struct BvhNode {
  Aabb child[2];
  uint32_t link[2] = {0, 0};
};

struct Bvh {
  std::vector<BvhNode> nodes;   // nodes[0] is the root; empty when there are no primitives
  std::vector<uint32_t> order;  // order[i]: the original index of the i-th primitive in leaf order
  uint32_t depth = 0;           // levels of inner nodes
  double build_seconds = 0;
};

// Builds over primitives given by their bounding boxes, on `threads` threads (0: one per hardware
// thread). The tree is the same for any number of threads. Throws LimitError beyond
// kMaxScenePrimitives, and Cancelled on an interrupt request (base/interrupt.h) or once `stop` is
// set, within milliseconds.
// `max_leaf`: the most primitives a leaf holds (the instances' BVH holds one instance a leaf, so that
// a ray enters only those whose box it meets).
Bvh build_bvh(const std::vector<Aabb>& boxes, unsigned threads = 0, const std::atomic<bool>* stop = nullptr,
              uint32_t max_leaf = kMaxLeafSize);

// The tree's SAH cost: the expected cost of a ray through it, in primitive tests (a traversal step
// costs as much as one), by surface area: every inner node weighted by its area, every leaf by its
// area times its count, over the root's area. Lower is a better tree.
double sah_cost(const Bvh& bvh);

// The boxes of a scene's own primitives, triangles first, then spheres: box i < triangles.size()
// is triangles[i]'s, the rest are spheres[i - triangles.size()]'s (PrimitiveNumbering puts the
// instances' triangles between the two).
std::vector<Aabb> primitive_boxes(const Scene& scene);

// A scene's whole structure: a BVH over its own primitives (primitive_boxes) and, where it places
// meshes by instances, one over each mesh's triangles in the mesh's space and one over the
// instances' world boxes (its Bvh::order names Scene::instances). Both renderers walk the two levels,
// each its own way.
struct SceneBvh {
  Bvh primitives;
  std::vector<Bvh> meshes;  // one per Scene::meshes
  Bvh instances;            // empty when the scene has none
  double build_seconds = 0;
};

// Builds all of them (threads and stop as build_bvh's).
SceneBvh build_scene_bvh(const Scene& scene, unsigned threads = 0, const std::atomic<bool>* stop = nullptr);

// The world box of each of the scene's instances: its mesh's box (the root's children's, in `meshes`)
// with every corner moved by the instance's transform.
std::vector<Aabb> instance_boxes(const Scene& scene, const std::vector<Bvh>& meshes);

}  // namespace vkray
