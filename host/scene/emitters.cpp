#include "scene/emitters.h"

#include <numbers>

#include "shared/scene_layout.h"

namespace vkray {

double primitive_area(const Scene& scene, uint32_t p) {
  if (p < scene.triangles.size()) {
    const Triangle& t = scene.triangles[p];
    const glm::dvec3 v0(t.v[0]);
    return 0.5 * glm::length(glm::cross(glm::dvec3(t.v[1]) - v0, glm::dvec3(t.v[2]) - v0));
  }
  const double r = scene.spheres[p - scene.triangles.size()].radius;
  return 4.0 * std::numbers::pi * r * r;
}

EmitterTable build_emitter_table(const Scene& scene) {
  EmitterTable table;
  std::vector<double> weights;
  const auto consider = [&](uint32_t p, uint32_t material) {
    const glm::vec3 e = scene.materials[material].emission;
    if (!scene.materials[material].emissive()) return;
    const double weight = primitive_area(scene, p) * double(gpu::emission_luminance(e));
    if (!(weight > 0)) return;
    table.entries.push_back({1.0f, uint32_t(table.entries.size()), p});
    weights.push_back(weight);
    table.total_weight += weight;
  };
  const uint32_t triangles = static_cast<uint32_t>(scene.triangles.size());
  for (uint32_t p = 0; p < triangles; ++p) consider(p, scene.triangles[p].material);
  for (uint32_t s = 0; s < scene.spheres.size(); ++s) consider(triangles + s, scene.spheres[s].material);
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
