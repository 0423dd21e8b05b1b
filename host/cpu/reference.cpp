#include "cpu/reference.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cfloat>
#include <cmath>
#include <limits>
#include <mutex>
#include <numbers>
#include <thread>

#include "base/errors.h"
#include "base/interrupt.h"
#include "base/threads.h"
#include "bvh/bvh.h"
#include "cpu/integrators.h"
#include "cpu/warp.h"
#include "scene/camera.h"
#include "shared/sampling.h"

namespace vkray::cpu {

ReferenceResult render_reference(const Scene& scene, const ImageSettings& settings, const ReferenceOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  ReferenceResult result;
  const PixelRegion region = options.region.empty() ? full_region(settings.width, settings.height) : options.region;
  if (!region.within(settings.width, settings.height))
    throw InternalError("a CPU render of pixels " + to_string(region) + " outside its image");
  result.region = region;
  result.image = Image(region.width(), region.height());
  result.signatures.assign(region.pixels(), 0);
  result.rays_per_row.assign(region.height(), 0);
  if (options.aovs) result.aovs.emplace(region.width(), region.height());

  SceneBvh built;
  if (options.use_bvh && !options.bvh) {
    built = build_scene_bvh(scene, options.threads);  // --threads holds for the build too
    result.bvh_seconds = built.build_seconds;
  }
  const SceneBvh* bvh = options.use_bvh ? (options.bvh ? options.bvh : &built) : nullptr;
  const Tracer tracer(scene, bvh);
  const Lights lights(tracer, options.shadows, options.sample_environment);
  const bool path = scene.integrator.type == Integrator::Type::path;
  const uint32_t seed = gpu::seed_key(settings.seed);
  const double aperture = scene.camera.aperture_radius, focus = scene.camera.focus_distance;
  const CameraBasis cam = camera_basis(scene.camera, settings.height);
  const SampleStrata strata = sample_strata(settings.samples_per_pixel);
  const dvec3 origin(cam.origin), right(cam.right), up(cam.up), forward(cam.forward);
  const double half_w = settings.width / 2.0, half_h = settings.height / 2.0;

  std::atomic<uint32_t> next_row{0};
  std::atomic<uint64_t> total_rays{0};
  std::atomic<bool> cancelled{false};
  std::mutex progress_mutex;
  uint32_t rows_done = 0;
  auto worker = [&] {
    uint64_t rays = 0;
    for (uint32_t row; !cancelled && (row = next_row++) < region.height();) {
      const uint32_t j = region.y0 + row;
      uint64_t row_rays = 0;
      for (uint32_t i = region.x0; i < region.x1; ++i) {
        if (interrupt_requested()) {  // per pixel: a row of many samples can take seconds
          cancelled = true;
          break;
        }
        const uint32_t index = j * settings.width + i;
        uint64_t signature = 0xcbf29ce484222325ull;
        dvec3 sum(0.0);
        FirstHitSums first_hits;
        for (uint32_t k = 0; k < settings.samples_per_pixel; ++k) {
          // Paths jitter even a single sample (shaders/trace.comp).
          const glm::vec2 xi =
              path ? gpu::jittered_offset(index, seed, k, strata.x, strata.inv_x, strata.inv_y)
                   : gpu::sample_offset(index, seed, k, settings.samples_per_pixel, strata.x, strata.inv_x, strata.inv_y);
          const double x = i + double(xi.x) - half_w, y = half_h - (j + double(xi.y));
          Ray ray{origin, glm::normalize(x * right + y * up + double(cam.focal_px) * forward)};
          SampleState state{gpu::sample_stream(index, seed, k), signature};
          state.first_hit = options.aovs ? &first_hits : nullptr;
          state.first_sample = k == 0;
          if (aperture > 0) {  // the thin lens: from a point of the lens to where the pinhole ray meets the plane of focus
            const double u1 = gpu::next_random(state.stream), u2 = gpu::next_random(state.stream);
            const glm::dvec2 disk = aperture * concentric_disk(u1, u2);
            const dvec3 focus_point = ray.origin + (focus / glm::dot(ray.dir, forward)) * ray.dir;
            ray.origin = origin + disk.x * right + disk.y * up;
            ray.dir = glm::normalize(focus_point - ray.origin);
          }
          sum += path ? path_radiance(tracer, lights, ray, state) : direct_radiance(tracer, lights, ray, state);
          signature = state.signature;
          row_rays += 1 + state.rays;
        }
        const size_t out = size_t(row) * region.width() + (i - region.x0);
        // Radiance past the largest float is held at it, as the GPU's is (packing/scene_packing.h).
        result.image.pixels[out] = glm::vec3(glm::min(sum / double(settings.samples_per_pixel), dvec3(FLT_MAX)));
        result.signatures[out] = signature;
        if (options.aovs) result.aovs->set(i - region.x0, row, first_hits);
      }
      result.rays_per_row[row] = row_rays;
      rays += row_rays;
      if (options.progress && !cancelled) {
        std::lock_guard lock(progress_mutex);
        options.progress(++rows_done, region.height());
      }
    }
    total_rays += rays;
  };

  const unsigned threads = thread_count(options.threads);
  std::vector<std::jthread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  pool.clear();  // joins
  if (cancelled) throw Cancelled();

  result.rays = total_rays;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace vkray::cpu
