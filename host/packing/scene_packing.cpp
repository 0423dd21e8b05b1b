#include "packing/scene_packing.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>

#include "base/check.h"
#include "scene/camera.h"

namespace vkray::gpu {
namespace {

float bits(uint32_t v) { return std::bit_cast<float>(v); }

// The word holding the children's high sides along `axis`: byte c of (lo.x, lo.y, lo.z, hi.x) in
// texel 2 and of (hi.y, hi.z) in texel 3 (shaders/shared/types.h).
template <typename Texel>
auto* hi_word(Texel* node, int axis) {
  return axis == 0 ? &node[2].w : &node[3][axis - 1];
}

// Corner q (0..255) of a quantized box along one axis, computed as the shader does. q * scale is
// exact (8 bits times a power of two), so fused or not, the sum is rounded once.
float dequantize(float origin, float scale, uint32_t q) { return origin + float(q) * scale; }

// The smallest power of two `scale` with 254 * scale >= extent: a box side spans at most 254 steps,
// leaving one step of room for rounding outward. Returned as a biased float exponent (1..254).
uint32_t scale_exponent(double extent) {
  int e = -126;
  if (extent > 0) {
    std::frexp(extent / 254.0, &e);  // extent / 254 = m * 2^e, m in [0.5, 1): 2^e >= extent / 254
    e = std::clamp(e, -126, 127);
  }
  return uint32_t(e + 127);
}

class NodePacker {
 public:
  explicit NodePacker(const Bvh& bvh) : bvh_(bvh) {}

  std::vector<glm::uvec4> pack() {
    if (!bvh_.nodes.empty()) emit(0);
    return std::move(texels_);
  }

 private:
  struct Child {
    uint32_t link;
    Aabb box;
  };

  // Writes the wide node for binary node `index` (and, first, the wide nodes below it); returns its
  // index. The root is 0, which is why 0 can mean "no child".
  uint32_t emit(uint32_t index) {
    const uint32_t wide = uint32_t(texels_.size() / VKRAY_TEXELS_PER_NODE);
    texels_.resize(texels_.size() + VKRAY_TEXELS_PER_NODE);
    Child children[VKRAY_NODE_WIDTH];
    int count = 0;
    const BvhNode& node = bvh_.nodes[index];
    for (int c = 0; c < 2; ++c) {
      const uint32_t link = node.link[c];
      if (is_leaf(link)) {
        if (leaf_count(link) > 0) children[count++] = {link, node.child[c]};  // count 0: the empty slot of a one-leaf root
        continue;
      }
      const BvhNode& child = bvh_.nodes[link];
      for (int g = 0; g < 2; ++g)
        if (!is_leaf(child.link[g]) || leaf_count(child.link[g]) > 0) children[count++] = {child.link[g], child.child[g]};
    }
    for (int c = 0; c < count; ++c)
      if (!is_leaf(children[c].link)) children[c].link = emit(children[c].link);
    write(wide, children, count);
    return wide;
  }

  void write(uint32_t wide, const Child* children, int count) {
    Aabb all;
    for (int c = 0; c < count; ++c) all.grow(children[c].box);
    glm::uvec4* t = &texels_[size_t(wide) * VKRAY_TEXELS_PER_NODE];
    uint32_t exponents = 0;
    glm::vec3 scale;
    for (int axis = 0; axis < 3; ++axis) {
      const uint32_t e = scale_exponent(double(all.max[axis]) - double(all.min[axis]));
      exponents |= e << (8 * axis);
      scale[axis] = std::bit_cast<float>(e << 23);
      t[0][axis] = std::bit_cast<uint32_t>(all.min[axis]);
    }
    t[0].w = exponents;
    for (int c = 0; c < count; ++c) {
      t[1][c] = children[c].link;
      for (int axis = 0; axis < 3; ++axis) {
        const float origin = all.min[axis], lo = children[c].box.min[axis], hi = children[c].box.max[axis];
        // Round outward: the largest step at or below lo, the smallest at or above hi.
        uint32_t q_lo = uint32_t(std::clamp(std::floor((double(lo) - origin) / scale[axis]), 0.0, 255.0));
        while (q_lo > 0 && dequantize(origin, scale[axis], q_lo) > lo) --q_lo;
        uint32_t q_hi = uint32_t(std::clamp(std::ceil((double(hi) - origin) / scale[axis]), 0.0, 255.0));
        while (q_hi < 255 && dequantize(origin, scale[axis], q_hi) < hi) ++q_hi;
        VKRAY_CHECK(dequantize(origin, scale[axis], q_hi) >= hi, "BVH node quantization lost a box side");
        set_byte(t[2][axis], c, q_lo);
        set_byte(*hi_word(t, axis), c, q_hi);
      }
    }
  }

