#include "session/cpu_render.h"

#include <algorithm>
#include <thread>

#include "base/threads.h"
#include "bvh/bvh.h"
#include "cpu/reference.h"

namespace vkray {

unsigned cpu_threads(const RenderOptions& options) {
  return thread_count(options.threads);
}

RenderResult render_on_cpu(const Scene& scene, const RenderOptions& options, const SceneBvh* bvh,
                           std::vector<uint64_t>* signatures) {
  cpu::ReferenceOptions reference_options;
  reference_options.threads = cpu_threads(options);
  reference_options.bvh = bvh;
  reference_options.shadows = options.shadows;
  reference_options.sample_environment = options.sample_environment;
  reference_options.aovs = options.aovs;
  if (options.progress)
    reference_options.progress = [&options](uint32_t done, uint32_t total) { options.progress("rows", done, total); };
  const ImageSettings settings = image_settings(scene, options);
  SceneBvh built;  // one BVH for a band's probe and the render
  if (options.region && std::holds_alternative<Band>(*options.region) && !bvh) {
    built = build_scene_bvh(scene, reference_options.threads);
    reference_options.bvh = bvh = &built;
  }
  if (options.region) reference_options.region = resolve_region(scene, settings, *options.region, bvh);
  cpu::ReferenceResult reference = cpu::render_reference(scene, settings, reference_options);
  RenderResult result;
  result.settings = settings;
  result.region = reference.region;
  result.part = options.region.has_value();
  result.image = std::move(reference.image);
  result.aovs = std::move(reference.aovs);
  result.stats.trace_seconds = reference.seconds;
  result.stats.rays = reference.rays;
  result.stats.threads = reference_options.threads;
  if (signatures) *signatures = std::move(reference.signatures);
  return result;
}

}  // namespace vkray
