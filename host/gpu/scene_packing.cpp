#include "gpu/scene_packing.h"

#include <algorithm>
#include <bit>

#include "camera.h"

namespace vkray::gpu {
namespace {

float bits(uint32_t v) { return std::bit_cast<float>(v); }

}  // namespace

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
  packed.nodes.reserve(bvh.nodes.size() * VKRAY_TEXELS_PER_NODE);
  for (const BvhNode& n : bvh.nodes) {
    packed.nodes.emplace_back(n.child[0].min, bits(n.link[0]));
    packed.nodes.emplace_back(n.child[0].max, bits(n.link[1]));
    packed.nodes.emplace_back(n.child[1].min, 0.0f);
    packed.nodes.emplace_back(n.child[1].max, 0.0f);
  }
  for (const Material& m : scene.materials) packed.materials.emplace_back(m.albedo, 0.0f);
  for (const PointLight& l : scene.lights) {
    packed.lights.emplace_back(l.position, 0.0f);
    packed.lights.emplace_back(l.intensity, 0.0f);
  }
  return packed;
}

}  // namespace vkray::gpu
