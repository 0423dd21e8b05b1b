#include "gpu/scene_packing.h"

#include <algorithm>
#include <bit>

#include "camera.h"

namespace vkray::gpu {
namespace {

float bits(uint32_t v) { return std::bit_cast<float>(v); }

}  // namespace

PackedScene pack_scene(const Scene& scene, const ImageSettings& image) {
  PackedScene packed;
  FrameUniforms& f = packed.frame;
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
  f.triangle_count = static_cast<uint32_t>(scene.triangles.size());
  f.sphere_count = static_cast<uint32_t>(scene.spheres.size());
  f.light_count = static_cast<uint32_t>(scene.lights.size());
  const SampleStrata strata = sample_strata(image.samples_per_pixel);
  f.strata_x = strata.x;
  f.strata_y = strata.y;
  f.inv_strata_x = strata.inv_x;
  f.inv_strata_y = strata.inv_y;
  f.inv_samples_per_pixel = 1.0f / static_cast<float>(image.samples_per_pixel);
  f.epsilon = scene.epsilon();

  packed.triangles.reserve(scene.triangles.size() * VKRAY_TEXELS_PER_TRIANGLE);
  for (const Triangle& t : scene.triangles) {
    packed.triangles.emplace_back(t.v[0], bits(t.material));
    packed.triangles.emplace_back(t.v[1], 0.0f);
    packed.triangles.emplace_back(t.v[2], 0.0f);
  }
  for (const Sphere& s : scene.spheres) {
    packed.spheres.emplace_back(s.center, s.radius);
    packed.spheres.emplace_back(bits(s.material), 0.0f, 0.0f, 0.0f);
  }
  for (const Material& m : scene.materials) packed.materials.emplace_back(m.albedo, 0.0f);
  for (const PointLight& l : scene.lights) {
    packed.lights.emplace_back(l.position, 0.0f);
    packed.lights.emplace_back(l.intensity, 0.0f);
  }
  return packed;
}

}  // namespace vkray::gpu
