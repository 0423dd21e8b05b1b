#include "session/cpu_render.h"

#include <algorithm>
#include <thread>

#include "cpu/reference.h"

namespace vkray {

unsigned cpu_threads(const RenderOptions& options) {
  return options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
}

RenderResult render_on_cpu(const Scene& scene, const RenderOptions& options, const Bvh* bvh,
                           std::vector<uint64_t>* signatures) {
  cpu::ReferenceOptions reference_options;
  reference_options.threads = cpu_threads(options);
  reference_options.bvh = bvh;
  reference_options.shadows = options.shadows;
  reference_options.aovs = options.aovs;
  if (options.progress)
    reference_options.progress = [&options](uint32_t done, uint32_t total) { options.progress("rows", done, total); };
  cpu::ReferenceResult reference = cpu::render_reference(scene, image_settings(scene, options), reference_options);
  RenderResult result;
  result.image = std::move(reference.image);
  result.aovs = std::move(reference.aovs);
  result.stats.trace_seconds = reference.seconds;
  result.stats.rays = reference.rays;
  result.stats.threads = reference_options.threads;
  if (signatures) *signatures = std::move(reference.signatures);
  return result;
}

}  // namespace vkray
