#include "load/scene_loader.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include <glm/gtc/constants.hpp>

#include "base/errors.h"
#include "base/extension.h"
#include "base/input_file.h"
#include "base/interrupt.h"
#include "base/json_document.h"
#include "load/environment_file.h"
#include "load/scene_parser.h"
#include "mesh/tangents.h"
#include "scene/transform.h"
#include "scene/float_range.h"

namespace vkray {
namespace {

// Calls f on every triangle the scene stores: its own and its meshes'.
template <typename F>
void each_triangle(Scene& scene, const F& f) {
  for (Triangle& t : scene.triangles) f(t);
  for (SharedMesh& mesh : scene.meshes)
    for (Triangle& t : mesh.triangles) f(t);
}

// Applies the transform (KHR_texture_transform) that all the textures of a material share to its
// triangles' texture coordinates, once, in double rounded to float: both renderers then read the
// same mapped coordinates, which recentre_texture_coordinates can move like any others. Textures
// with transforms of their own keep them (and their triangles' coordinates stay where they are).
void apply_shared_texture_transforms(Scene& scene) {
  std::vector<std::optional<TextureRef>> shared(scene.materials.size());  // the transform to apply, held by a ref
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    const TextureRef* first = nullptr;
    bool same = true;
    for (const TextureRef* ref : m.textures()) {
      if (!ref->present()) continue;
      if (!first) first = ref;
      same = same && ref->to_u == first->to_u && ref->to_v == first->to_v;
    }
    if (first && same && first->transformed()) shared[i] = *first;
  }
  each_triangle(scene, [&](Triangle& t) {
    if (shared[t.material])
      for (auto* set : {&t.uv, &t.uv1})
        for (glm::vec2& uv : *set) uv = glm::vec2(shared[t.material]->map(glm::dvec2(uv)));
  });
  for (size_t i = 0; i < scene.materials.size(); ++i)
    if (shared[i])
      for (TextureRef* ref : scene.materials[i].textures()) ref->to_u = glm::vec3(1, 0, 0), ref->to_v = glm::vec3(0, 1, 0);
}

// Moves each textured triangle's texture coordinates by a whole number of periods toward [0, 2)
// along each axis its textures repeat (an even number, so that a mirrored repeat reads the same):
// exact in float, and the texture reads the same, but both renderers then interpolate small
// numbers, so that a floor tiled 5000 times is not sampled half a texel apart by float and double.
void recentre_texture_coordinates(Scene& scene) {
  each_triangle(scene, [&](Triangle& t) {
    const Material& m = scene.materials[t.material];
    if (!m.textured()) return;
    // A texture still transformed (its material's textures have different transforms) maps a whole
    // period of the coordinate to another amount of its own: such coordinates stay where they are.
    const auto repeats = [&](bool s) {
      for (const TextureRef* ref : m.textures())
        if (ref->present() && ((s ? ref->wrap_s : ref->wrap_t) == TextureWrap::clamp_to_edge || ref->transformed())) return false;
      return true;
    };
    for (int axis = 0; axis < 2; ++axis) {
      if (!repeats(axis == 0)) continue;
      for (auto* set : {&t.uv, &t.uv1}) {
        const float lowest = std::min({(*set)[0][axis], (*set)[1][axis], (*set)[2][axis]});
        const float shift = 2.0f * std::floor(lowest / 2.0f);
        for (glm::vec2& uv : *set) uv[axis] -= shift;
      }
    }
  });
}

// MikkTSpace's tangents for the triangles of normal-mapped materials that have none (a glTF file
// without TANGENT, an OBJ or PLY file, a scene file's own triangles), each object's together, from
// the normals they are shaded with and their texture coordinates before any transform maps them
// (KHR_texture_transform moves where a texture is read, not the mesh's tangent space).
void add_missing_tangents(std::vector<Triangle>& all, const std::vector<Material>& materials, bool by_object) {
  std::vector<std::vector<size_t>> of_object;  // the triangles that need tangents, by object
  for (size_t i = 0; i < all.size(); ++i) {
    const Triangle& t = all[i];
    if (!materials[t.material].normal_texture.present() || t.has_tangents()) continue;
    const size_t object = by_object ? t.object : 0;
    if (object >= of_object.size()) of_object.resize(object + 1);
    of_object[object].push_back(i);
  }
  std::vector<TangentTriangle> input;
  for (const std::vector<size_t>& triangles : of_object) {
    if (triangles.empty()) continue;
    throw_if_interrupted();
    input.clear();
    input.reserve(triangles.size());
    for (const size_t i : triangles) {
      const Triangle& t = all[i];
      TangentTriangle m{t.v, t.normals, t.texcoords(materials[t.material].normal_texture.texcoord)};
      if (!t.smooth) {
        const glm::dvec3 n = glm::cross(glm::dvec3(t.v[1]) - glm::dvec3(t.v[0]), glm::dvec3(t.v[2]) - glm::dvec3(t.v[0]));
        const double length = glm::length(n);
        m.normal.fill(length > 0 ? glm::vec3(n / length) : glm::vec3(0.0f));
      }
      input.push_back(m);
    }
    const std::vector<std::array<glm::vec4, 3>> tangents = mikktspace_tangents(input);
    for (size_t k = 0; k < triangles.size(); ++k) all[triangles[k]].tangents = tangents[k];
  }
}

// The scene's own triangles by object; each mesh that instances place, in its own space, as one.
void add_missing_tangents(Scene& scene) {
  add_missing_tangents(scene.triangles, scene.materials, true);
  for (SharedMesh& mesh : scene.meshes) add_missing_tangents(mesh.triangles, scene.materials, false);
}

// What every scene goes through last, whatever its file type: tangents where normal maps need them,
// its texture coordinates mapped by shared transforms and recentred, and the checks that need the
// whole scene.
void finish_scene(Scene& scene) {
  add_missing_tangents(scene);
  apply_shared_texture_transforms(scene);
  recentre_texture_coordinates(scene);
  check_float_range(scene);
}


}  // namespace

