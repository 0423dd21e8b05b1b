#include "scene/float_range.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "base/errors.h"
#include "base/extension.h"
#include "scene/emitters.h"

namespace vkray {
namespace {

std::string brief(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// Where a primitive comes from, for a message: its place in a scene file's "objects", or, in a
// glTF file rendered on its own, the material it has.
std::string where_is(const Scene& scene, uint32_t object, const Material& material) {
  const std::string named = "material \"" + printable(material.name) + "\"";
  return is_gltf_path(scene.file) ? named : "/objects/" + std::to_string(object) + " (" + named + ")";
}

void check_extent(const Scene& scene) {
  if (scene.triangles.empty() && scene.spheres.empty() && scene.instances.empty()) return;  // nothing to square a distance to
  const float extent = scene.extent();
  if (extent >= kMinExtent) return;
  throw SceneError(scene.file.string() + ": the scene reaches only " + brief(extent) +
                   " from the origin (its largest coordinate, camera and lights included): the GPU's 32-bit floats "
                   "square distances a hundred-thousandth of that, below the smallest normal float; vkray renders "
                   "scenes that reach at least 1e-9: scale it up");
}

struct Radiance {
  std::string key;  // what the scene calls it
  float brightest = 0.0f;  // its brightest channel
};

float brightest(const glm::vec3& c) { return std::max({c.r, c.g, c.b}); }

void check_radiance_range(const Scene& scene) {
  std::vector<Radiance> all;
  const bool json = !is_gltf_path(scene.file);
  all.push_back({"/background", brightest(scene.background)});
  if (scene.environment) all.push_back({json ? "/environment" : "the environment map", scene.environment->brightest});
  all.push_back({"/ambient", brightest(scene.ambient)});
  for (const Material& m : scene.materials)
    all.push_back({"material \"" + printable(m.name) + "\"'s emission", brightest(m.emission)});
  for (size_t i = 0; i < scene.lights.size(); ++i)
    all.push_back({(json ? "/lights/" : "light ") + std::to_string(i) +
                       (scene.lights[i].type == Light::Type::directional ? (json ? "/irradiance" : "'s irradiance")
                                                                          : (json ? "/intensity" : "'s intensity")),
                   brightest(scene.lights[i].intensity)});
  const Radiance* bright = nullptr;
  const Radiance* dim = nullptr;
  for (const Radiance& r : all) {
    if (!(r.brightest > 0.0f)) continue;
    if (!bright || r.brightest > bright->brightest) bright = &r;
    if (!dim || r.brightest < dim->brightest) dim = &r;
  }
  if (!bright || double(bright->brightest) <= kMaxRadianceRatio * double(dim->brightest)) return;
  throw SceneError(scene.file.string() + ": " + dim->key + ", " + brief(dim->brightest) +
                   ", is more than 1e30 times dimmer than the scene's brightest radiance (" + bright->key + ", " +
                   brief(bright->brightest) +
                   "): the GPU's 32-bit floats cannot carry both; make the dim one 0 or brighter");
}

void check_area_lights(const Scene& scene) {
  const EmitterTable table = build_emitter_table(scene);
  const PrimitiveNumbering numbering(scene);
  for (const EmitterTable::Entry& e : table.entries) {
    const uint32_t material = numbering.material(e.primitive);
    if (table.density[material] <= double(FLT_MAX)) continue;
    const uint32_t object = numbering.object(e.primitive);
    throw SceneError(scene.file.string() + ": " + where_is(scene, object, scene.materials[material]) +
                     ": an area light of area " + brief(primitive_area(scene, numbering, e.primitive)) +
                     ": light sampling picks its points with a density of at least 1 / area, past the largest 32-bit "
                     "float (3.4e38) the GPU computes with; make it larger, or its material not emit");
  }
}

// Rays reach an instance's mesh moved by the inverse of its transform: from anywhere within the
// scene's reach, they must arrive within the coordinates vkray computes with (a mesh scaled by 1e-9
// and seen from 1e3 away would be met by rays from 1e12 in its own space, past where the GPU's
// products stay finite).
void check_instances(const Scene& scene) {
  if (scene.instances.empty()) return;
  const double reach = scene.extent();
  for (const Instance& instance : scene.instances) {
    const glm::dmat4 inverse = glm::inverse(glm::dmat4(instance.to_world));
    // And the other way: a mesh grown by more than 1e9 turns its normals by a transform whose
    // squares fall below the smallest normal float.
    double growth = 0;
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) growth = std::max(growth, double(std::abs(instance.to_world[c][r])));
    if (growth > double(kMaxCoordinate)) {
      const SharedMesh& mesh = scene.meshes[instance.mesh];
      throw SceneError(scene.file.string() + ": " + where_is(scene, instance.object, scene.materials[mesh.triangles[0].material]) +
                       ": an instance's transform scales its mesh by " + brief(growth) + ", past the 1e9 vkray renders");
    }
    double farthest = 0;
    for (int r = 0; r < 3; ++r)
      farthest = std::max(farthest, (std::abs(inverse[0][r]) + std::abs(inverse[1][r]) + std::abs(inverse[2][r])) * reach +
                                        std::abs(inverse[3][r]));
    if (farthest <= double(kMaxCoordinate)) continue;
    const SharedMesh& mesh = scene.meshes[instance.mesh];
    throw SceneError(scene.file.string() + ": " + where_is(scene, instance.object, scene.materials[mesh.triangles[0].material]) +
                     ": an instance's transform shrinks its mesh so far that rays from the scene (reaching " + brief(reach) +
                     ") would meet it from " + brief(farthest) + " in the mesh's own space, past the coordinates vkray renders (+-1e9)");
  }
}

}  // namespace

void check_float_range(const Scene& scene) {
  check_extent(scene);
  check_radiance_range(scene);
  check_area_lights(scene);
  check_instances(scene);
}

}  // namespace vkray
