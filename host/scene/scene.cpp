#include "scene/scene.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>

#include <glm/gtc/matrix_inverse.hpp>

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
  for (const auto& l : lights)
    if (l.type != Light::Type::directional) grow(l.position);
  for (const auto& s : spheres) grow(glm::abs(s.center) + s.radius);
  for (const auto& t : triangles)
    for (const auto& p : t.v) grow(p);
  // An instance's world box: its mesh's box, every corner moved.
  std::vector<std::pair<glm::vec3, glm::vec3>> boxes(meshes.size(), {glm::vec3(FLT_MAX), glm::vec3(-FLT_MAX)});
  for (size_t m = 0; m < meshes.size(); ++m)
    for (const auto& t : meshes[m].triangles)
      for (const auto& p : t.v) boxes[m] = {glm::min(boxes[m].first, p), glm::max(boxes[m].second, p)};
  for (const Instance& instance : instances) {
    const auto& [lo, hi] = boxes[instance.mesh];
    if (lo.x > hi.x) continue;
    for (int corner = 0; corner < 8; ++corner) {
      const glm::vec3 p((corner & 1) ? hi.x : lo.x, (corner & 2) ? hi.y : lo.y, (corner & 4) ? hi.z : lo.z);
      grow(glm::vec3(instance.to_world * glm::vec4(p, 1.0f)));
    }
  }
  return e;
}

PrimitiveNumbering::PrimitiveNumbering(const Scene& scene) : scene_(&scene) {
  uint64_t next = scene.triangles.size();
  instance_first_.reserve(scene.instances.size());
  for (const Instance& instance : scene.instances) {
    instance_first_.push_back(next);
    next += scene.meshes[instance.mesh].triangles.size();
  }
  sphere_first_ = next;
}

PrimitiveNumbering::Placed PrimitiveNumbering::at(uint64_t p) const {
  if (p < scene_->triangles.size()) return {&scene_->triangles[p], nullptr, -1};
  if (p >= sphere_first_) return {nullptr, &scene_->spheres[p - sphere_first_], -1};
  // The last instance that starts at or before p (instances of empty meshes start where the next does).
  const auto after = std::upper_bound(instance_first_.begin(), instance_first_.end(), p);
  const auto instance = size_t(after - instance_first_.begin()) - 1;
  return {&scene_->meshes[scene_->instances[instance].mesh].triangles[p - instance_first_[instance]], nullptr, int64_t(instance)};
}

uint32_t PrimitiveNumbering::material(uint64_t p) const {
  const Placed placed = at(p);
  return placed.sphere ? placed.sphere->material : placed.triangle->material;
}

uint32_t PrimitiveNumbering::object(uint64_t p) const {
  const Placed placed = at(p);
  if (placed.instance >= 0) return scene_->instances[size_t(placed.instance)].object;
  return placed.sphere ? placed.sphere->object : placed.triangle->object;
}

Triangle placed_triangle(const Triangle& t, const glm::dmat4& to_world) {
  const glm::dmat3 linear(to_world);
  const glm::dmat3 normal_matrix = glm::transpose(glm::inverse(linear));
  const bool mirrors = glm::determinant(linear) < 0;
  Triangle out = t;
  for (size_t k = 0; k < 3; ++k) {
    out.v[k] = glm::vec3(to_world * glm::dvec4(t.v[k], 1.0));
    if (t.smooth) out.normals[k] = glm::vec3(glm::normalize(normal_matrix * glm::dvec3(t.normals[k])));
    if (t.has_tangents()) {
      const glm::dvec3 d = linear * glm::dvec3(t.tangents[k]);
      out.tangents[k] = glm::vec4(glm::vec3(glm::normalize(d)), mirrors ? -t.tangents[k].w : t.tangents[k].w);
    }
  }
  if (mirrors) out.swap_corners();
  return out;
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
         std::equal(a.spheres.begin(), a.spheres.end(), b.spheres.begin(), b.spheres.end(), same) &&
         std::equal(a.meshes.begin(), a.meshes.end(), b.meshes.begin(), b.meshes.end(),
                    [&](const SharedMesh& x, const SharedMesh& y) {
                      return std::equal(x.triangles.begin(), x.triangles.end(), y.triangles.begin(), y.triangles.end(), same);
                    }) &&
         std::equal(a.instances.begin(), a.instances.end(), b.instances.begin(), b.instances.end(), [](const Instance& x, const Instance& y) {
           return x.mesh == y.mesh && x.object == y.object && std::memcmp(&x.to_world, &y.to_world, sizeof(glm::mat4)) == 0;
         });
}

}  // namespace vkray
