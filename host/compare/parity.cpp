#include "compare/parity.h"

#include <algorithm>

#include "bvh/bvh.h"
#include "session/cpu_render.h"

namespace vkray {

ParityResult compare_with_reference(Session& session, std::shared_ptr<const Scene> scene, const RenderOptions& options) {
  const ImageSettings image = image_settings(*scene, options);  // a bad override fails before any work
  // One hierarchy, traversed by both.
  const auto bvh = std::make_shared<const SceneBvh>(build_scene_bvh(*scene));
  RenderOptions with_aovs = options;  // parity covers the first-hit passes too
  with_aovs.aovs = true;
  RenderResult gpu;
  {
    const DeviceScene on_device = session.upload(scene, bvh);
    gpu = session.render(on_device, with_aovs);
  }
  std::vector<uint64_t> signatures;
  RenderResult cpu = render_on_cpu(*scene, with_aovs, bvh.get(), &signatures);
  return judge_parity(image, std::move(gpu), std::move(cpu), std::move(signatures), parity_tolerance(*scene), scene->extent());
}

ParityTolerance parity_tolerance(const Scene& scene) {
  ParityTolerance tolerance;
  // Glass picks reflection or refraction at random, even in the direct model (which shades every
  // other surface, rough glass and thin sheets included, where the ray meets it).
  const bool chooses = std::any_of(scene.materials.begin(), scene.materials.end(),
                                   [](const Material& m) { return m.has(VKRAY_BSDF_DELTA) && m.has(VKRAY_BSDF_TRANSMISSION); });
  const bool emitters = std::any_of(scene.materials.begin(), scene.materials.end(), [](const Material& m) { return m.emissive(); });
  // An environment map is sampled at random too, through cumulative shares the GPU holds in float.
  tolerance.stochastic = scene.integrator.type == Integrator::Type::path || chooses || emitters || scene.environment ||
                         scene.camera.aperture_radius > 0;
  tolerance.textured = std::any_of(scene.materials.begin(), scene.materials.end(), [](const Material& m) { return m.textured(); });
  return tolerance;
}

ParityResult judge_parity(const ImageSettings& image, RenderResult gpu, RenderResult cpu, std::vector<uint64_t> signatures,
                          const ParityTolerance& tolerance, double scene_extent) {
  ParityResult result;
  result.tolerance = tolerance;
  result.image = image;
  result.gpu = std::move(gpu);
  result.cpu = std::move(cpu);
  result.signatures = std::move(signatures);
  result.metrics = compare_images(result.gpu.image, result.cpu.image, result.signatures, result.tolerance);
  if (result.gpu.aovs && result.cpu.aovs)
    compare_aovs(*result.gpu.aovs, *result.cpu.aovs, result.signatures, scene_extent, result.tolerance, result.metrics);
  return result;
}

}  // namespace vkray
