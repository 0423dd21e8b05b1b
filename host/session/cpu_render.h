// Rendering with the CPU reference (host/cpu/reference.h) through the same options and result as
// the GPU path, so that a face treats both renderers alike.
#pragma once

#include <cstdint>
#include <vector>

#include "scene/scene.h"
#include "session/options.h"

namespace vkray {
struct SceneBvh;

// Throws Cancelled on an interrupt request (base/interrupt.h), UsageError for an override out of range.
// `bvh`: one already built for the scene; null builds one (its time is part of the trace).
// `signatures`: where to put each pixel's record of what its samples saw (cpu/reference.h), for
// parity's edge detection.
RenderResult render_on_cpu(const Scene& scene, const RenderOptions& options, const SceneBvh* bvh = nullptr,
                           std::vector<uint64_t>* signatures = nullptr);

// The threads the CPU reference uses for `options`.
unsigned cpu_threads(const RenderOptions& options);

}  // namespace vkray