using scene_file::SceneParser;

Scene parse_scene(std::string_view json_text, const std::filesystem::path& file, MeshCache* meshes,
                  const std::filesystem::path& environment) {
  const nlohmann::json root = parse_json_document(json_text, file);
  Scene scene;
  scene.file = file;
  scene.name = file.stem().string();
  MeshCache this_scene;
  SceneParser parser(file, scene, meshes ? *meshes : this_scene);
  parser.replace_environment_with(environment);
  parser.parse(root);
  if (!environment.empty()) set_environment(scene, environment);
  finish_scene(scene);
  return scene;
}

namespace {

// The box around every triangle the scene places (an instance's: its mesh's box, every corner
// placed); lo > hi when there are none.
std::pair<glm::vec3, glm::vec3> placed_bounds(const Scene& scene) {
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  const auto grow = [&](const glm::vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  };
  for (const Triangle& t : scene.triangles)
    for (const glm::vec3& p : t.v) grow(p);
  std::vector<std::pair<glm::vec3, glm::vec3>> meshes(scene.meshes.size(), {glm::vec3(FLT_MAX), glm::vec3(-FLT_MAX)});
  for (size_t m = 0; m < scene.meshes.size(); ++m)
    for (const Triangle& t : scene.meshes[m].triangles)
      for (const glm::vec3& p : t.v) meshes[m] = {glm::min(meshes[m].first, p), glm::max(meshes[m].second, p)};
  for (const Instance& instance : scene.instances) {
    const auto& [a, b] = meshes[instance.mesh];
    for (int corner = 0; corner < 8; ++corner)
      grow(transform_point(instance.to_world, glm::vec3((corner & 1) ? b.x : a.x, (corner & 2) ? b.y : a.y, (corner & 4) ? b.z : a.z)));
  }
  return {lo, hi};
}

// The camera vkray frames a glTF scene with when the file has none: a 45-degree vertical field of
// view from the front (glTF's +z) and a little above, so that the bounding sphere fills the height.
Camera framing_camera(const Scene& scene) {
  Camera camera;
  camera.focal_length = 0.5f / std::tan(glm::radians(45.0f) / 2);
  const auto [lo, hi] = placed_bounds(scene);
  if (lo.x > hi.x) {
    camera.position = glm::vec3(0.0f, 0.0f, 1.0f);
    camera.forward = glm::vec3(0.0f, 0.0f, -1.0f);
    return camera;
  }
  const glm::dvec3 centre = (glm::dvec3(lo) + glm::dvec3(hi)) / 2.0;
  const double radius = std::max(glm::length(glm::dvec3(hi) - glm::dvec3(lo)) / 2.0, 1e-6);
  const double distance = radius / std::sin(glm::radians(45.0 / 2)) * 1.05;
  const glm::dvec3 direction = glm::normalize(glm::dvec3(0.0, 0.3, 1.0));
  camera.position = glm::vec3(centre + distance * direction);
  camera.forward = glm::vec3(-direction);
  return camera;
}

}  // namespace

Scene load_gltf_scene(const std::filesystem::path& file, MeshCache* meshes, const std::filesystem::path& environment) {
  Scene scene;
  scene.file = file;
  scene.name = file.stem().string();
  scene.description = "The glTF file " + file.filename().string();
  MeshCache this_scene;
  SceneParser parser(file, scene, meshes ? *meshes : this_scene);
  const auto [camera, aspect] = parser.add_gltf(nullptr, file, glm::mat4(1.0f));
  scene.camera = camera ? *camera : framing_camera(scene);
  if (!(glm::all(glm::lessThanEqual(glm::abs(scene.camera.position), glm::vec3(kMaxCoordinate)))))
    throw LimitError(file.string() + ": the camera vkray frames the model with would stand past +-1e9 (docs/limits.md)");
  if (!camera) scene.warnings.push_back(file.string() + ": no perspective camera: vkray frames the scene from the front");
  if (aspect > 0.0f)
    scene.image.width = uint32_t(std::clamp(std::lround(double(scene.image.height) * aspect), 1l, long(kMaxImageSide)));
  if (!environment.empty()) set_environment(scene, environment);
  // A file that brings no light is lit from the camera, so that it is seen at all (docs/scene-format.md):
  // a point light whose irradiance at the scene's centre, straight on, is 1. Emissive surfaces do not
  // count: a model's glowing parts (a helmet's visor lights) rarely light the rest of it.
  const auto [lo, hi] = placed_bounds(scene);
  if (scene.lights.empty() && !scene.environment && lo.x <= hi.x) {
    const float distance = std::max(glm::length((lo + hi) / 2.0f - scene.camera.position), 1e-6f);
    Light light;
    light.position = scene.camera.position;
    light.intensity = glm::vec3(glm::pi<float>() * distance * distance);
    scene.lights.push_back(light);
    scene.warnings.push_back(file.string() + ": the file brings no light (emissive surfaces do not count): vkray adds a point light at the camera");
  }
  finish_scene(scene);
  return scene;
}

Scene load_scene(const std::filesystem::path& file, MeshCache* meshes, const std::filesystem::path& environment) {
  if (file.empty()) throw SceneError("the scene file name is empty");
  if (is_gltf_path(file)) return load_gltf_scene(file, meshes, environment);
  const InputFile input = read_input_file(file, kMaxSceneFileBytes);
  if (!input.error.empty()) throw SceneError(file.string() + ": " + input.error);
  return parse_scene(input.text, file, meshes, environment);
}


}  // namespace vkray
