#include "scene/digest.h"

#include <memory>

#include "base/hash.h"

namespace vkray {
namespace {

// A new field in one of these must be hashed below (or said not to matter to a pixel), and the size
// here updated: the build stops until it is.
static_assert(sizeof(Camera) == 48, "a Camera field is not in scene_digest");
static_assert(sizeof(Integrator) == 12, "an Integrator field is not in scene_digest");
static_assert(sizeof(Light) == 52, "a Light field is not in scene_digest");
static_assert(sizeof(Sphere) == 28, "a Sphere field is not in scene_digest");
static_assert(sizeof(Triangle) == 228, "a Triangle field is not in scene_digest");
static_assert(sizeof(TextureRef) == 44, "a TextureRef field is not in scene_digest");
static_assert(sizeof(Material) == 400, "a Material field is not in scene_digest");
static_assert(sizeof(Scene) == 536, "a Scene field is not in scene_digest");
static_assert(sizeof(Environment) == 104, "an Environment field is not in scene_digest");  // brightest: of the texels hashed
static_assert(sizeof(Instance) == 72, "an Instance field is not in scene_digest");

// Hasher with glm's vectors, component by component.
class SceneHasher : public Hasher {
 public:
  using Hasher::add;
  template <int N, typename T, glm::qualifier Q>
  void add(const glm::vec<N, T, Q>& v) {
    for (int i = 0; i < N; ++i) add(v[i]);
  }
};

void add(SceneHasher& h, const TextureRef& t) {
  h.add(t.texture);
  h.add(t.wrap_s);
  h.add(t.wrap_t);
  h.add(t.filter);
  h.add(t.texcoord);
  h.add(t.to_u);
  h.add(t.to_v);
}

}  // namespace

std::string scene_digest(const Scene& scene) {
  auto h = std::make_unique<SceneHasher>();  // its buffer is too large for a thread's stack to hold lightly
  // A version of this layout: bump it when the order or the meaning of what is hashed changes.
  h->add(std::string("vkray scene digest 10"));
  const Camera& c = scene.camera;
  h->add(c.position), h->add(c.forward), h->add(c.up), h->add(c.focal_length), h->add(c.aperture_radius),
      h->add(c.focus_distance);
  h->add(scene.integrator.type), h->add(scene.integrator.max_depth), h->add(scene.integrator.rr_depth);
  h->add(scene.background), h->add(scene.ambient);
  // The map by its texels as scaled (the file's name and the scale, as such, do not reach a pixel).
  h->add(scene.environment.has_value());
  if (scene.environment) {
    const Image& map = *scene.environment->radiance;
    h->add(map.width), h->add(map.height);
    h->bytes(map.pixels.data(), map.pixels.size() * sizeof(glm::vec3));
    for (int column = 0; column < 3; ++column) h->add(scene.environment->to_world[column]);
  }
  h->add(uint64_t(scene.materials.size()));
  for (const Material& m : scene.materials) {
    h->add(m.type), h->add(m.albedo), h->add(m.ior), h->add(m.emission), h->add(m.alpha), h->add(m.eta), h->add(m.k), h->add(m.metallic),
        h->add(m.roughness), h->add(m.transmission);
    add(*h, m.albedo_texture);
    add(*h, m.emission_texture);
    add(*h, m.metallic_roughness_texture);
    add(*h, m.normal_texture);
    h->add(m.normal_scale);
    h->add(m.double_sided);
    h->add(m.alpha_mode), h->add(m.opacity), h->add(m.alpha_cutoff);
    add(*h, m.opacity_texture);
    add(*h, m.transmission_texture);
    h->add(m.vertex_colours_emit);
    h->add(m.emits_both_sides);
  }
  h->add(uint64_t(scene.textures.size()));
  for (const auto& t : scene.textures) {
    h->add(t->width), h->add(t->height);
    h->bytes(t->texels.data(), t->texels.size() * sizeof(uint16_t));
  }
  h->add(uint64_t(scene.lights.size()));
  for (const Light& l : scene.lights) {
    h->add(l.type), h->add(l.position), h->add(l.intensity), h->add(l.direction);
    h->add(l.falloff), h->add(l.cutoff_angle), h->add(l.beam_width);
  }
  h->add(uint64_t(scene.spheres.size()));
  for (const Sphere& s : scene.spheres) h->add(s.center), h->add(s.radius), h->add(s.material), h->add(s.object), h->add(s.inward);
  const auto add_triangles = [&](const std::vector<Triangle>& triangles) {
    h->add(uint64_t(triangles.size()));
    for (const Triangle& t : triangles) {
      for (const glm::vec3& v : t.v) h->add(v);
      h->add(t.material), h->add(t.object), h->add(t.smooth);
      for (const glm::vec3& n : t.normals) h->add(n);
      for (const glm::vec2& uv : t.uv) h->add(uv);
      for (const glm::vec2& uv : t.uv1) h->add(uv);
      for (const glm::vec4& tangent : t.tangents) h->add(tangent);
      for (const glm::vec4& colour : t.colours) h->add(colour);
    }
  };
  add_triangles(scene.triangles);
  // Instances only where there are some: a scene without keeps the digest it always had.
  if (!scene.instances.empty()) {
    h->add(uint64_t(scene.meshes.size()));
    for (const SharedMesh& m : scene.meshes) add_triangles(m.triangles);
    h->add(uint64_t(scene.instances.size()));
    for (const Instance& i : scene.instances) {
      h->add(i.mesh), h->add(i.object);
      for (int column = 0; column < 4; ++column) h->add(glm::vec4(i.to_world[column]));
    }
  }
  return h->hex();
}

}  // namespace vkray
