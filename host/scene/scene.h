// The in-memory scene: what a scene file (docs/scene-format.md) describes, with every object
// transform already applied to its own primitives; a mesh placed more than once is stored once, in
// its own space, and placed by instances, whose transforms the renderers apply to rays.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "image/image.h"
#include "shared/materials.h"
#include "scene/texture.h"

namespace vkray {

// Upper bounds of a scene's image settings (and kMaxImageSide, image/image.h), which keep later size
// arithmetic far from overflow; the device's own limits are checked again before anything is allocated.
constexpr uint32_t kMaxSamplesPerPixel = 65536;
// The largest max_depth and rr_depth a path integrator takes (-1, no limit, is allowed too).
constexpr int32_t kMaxPathDepth = 1024;

// Every world-space coordinate (after transforms) lies within +-kMaxCoordinate, and so do the
// camera, its target and the lights. The GPU's float math raises coordinate differences d (at
// most 2e9) to the fourth power at most: the squared length of a triangle's edge cross product,
// 3 (2 d^2)^2 = 1.9e38, and the barycentric denominator |e1|^2 |e2|^2 = (3 d^2)^2 = 1.4e38, both
// below FLT_MAX (3.4e38); the 3x3 determinant (d^3) and a sphere's |oc|^2 (d^2) stay far below. So
// no sum or product in the BVH builder or either renderer can overflow, and the two renderers see
// the same numbers. A scene past it is refused at load, the same for both renderers.
constexpr float kMaxCoordinate = 1e9f;

// A scene holds at most this many primitives (triangles and spheres together): a BVH leaf names its
// first primitive in 27 bits (bvh/bvh.h checks that the two agree).
constexpr size_t kMaxScenePrimitives = (size_t(1) << 27) - 1;
// A scene places at most this many primitives, instances' counted each time they are placed: a
// primitive's place in the scene (PrimitiveNumbering) travels to the GPU as the bits of a float,
// and every number below 0x7f800000 is the bits of a finite float.
constexpr uint64_t kMaxPlacedPrimitives = 2'000'000'000;
// A scene holds at most this many instances: far past a real scene's (the memory of one is about 200
// bytes), and a small glTF file cannot claim more (an accessor without a buffer view holds any count
// of zeros).
constexpr size_t kMaxInstances = size_t(1) << 24;

struct ImageSettings {
  uint32_t width = 512;
  uint32_t height = 512;
  uint32_t samples_per_pixel = 1;
  // Picks the sample streams (the scene's "seed", --seed): renders with the same seed are the same,
  // and different seeds give independent streams, so that renders can be averaged. 0 gives the
  // streams vkray always had.
  uint32_t seed = 0;
};

struct Camera {
  glm::vec3 position{0.0f};
  glm::vec3 forward{0.0f, 0.0f, 1.0f};  // unit view direction
  glm::vec3 up{0.0f, 1.0f, 0.0f};       // never parallel to forward; its squared length is finite
  float focal_length = 1.0f;            // in units of the image height
  // The thin lens (Mitsuba's `thinlens`): rays leave a disk of this radius around the position,
  // aimed so that the plane focus_distance ahead is sharp. 0: the pinhole.
  float aperture_radius = 0.0f;
  float focus_distance = 1.0f;
};

// The material types, numbered as the shader numbers them: made from the table in
// shaders/shared/materials.h, which also gives each its properties.
enum class MaterialType : uint32_t {
#define VKRAY_MATERIAL_ENUMERATOR(number, name, properties) name = number,
  VKRAY_MATERIAL_TYPES(VKRAY_MATERIAL_ENUMERATOR)
#undef VKRAY_MATERIAL_ENUMERATOR
};

// glTF's alphaMode, numbered as the shader numbers them (VKRAY_ALPHA_* in shaders/shared/materials.h).
enum class AlphaMode : uint32_t { opaque = VKRAY_ALPHA_OPAQUE, mask = VKRAY_ALPHA_MASK, blend = VKRAY_ALPHA_BLEND };

// The name a scene file gives the type ("roughconductor"), and the type of a name (nullopt: none).
std::string_view material_type_name(MaterialType type);
std::optional<MaterialType> material_type_named(std::string_view name);

// The largest index of refraction (and absorption coefficient) a material takes: past every real
// material (diamond's index is 2.4, metals' absorption about 10), so that a typo shows.
constexpr float kMaxIor = 100.0f;

struct Material {
  std::string name;
  MaterialType type = MaterialType::diffuse;
  // diffuse: the albedo; mirror: the reflectance; roughconductor: the specular reflectance;
  // roughdielectric: 1; glass: unused
  glm::vec3 albedo{0.0f};
  float ior = 1.5f;          // glass, roughdielectric: the index of refraction inside (outside: 1, vacuum)
  glm::vec3 emission{0.0f};  // radiance emitted on the side the geometric normal faces
  // The rough materials' GGX roughness along the two tangents of the shading frame (Mitsuba's
  // alpha_u, alpha_v); roughconductor's complex index of refraction eta + i k (eta 0 with k 1 makes
  // the Fresnel term 1).
  glm::vec2 alpha{0.1f};
  glm::vec3 eta{0.0f};
  glm::vec3 k{1.0f};
  // metallic_roughness (glTF's model, its albedo the base colour): how metallic, and how rough (its
  // GGX alpha is roughness squared); glTF's defaults.
  float metallic = 1.0f;
  float roughness = 1.0f;
  // metallic_roughness (0 for every other type, which the readers never set): how much of the light
  // its dielectric does not reflect passes through it rather than into its Lambertian base (glTF's
  // KHR_materials_transmission, thin-walled: a sheet with no inside, its transmission the specular
  // lobe mirrored through the surface), times the red of `transmission_texture` (linear).
  float transmission = 0.0f;
  // Textures that multiply albedo (or reflectance) and emission where a triangle has texture
  // coordinates (glTF's baseColorTexture and emissiveTexture, an .mtl file's map_Kd), and
  // metallic_roughness's metallic (by its blue) and roughness (by its green), a linear texture
  // (glTF's metallicRoughnessTexture).
  TextureRef albedo_texture;
  TextureRef emission_texture;
  TextureRef metallic_roughness_texture;
  // A tangent-space normal map (glTF's normalTexture, linear): its red, green and blue, each taken from
  // [0, 1] to [-1, 1], are a normal along a triangle's tangent, bitangent and normal (Triangle::tangents);
  // `normal_scale` multiplies the first two (glTF's normalTexture.scale).
  TextureRef normal_texture;
  float normal_scale = 1.0f;
  // false: single-sided (glTF's doubleSided false): camera rays, and so the first-hit passes, pass
  // through its triangles' back faces (the side away from their winding's normal); every other ray
  // meets both sides.
  bool double_sided = true;
  // How much of the surface is there (glTF's alphaMode; VKRAY_ALPHA_* in shaders/shared/materials.h):
  // the opacity is `opacity` (glTF's baseColorFactor alpha, an .mtl file's d) times the alpha of
  // `opacity_texture` (glTF's base colour texture; an .mtl file's map_d, whose grey is its alpha where
  // the picture has none). opaque: all of it; mask: where the opacity is at least `alpha_cutoff`;
  // blend: each ray meets it with probability the opacity. The same for every ray.
  AlphaMode alpha_mode = AlphaMode::opaque;
  float opacity = 1.0f;
  float alpha_cutoff = 0.5f;
  TextureRef opacity_texture;
  TextureRef transmission_texture;
  // What a triangle's vertex colours multiply (Triangle::colours): its albedo, or (glTF's
  // KHR_materials_unlit, whose base colour is its emission) its emission.
  bool vertex_colours_emit = false;
  // Whether its emission leaves both sides of the surface, not only the side the geometric normal
  // faces (a double-sided KHR_materials_unlit material, whose base colour shows from both).
  bool emits_both_sides = false;