  static void set_byte(uint32_t& word, int c, uint32_t value) { word |= value << (8 * c); }

  const Bvh& bvh_;
  std::vector<glm::uvec4> texels_;
};

}  // namespace

std::vector<glm::uvec4> pack_nodes(const Bvh& bvh) { return NodePacker(bvh).pack(); }

Aabb unpack_child_box(const glm::uvec4* node, int c) {
  Aabb box;
  for (int axis = 0; axis < 3; ++axis) {
    const float origin = std::bit_cast<float>(node[0][axis]);
    const float scale = std::bit_cast<float>(((node[0].w >> (8 * axis)) & 0xffu) << 23);
    box.min[axis] = dequantize(origin, scale, (node[2][axis] >> (8 * c)) & 0xffu);
    box.max[axis] = dequantize(origin, scale, (*hi_word(node, axis) >> (8 * c)) & 0xffu);
  }
  return box;
}

uint32_t row_stride(uint32_t rows) {
  if (rows <= 2) return 1;
  uint32_t stride = static_cast<uint32_t>(std::lround(double(rows) * 0.6180339887498949));
  while (std::gcd(stride, rows) != 1) ++stride;  // ends by rows - 1 at the latest
  return stride;
}

FrameUniforms pack_frame(const Scene& scene, uint32_t primitive_count, const ImageSettings& image) {
  FrameUniforms f{};
  const CameraBasis cam = camera_basis(scene.camera, image.height);
  f.origin = glm::vec4(cam.origin, 0.0f);
  f.right = glm::vec4(cam.right, 0.0f);
  f.up = glm::vec4(cam.up, 0.0f);
  f.forward = glm::vec4(cam.forward, cam.focal_px);
  f.background = glm::vec4(scene.background, 0.0f);
  f.ambient = glm::vec4(scene.ambient, 0.0f);
  f.width = image.width;
  f.height = image.height;
  f.samples_per_pixel = image.samples_per_pixel;
  f.primitive_count = primitive_count;
  f.light_count = static_cast<uint32_t>(scene.lights.size());
  const SampleStrata strata = sample_strata(image.samples_per_pixel);
  f.strata_x = strata.x;
  f.strata_y = strata.y;
  f.inv_strata_x = strata.inv_x;
  f.inv_strata_y = strata.inv_y;
  f.inv_samples_per_pixel = 1.0f / static_cast<float>(image.samples_per_pixel);
  f.epsilon = scene.epsilon();
  return f;
}

PackedScene pack_scene(const Scene& scene, const Bvh& bvh) {
  PackedScene packed;
  const size_t triangle_count = scene.triangles.size();
  const bool any_smooth = std::any_of(scene.triangles.begin(), scene.triangles.end(), [](const Triangle& t) { return t.smooth; });
  packed.primitives.reserve(bvh.order.size() * VKRAY_TEXELS_PER_PRIMITIVE);
  if (any_smooth) packed.normals.resize(bvh.order.size() * VKRAY_TEXELS_PER_PRIMITIVE, glm::vec4(0.0f));
  for (size_t slot = 0; slot < bvh.order.size(); ++slot) {
    const uint32_t p = bvh.order[slot];
    if (p < triangle_count) {
      const Triangle& t = scene.triangles[p];
      packed.primitives.emplace_back(t.v[0], bits(t.material | (t.smooth ? VKRAY_PRIM_SMOOTH : 0u)));
      packed.primitives.emplace_back(t.v[1], bits(p));
      packed.primitives.emplace_back(t.v[2], 0.0f);
      if (t.smooth)
        for (size_t k = 0; k < 3; ++k) packed.normals[slot * VKRAY_TEXELS_PER_PRIMITIVE + k] = glm::vec4(t.normals[k], 0.0f);
    } else {
      const Sphere& s = scene.spheres[p - triangle_count];
      packed.primitives.emplace_back(s.center, bits(s.material | VKRAY_PRIM_SPHERE));
      packed.primitives.emplace_back(s.radius, 0.0f, 0.0f, bits(p));
      packed.primitives.emplace_back(0.0f);
    }
  }
  packed.nodes = pack_nodes(bvh);
  for (const Material& m : scene.materials) packed.materials.emplace_back(m.albedo, 0.0f);
  for (const PointLight& l : scene.lights) {
    packed.lights.emplace_back(l.position, 0.0f);
    packed.lights.emplace_back(l.intensity, 0.0f);
  }
  return packed;
}

}  // namespace vkray::gpu
