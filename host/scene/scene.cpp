#include "scene/scene.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace vkray {

std::string_view material_type_name(MaterialType type) {
#define VKRAY_MATERIAL_NAME(number, name, properties) \
  if (uint32_t(type) == number) return #name;
  VKRAY_MATERIAL_TYPES(VKRAY_MATERIAL_NAME)
#undef VKRAY_MATERIAL_NAME
  return "unknown";
}

std::optional<MaterialType> material_type_named(std::string_view name) {
#define VKRAY_MATERIAL_NAMED(number, type_name, properties) \
  if (name == #type_name) return MaterialType(number);
  VKRAY_MATERIAL_TYPES(VKRAY_MATERIAL_NAMED)
#undef VKRAY_MATERIAL_NAMED
  return std::nullopt;
}

float Scene::extent() const {
  float e = 0.0f;
  auto grow = [&e](glm::vec3 p) { e = std::max({e, std::abs(p.x), std::abs(p.y), std::abs(p.z)}); };
  // Rays leave anywhere on the lens: its rounding is what epsilon must stand above.
  grow(glm::abs(camera.position) + camera.aperture_radius);
  for (const auto& l : lights) grow(l.position);
  for (const auto& s : spheres) grow(glm::abs(s.center) + s.radius);
  for (const auto& t : triangles)
    for (const auto& p : t.v) grow(p);
  return e;
}

namespace {

// Bit for bit: -0 and 0 are different coordinates to the shader's packed buffers.
bool same_bits(const glm::vec3& a, const glm::vec3& b) { return std::memcmp(&a, &b, sizeof(glm::vec3)) == 0; }

bool same_bits(const Triangle& a, const Triangle& b) {
  for (size_t k = 0; k < 3; ++k)
    if (!same_bits(a.v[k], b.v[k]) || !same_bits(a.normals[k], b.normals[k]) ||
        std::memcmp(&a.uv[k], &b.uv[k], sizeof(glm::vec2)) != 0 || std::memcmp(&a.uv1[k], &b.uv1[k], sizeof(glm::vec2)) != 0 ||
        std::memcmp(&a.tangents[k], &b.tangents[k], sizeof(glm::vec4)) != 0 || std::memcmp(&a.colours[k], &b.colours[k], sizeof(glm::vec4)) != 0)
      return false;
  return a.material == b.material && a.object == b.object && a.smooth == b.smooth;
}

bool same_bits(const Sphere& a, const Sphere& b) {
  return same_bits(a.center, b.center) && std::memcmp(&a.radius, &b.radius, sizeof(float)) == 0 && a.material == b.material &&
         a.object == b.object && a.inward == b.inward;
}

}  // namespace

bool same_geometry(const Scene& a, const Scene& b) {
  // Materials are compared by index (a primitive's flags hold it), not by value, but for their sides.
  const auto same = [](const auto& x, const auto& y) { return same_bits(x, y); };
  const auto same_texture = [](const std::shared_ptr<const Texture>& x, const std::shared_ptr<const Texture>& y) {
    return x == y || (x->width == y->width && x->height == y->height && x->texels == y->texels);
  };
  // The texture coordinates are on the device when some material has a texture.
  const auto textured = [](const Scene& s) {
    return std::any_of(s.materials.begin(), s.materials.end(), [](const Material& m) { return m.textured(); });
  };
  // The tangents are on the device when some material has a normal map.
  const auto normal_mapped = [](const Scene& s) {
    return std::any_of(s.materials.begin(), s.materials.end(), [](const Material& m) { return m.normal_texture.present(); });
  };
  // A primitive's flags also say whether its material is single-sided, and whether it lets rays through.
  const auto same_primitive_flags = [&] {
    for (size_t i = 0; i < a.materials.size(); ++i)
      if (a.materials[i].double_sided != b.materials[i].double_sided || a.materials[i].see_through() != b.materials[i].see_through() ||
          a.materials[i].alpha_mode != b.materials[i].alpha_mode)  // with vertex colours' alpha, the mode decides too
        return false;
    return true;
  };
  return a.materials.size() == b.materials.size() && textured(a) == textured(b) && normal_mapped(a) == normal_mapped(b) && same_primitive_flags() &&
         std::equal(a.textures.begin(), a.textures.end(), b.textures.begin(), b.textures.end(), same_texture) &&
         std::equal(a.triangles.begin(), a.triangles.end(), b.triangles.begin(), b.triangles.end(), same) &&
         std::equal(a.spheres.begin(), a.spheres.end(), b.spheres.begin(), b.spheres.end(), same);
}

}  // namespace vkray