  bool emissive() const { return emission != glm::vec3(0.0f); }
  // Every texture reference, for code that treats them alike.
  std::array<TextureRef*, 6> textures() {
    return {&albedo_texture, &emission_texture, &metallic_roughness_texture, &normal_texture, &opacity_texture, &transmission_texture};
  }
  std::array<const TextureRef*, 6> textures() const {
    return {&albedo_texture, &emission_texture, &metallic_roughness_texture, &normal_texture, &opacity_texture, &transmission_texture};
  }
  bool textured() const {
    const auto refs = textures();
    return std::any_of(refs.begin(), refs.end(), [](const TextureRef* t) { return t->present(); });
  }
  // Whether its alpha lets some ray through somewhere: a mode other than opaque with an opacity
  // texture, or an opacity factor that is not whole (below the cutoff, for mask).
  bool see_through() const {
    if (alpha_mode == AlphaMode::opaque) return false;
    return opacity_texture.present() || !(opacity >= (alpha_mode == AlphaMode::mask ? alpha_cutoff : 1.0f));
  }
  // Its properties (VKRAY_BSDF_* in shaders/shared/materials.h): code outside the BSDFs asks these.
  uint32_t properties() const { return gpu::material_value_properties(uint32_t(type), transmission); }
  bool has(uint32_t property) const { return (properties() & property) != 0; }
};

// How light is carried to the camera (Mitsuba's integrators).
struct Integrator {
  enum class Type { direct, path };
  Type type = Type::direct;  // direct: the lecture's model; path: the rendering equation
  int32_t max_depth = -1;    // path: Mitsuba's max_depth (1: emitters seen directly; -1: no limit)
  uint32_t rr_depth = 5;     // path: Russian roulette from this depth on
};

// A light that is not a surface, each as Mitsuba's emitter of the name: it sends light from one point
// (point, spot) or from one direction (directional), so only the lights themselves find it, never a
// ray by chance.
struct Light {
  enum class Type : uint32_t { point, spot, directional };
  // How a spot dims toward its edge: Mitsuba's `spot` (1 within beam_width, then linearly in the
  // angle to 0 at cutoff_angle), or KHR_lights_punctual's (the square of a ramp in the cosine from
  // the outer cone, cutoff_angle, to the inner, beam_width).
  enum class Falloff : uint32_t { mitsuba, gltf };
  Type type = Type::point;
  glm::vec3 position{0.0f};   // point, spot
  // point: radiant intensity I (W/sr; a file's "power" P is stored as P / 4pi); spot: I at its
  // centre; directional: irradiance E (W/m^2) on a surface that faces it
  glm::vec3 intensity{0.0f};
  glm::vec3 direction{0.0f, 0.0f, 1.0f};  // spot, directional: unit, the way its light travels
  Falloff falloff = Falloff::mitsuba;
  float cutoff_angle = 0.0f;  // spot: radians from the axis, in (0, pi]: no light past it
  float beam_width = 0.0f;    // spot: radians, in [0, cutoff_angle]: full light within it
};

struct Sphere {
  glm::vec3 center{0.0f};
  float radius = 0.0f;
  uint32_t material = 0;
  uint32_t object = 0;  // its place in the file's "objects": the `object` pass (AOV) reports it
  bool inward = false;  // "flip_normals": the normal points to the centre (for emission and glass)

};

struct Triangle {
  std::array<glm::vec3, 3> v;
  uint32_t material = 0;
  uint32_t object = 0;                 // its place in the file's "objects"
  bool smooth = false;                 // shade with `normals` interpolated, not the face normal
  std::array<glm::vec3, 3> normals{};  // unit vertex normals, when smooth
  // Texture coordinates of the vertices, as glTF has them: (0, 0) is the top left corner of a
  // picture, (1, 1) its bottom right. All zero where the mesh has none.
  std::array<glm::vec2, 3> uv{};
  // A second set, for the textures that read it (TextureRef::texcoord 1: a glTF material whose
  // textures use two TEXCOORD_n). All zero where none does.
  std::array<glm::vec2, 3> uv1{};
  // The vertices' tangents where the material has a normal map (glTF's TANGENT, or MikkTSpace's):
  // xyz the unit tangent along which u grows, w the bitangent's sign: bitangent = w cross(normal,
  // tangent), the direction in which v falls (up the picture). w 0: none.
  std::array<glm::vec4, 3> tangents{};
  // The vertices' colours (glTF's COLOR_0), each component in [0, 1], interpolated across the
  // triangle: rgb multiplies the material's base colour (Material::vertex_colours_emit says which),
  // a its opacity. White where the mesh has none.
  std::array<glm::vec4, 3> colours{glm::vec4(1.0f), glm::vec4(1.0f), glm::vec4(1.0f)};

