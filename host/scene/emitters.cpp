#include "scene/emitters.h"

#include <numbers>

#include "base/errors.h"
#include "shared/scene_layout.h"

namespace vkray {

double primitive_area(const Scene& scene, const PrimitiveNumbering& numbering, uint64_t p) {
  const PrimitiveNumbering::Placed placed = numbering.at(p);
  if (placed.sphere) {
    const double r = placed.sphere->radius;
    return 4.0 * std::numbers::pi * r * r;
  }
  const Triangle& t = *placed.triangle;
  glm::dvec3 v[3] = {glm::dvec3(t.v[0]), glm::dvec3(t.v[1]), glm::dvec3(t.v[2])};
  if (placed.instance >= 0) {  // the area it has where its instance places it
    const glm::dmat4 to_world(scene.instances[size_t(placed.instance)].to_world);
    for (glm::dvec3& corner : v) corner = glm::dvec3(to_world * glm::dvec4(corner, 1.0));
  }
  return 0.5 * glm::length(glm::cross(v[1] - v[0], v[2] - v[0]));
}

EmitterTable build_emitter_table(const Scene& scene) {
  EmitterTable table;
  std::vector<double> weights;
  const PrimitiveNumbering numbering(scene);
  const auto consider = [&](uint64_t p, uint32_t material) {
    const glm::vec3 e = scene.materials[material].emission;
    if (!scene.materials[material].emissive()) return;
    const double weight = primitive_area(scene, numbering, p) * double(gpu::emission_luminance(e));
    if (!(weight > 0)) return;
    table.entries.push_back({1.0f, uint32_t(table.entries.size()), uint32_t(p)});
    weights.push_back(weight);
    table.total_weight += weight;
  };
  const uint64_t triangles = scene.triangles.size();
  // An instance's emitters: its mesh's emissive triangles, found once per mesh. Each placed one is an
  // entry: as many as a scene of copies would have, held to the scene's primitive limit before any
  // is made.
  std::vector<std::vector<uint32_t>> emissive(scene.meshes.size());
  for (size_t m = 0; m < scene.meshes.size(); ++m)
    for (uint32_t t = 0; t < scene.meshes[m].triangles.size(); ++t)
      if (scene.materials[scene.meshes[m].triangles[t].material].emissive()) emissive[m].push_back(t);
  uint64_t placed = 0;
  for (const Instance& instance : scene.instances) placed += emissive[instance.mesh].size();
  if (placed > kMaxScenePrimitives)
    throw LimitError(scene.file.string() + ": its instances place " + std::to_string(placed) +
                     " emissive triangles; vkray samples at most " + std::to_string(kMaxScenePrimitives) + " area lights");
  for (uint64_t p = 0; p < triangles; ++p) consider(p, scene.triangles[size_t(p)].material);
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const SharedMesh& mesh = scene.meshes[scene.instances[i].mesh];
    for (const uint32_t t : emissive[scene.instances[i].mesh]) consider(numbering.instance_first(i) + t, mesh.triangles[t].material);
  }
  for (uint64_t s = 0; s < scene.spheres.size(); ++s) consider(numbering.sphere_first() + s, scene.spheres[size_t(s)].material);
  table.density.assign(scene.materials.size(), 0.0);
  if (table.total_weight > 0)
    for (size_t m = 0; m < scene.materials.size(); ++m)
      if (scene.materials[m].emissive())
        table.density[m] = double(gpu::emission_luminance(scene.materials[m].emission)) / table.total_weight;

  // Vose's method: scaled weights below 1 are topped up from one above 1, which becomes their alias.
  const size_t n = weights.size();
  std::vector<double> scaled(n);
  std::vector<uint32_t> small, large;
  for (size_t i = 0; i < n; ++i) {
    scaled[i] = weights[i] * double(n) / table.total_weight;
    (scaled[i] < 1.0 ? small : large).push_back(uint32_t(i));
  }
  while (!small.empty() && !large.empty()) {
    const uint32_t s = small.back(), l = large.back();
    small.pop_back();
    table.entries[s].probability = float(scaled[s]);
    table.entries[s].alias = l;
    scaled[l] -= 1.0 - scaled[s];
    if (scaled[l] < 1.0) {
      large.pop_back();
      small.push_back(l);
    }
  }
  // What is left is 1 up to rounding: kept whole (its alias is itself).
  for (const uint32_t i : small) table.entries[i].probability = 1.0f;
  for (const uint32_t i : large) table.entries[i].probability = 1.0f;
  return table;
}

}  // namespace vkray