  bool has_tangents() const { return tangents[0].w != 0.0f; }
  // The texture coordinates of texture coordinate set `set` (TextureRef::texcoord).
  const std::array<glm::vec2, 3>& texcoords(uint32_t set) const { return set == 0 ? uv : uv1; }
  // Turns the winding around (the front face to the back) by swapping corners 1 and 2 of everything
  // given per corner.
  void swap_corners() {
    std::swap(v[1], v[2]);
    std::swap(normals[1], normals[2]);
    std::swap(uv[1], uv[2]);
    std::swap(uv1[1], uv1[2]);
    std::swap(tangents[1], tangents[2]);
    std::swap(colours[1], colours[2]);
  }
  bool coloured() const { return colours[0] != glm::vec4(1.0f) || colours[1] != glm::vec4(1.0f) || colours[2] != glm::vec4(1.0f); }
  bool translucent_colours() const { return colours[0].a != 1.0f || colours[1].a != 1.0f || colours[2].a != 1.0f; }
};

// A mesh that instances place (Scene::instances): its triangles in its own space, stored once
// however often it is placed. A triangle's `object` is unused: its instance's counts.
struct SharedMesh {
  std::vector<Triangle> triangles;
};

// One placement of a mesh: its triangles as `to_world` (affine, invertible) moves them. The
// renderers move rays the other way, into the mesh's space (its normals turn by the inverse
// transpose); a transform that mirrors keeps front faces front, as it does for a scene's own
// triangles.
struct Instance {
  uint32_t mesh = 0;  // in Scene::meshes
  glm::mat4 to_world{1.0f};
  uint32_t object = 0;  // its place in the file's "objects": the `object` pass reports it
};

// An equirectangular map of radiance that surrounds the scene, infinitely far (Mitsuba's `envmap`):
// what rays that leave the scene see, and a light to both integrators. It replaces `background`.
// Orientation and texel layout: shaders/shared/scene_layout.h ("The environment map").
struct Environment {
  std::filesystem::path file;  // where the map was read from (a .hdr or .exr file)
  // Its texels, times the scene's `scale`: 2:1, finite and non-negative; shared by copies of a scene.
  std::shared_ptr<const Image> radiance;
  float brightest = 0.0f;  // the brightest channel of any of its texels, scaled
  float scale = 1.0f;
  glm::mat3 to_world{1.0f};  // a rotation: the map's frame in the world (Mitsuba's to_world)
};

struct Scene {
  std::filesystem::path file;  // where it was loaded from; paths inside are relative to its folder
  std::string name;            // the file's stem: "cornell" for scenes/cornell.json
  std::string description;     // what the scene is for, in a sentence: free text, never rendered
  ImageSettings image;
  Camera camera;
  Integrator integrator;
  glm::vec3 background{0.0f};
  std::optional<Environment> environment;  // in place of background when present
  glm::vec3 ambient{0.0f};
  std::vector<Material> materials;
  std::vector<Light> lights;
  std::vector<Sphere> spheres;
  std::vector<Triangle> triangles;
  std::vector<SharedMesh> meshes;    // what `instances` place
  std::vector<Instance> instances;
  std::vector<std::shared_ptr<const Texture>> textures;  // what the materials' TextureRefs index
  std::vector<std::string> warnings;  // odd but valid input, e.g. unknown keys
  // Files the scene reads besides itself (meshes): `vkray watch` watches them.
  std::vector<std::filesystem::path> referenced_files;

  // Largest absolute coordinate of anything in the scene (geometry, lights, camera).
  float extent() const;

  // The contract's epsilon: the offset of shadow-ray origins and the smallest accepted t. 1e-5 of
  // the scene's extent: far above float rounding at that scale (~1e-7 relative), far below any feature.
  float epsilon() const { return std::max(extent(), 1e-30f) * 1e-5f; }
  // Whether some primitive lets rays through (its material's alpha, or a triangle's vertex colours'):
  // every ray then draws a key from its sample's stream (shared/sampling.h, alpha_random), on both
  // renderers. The GPU's pipeline reads the same off the packed primitives' flags (VKRAY_PRIM_ALPHA).
  bool see_through() const {
    return std::any_of(spheres.begin(), spheres.end(), [&](const Sphere& s) { return materials[s.material].see_through(); }) ||
           any_triangle([&](const Triangle& t) { return see_through(t); });
  }
  // Whether some triangle, the meshes' included, satisfies `predicate`.
  template <typename Predicate>
  bool any_triangle(const Predicate& predicate) const {
    return std::any_of(triangles.begin(), triangles.end(), predicate) ||
           std::any_of(meshes.begin(), meshes.end(), [&](const SharedMesh& m) { return std::any_of(m.triangles.begin(), m.triangles.end(), predicate); });
  }
  // Whether a triangle lets some ray through: its material does, or the material blends or masks and
  // the triangle's vertex colours are not all opaque.
  bool see_through(const Triangle& t) const {
    const Material& m = materials[t.material];
    return m.see_through() || (m.alpha_mode != AlphaMode::opaque && t.translucent_colours());
  }
};

// The scene's numbering of the primitives it places: its own triangles, then each instance's mesh
// triangles (instance by instance, each in its mesh's order), then its spheres. Ties between hits
// and alpha keys go by it (VKRAY_TIE, shared/sampling.h) on both renderers, so a scene renders as
// it would with every instance's triangles copied into place in that order.
class PrimitiveNumbering {
 public:
  explicit PrimitiveNumbering(const Scene& scene);

  struct Placed {
    const Triangle* triangle = nullptr;  // in its mesh's space when `instance` >= 0
    const Sphere* sphere = nullptr;
    int64_t instance = -1;               // in Scene::instances
  };
  uint64_t count() const { return sphere_first_ + scene_->spheres.size(); }
  uint64_t instance_first(size_t instance) const { return instance_first_[instance]; }
  uint64_t sphere_first() const { return sphere_first_; }
  Placed at(uint64_t p) const;
  uint32_t material(uint64_t p) const;
  uint32_t object(uint64_t p) const;

 private:
  const Scene* scene_;
  std::vector<uint64_t> instance_first_;
  uint64_t sphere_first_ = 0;
};

// Triangle `t` of a mesh as instance `to_world` places it: its vertices moved, its normals turned by
// the inverse transpose and its tangents as directions (each unit again), corners swapped where the
// transform mirrors. What a renderer that copied the instance into place would hold.
Triangle placed_triangle(const Triangle& t, const glm::dmat4& to_world);

// Whether two scenes have the same primitives, bit for bit, with the same materials, objects and
// textures (a scene on the device can then keep its BVH, primitive and texture buffers:
// Session::upload_changes).
bool same_geometry(const Scene& a, const Scene& b);

}  // namespace vkray
