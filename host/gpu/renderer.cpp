#include "gpu/renderer.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <optional>

#include "base/checked.h"
#include "base/errors.h"
#include "base/interrupt.h"
#include "base/timing.h"
#include "gpu/buffer.h"
#include "gpu/tiling.h"
#include "packing/scene_packing.h"
#include "shared/first_hit_layout.h"
#include "shared/types.h"

namespace vkray::gpu {
namespace {

// A render's first submission aims at about this many ray-primitive tests: a fraction of a second
// on lavapipe with 2 cores, so that not even the first one runs long on a slow device.
constexpr double kTestsPerTile = double(1 << 26);

// Rays one sample traces, roughly: the camera ray and each light's shadow ray; a path these at each
// of its vertices, with a shadow ray to an area light and one to the background besides.
double rays_per_sample(const Scene& scene) {
  if (scene.integrator.type == Integrator::Type::direct) return 1.0 + double(scene.lights.size());
  // Past rr_depth a path goes on with probability at most 0.95: 20 more vertices on average at most.
  const double rr_vertices = double(scene.integrator.rr_depth) + 20.0;
  const double vertices = scene.integrator.max_depth > 0 ? std::min(double(scene.integrator.max_depth), rr_vertices) : rr_vertices;
  return (3.0 + double(scene.lights.size())) * vertices;
}

// Ray-primitive tests one sample costs through the BVH, roughly: a ray visits on the order of
// log2(N) nodes and a few leaves.
double tests_per_sample(const Scene& scene) {
  const double primitives = double(PrimitiveNumbering(scene).count()) + 1.0;  // as placed
  return (8.0 + 4.0 * std::log2(primitives)) * rays_per_sample(scene);
}

// The first submission's pixels: a square (its side a multiple of the workgroup's, at most the
// image's longer side rounded up) whose ray-primitive tests stay near kTestsPerTile whatever the
// scene size and sample count.
uint64_t first_submission_pixels(const Scene& scene, const ImageSettings& image) {
  const double pixels = kTestsPerTile / (tests_per_sample(scene) * image.samples_per_pixel);
  const uint32_t side = static_cast<uint32_t>(std::sqrt(pixels)) / VKRAY_WORKGROUP_X * VKRAY_WORKGROUP_X;
  const uint32_t largest = (std::max(image.width, image.height) + VKRAY_WORKGROUP_X - 1) / VKRAY_WORKGROUP_X * VKRAY_WORKGROUP_X;
  const uint64_t clamped = std::clamp<uint32_t>(side, VKRAY_WORKGROUP_X, largest);
  return clamped * clamped;
}


// Every submission after the first aims at this much device time, at the rate the ones before it
// ran: long enough that a submission's fixed costs vanish on a fast GPU, and that llvmpipe's threads
// wait little at the end of each dispatch (each takes a contiguous share of its workgroups, and the
// one done first waits for the others: the fewer workgroups, the longer); short enough that
// progress, Ctrl-C (which waits for the running submission) and a display watchdog are not kept
// waiting on a slow device. Well below --tile-timeout's default of a minute (docs/commands.md).
constexpr double kSubmissionSeconds = 0.4;
// The most pixels a submission (an output slot) holds: 64 MiB a slot, two slots.
constexpr uint64_t kMostSlotPixels = uint64_t(1) << 22;


bool is_timeout(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const TimeoutError&) {
    return true;
  } catch (...) {
    return false;
  }
}


// The output holds two submissions' pixels (slots), not the image: any image size fits the
// device's maxStorageBufferRange (128 MiB on lavapipe). One slot is traced while the other is read
// back.
constexpr uint32_t kSlots = 2;
// Tiles and bands are cut in whole workgroups.
constexpr uint32_t kGranule = VKRAY_WORKGROUP_X;

// How a render's submissions fit the output's slots.
struct SlotPlan {
  uint64_t slot_pixels = 0;  // the most pixels one submission holds
  uint32_t tile_side = 0;    // square tiles of this side; 0: bands sized by SubmissionSizer
};

// Square tiles of request.tile_side when asked for (smaller where a slot cannot hold one), otherwise
// bands. Throws DeviceError when not even the least submission fits the device.
SlotPlan plan_slots(const Context& ctx, const TraceRequest& request, const PixelRegion& region) {
  // The larger of the two outputs per pixel bounds a slot: the AOVs' when asked for.
  const uint64_t pixel_bytes = request.variant.aovs ? sizeof(FirstHitTexels) : sizeof(glm::vec4);
  const uint64_t slot_limit = ctx.limits().maxStorageBufferRange / (kSlots * pixel_bytes);
  const uint64_t image_pixels = region.pixels();
  const bool fixed_tiles = request.tile_side > 0;
  uint32_t side = request.tile_side;
  const auto square_pixels = [&] { return uint64_t(std::min(side, region.width())) * std::min(side, region.height()); };
  while (fixed_tiles && side > kGranule && square_pixels() > slot_limit) side -= kGranule;
  // The least a slot must hold: the square asked for, or the smallest piece a submission may be.
  const uint64_t needed = fixed_tiles ? square_pixels() : std::min<uint64_t>(image_pixels, kGranule * kGranule);
  if (needed > slot_limit)
    throw DeviceError("a render tile does not fit " + ctx.device_name() + ": " + std::to_string(kSlots * needed * pixel_bytes) +
                      " bytes of output, maxStorageBufferRange is " + std::to_string(ctx.limits().maxStorageBufferRange));
  if (fixed_tiles) return {needed, side};
  return {std::min({kMostSlotPixels, slot_limit, std::max<uint64_t>(image_pixels, kGranule * kGranule)}), 0};
}

// Where the next tile comes from: the region cut in squares of the plan's side, or in bands sized by
// the time the ones before took. Tiles are in the image's coordinates, which the shader's sample
// pattern takes.
class TileSource {
 public:
  TileSource(const Scene& scene, const TraceRequest& request, const PixelRegion& region, const SlotPlan& plan)
      : region_(region),
        side_(plan.tile_side),
        cursor_(region.width(), region.height(), kGranule),
        sizer_(sizer(first_submission_pixels(scene, request.image), plan, request.tile_timeout)) {}

  bool done() const { return cursor_.done(); }
  TileRect next() {
    TileRect rect = side_ > 0 ? cursor_.next_square(side_) : cursor_.next(sizer_.next());
    rect.x0 += region_.x0;
    rect.y0 += region_.y0;
    return rect;
  }
  // A submission of `pixels` took `seconds` of device time.
  void finished(uint64_t pixels, double seconds) { sizer_.finished(pixels, seconds); }

 private:
  // The first submission is the size the cost model gives; the sizer takes over from the second's
  // time on, aiming at a tenth of --tile-timeout at most, so that growing 8x from a cheap
  // submission stays within it.
  static SubmissionSizer sizer(uint64_t first, const SlotPlan& plan, std::chrono::milliseconds tile_timeout) {
    const double target_seconds = std::min(kSubmissionSeconds, 0.1 * std::chrono::duration<double>(tile_timeout).count());
    return SubmissionSizer(first, std::max<uint64_t>(kGranule * kGranule, first / 64), plan.slot_pixels, target_seconds);
  }

  PixelRegion region_;
  uint32_t side_;
  TileCursor cursor_;
  SubmissionSizer sizer_;
};

// The push constants of a tile traced in `slot`, but for its samples.
TileConstants tile_constants(const TileRect& rect, uint32_t slot, uint64_t slot_pixels) {
  TileConstants tile{};
  tile.x0 = rect.x0;
  tile.y0 = rect.y0;
  tile.width = rect.width;
  tile.height = rect.height;
  tile.row_stride = row_stride((tile.height + VKRAY_WORKGROUP_Y - 1) / VKRAY_WORKGROUP_Y);
  tile.output_offset = uint32_t(slot * slot_pixels);
  tile.probe_iterations = 2;
  return tile;
}

}  // namespace

FirstHitSums first_hit_sums(const FirstHitTexels& texels) {
  FirstHitSums sums;
  sums.albedo = first_hit_albedo(texels);
  sums.hits = first_hit_count(texels);
  sums.normal = first_hit_normal(texels);
  sums.object = first_hit_object(texels);
  sums.position = first_hit_position(texels);
  sums.depth = first_hit_depth(texels);
  return sums;
}

// The most samples of a pixel one dispatch traces. llvmpipe ends every loop of an invocation once
// the invocation has made 65535 loop iterations in all (Mesa 22.3's loop limiter), without a word:
// at 16 x 16 pixels of the Cornell box, 2048 spp in one dispatch gave an image 29% too dark (1024 did
// not). A sample's loop iterations (the sample loop, the light loop, each ray's BVH walk) are bounded
// by its estimated tests; a dispatch gets at most half the limit of them, and at most 64 samples.
// A scene compiled into the shader has no walk: a ray makes no iteration, or one for each surface
// it passes in a scene with see-through surfaces (counted as 8), and a dispatch gets at most 256
// samples. More samples a dispatch even out what a lane's paths cost: the lanes of a batch wait for
// the one whose paths were longest, less so the more paths each adds up (the sphere grid: 4.6%
// fewer instructions at 256 samples a dispatch than at 32).
// That is an estimate (a path's length is random): the shader says when its loops were cut short
// (VKRAY_LOOPS_CUT_SHORT), and the tile is traced again with half as many samples a dispatch.
uint32_t samples_in_one_dispatch(const Scene& scene, const ShaderVariant& variant) {
  if (!variant.inline_scene.empty())
    return uint32_t(std::clamp(32768.0 / ((variant.alpha ? 8.0 : 1.0) * rays_per_sample(scene)), 1.0, 256.0));
  return uint32_t(std::clamp(32768.0 / tests_per_sample(scene), 1.0, 64.0));
}

void record_sample_dispatches(const vk::raii::CommandBuffer& cb, vk::PipelineLayout layout, TileConstants tile,
                              uint32_t sample_begin, uint32_t sample_end, uint32_t samples_per_dispatch) {
  const uint32_t groups_x = (tile.width + VKRAY_WORKGROUP_X - 1) / VKRAY_WORKGROUP_X;
  const uint32_t groups_y = (tile.height + VKRAY_WORKGROUP_Y - 1) / VKRAY_WORKGROUP_Y;
  for (tile.sample_begin = sample_begin; tile.sample_begin < sample_end; tile.sample_begin = tile.sample_end) {
    tile.sample_end = std::min(sample_end, tile.sample_begin + samples_per_dispatch);
    if (tile.sample_begin > sample_begin) {  // the last dispatch's sums are read by this one
      const vk::MemoryBarrier sums(vk::AccessFlagBits::eShaderWrite,
                                   vk::AccessFlagBits::eShaderRead | vk::AccessFlagBits::eShaderWrite);
      cb.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eComputeShader, {}, sums, {}, {});
    }
    cb.pushConstants<TileConstants>(layout, vk::ShaderStageFlagBits::eCompute, 0, tile);
    cb.dispatch(groups_x, groups_y, 1);
  }
  // The shader's writes are read by the host after the fence.
  const vk::MemoryBarrier to_host(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eHostRead);
  cb.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eHost, {}, to_host, {}, {});
}

// Everything one render's submissions use. Declaration order is destruction order reversed: the
// command buffer before its pool, the descriptor set before the buffers, the pipeline and the
// scene (and through them the device) last.
struct Renderer::Frame {
  // Binds a frame: the frame's uniforms, the output's slots and the descriptor set.
  Frame(const Context& ctx, std::shared_ptr<const TracePipeline> trace_pipeline, std::shared_ptr<const SceneBuffers> scene,
        const ImageSettings& image, const SlotPlan& plan, bool aovs);
  // A command buffer and a fence for each slot.
  void create_commands(const Context& ctx);
  // Records and submits the next submission: `rect`'s samples, at most samples_per_dispatch of them
  // in one dispatch.
  void submit_tile(const Context& ctx, const TileRect& rect, uint32_t samples_per_pixel, uint32_t samples_per_dispatch);
  // Waits for submission `index` and frees its fence; returns when it was seen finished.
  Clock::time_point wait_for_tile(const Context& ctx, uint32_t index, std::chrono::milliseconds timeout);
  // Copies submission `index`'s pixels into `result` (and its first-hit passes into `aovs`, when
  // asked for), both in the region's coordinates, and adds its rays. Returns false, having copied
  // nothing, when the driver cut its loops short.
  bool read_tile_back(const vk::raii::Device& device, uint32_t index, const PixelRegion& region, Image& result, Aovs* aovs,
                      uint64_t& rays) const;

  struct Submitted {
    TileRect rect;
    Clock::time_point at;
  };

  std::shared_ptr<const TracePipeline> trace_pipeline;
  std::shared_ptr<const SceneBuffers> scene;
  std::shared_ptr<const vk::raii::Pipeline> pipeline;
  SlotPlan plan;
  Buffer uniforms;
  Buffer output;  // kSlots tiles' slots: one traced while the other is read back
  Buffer aov_output;  // the same slots' first-hit passes (a placeholder when not asked for)
  std::optional<DescriptorSet> descriptors;
  vk::raii::CommandPool command_pool{nullptr};
  vk::raii::CommandBuffers command_buffers{nullptr};  // one per slot
  std::vector<vk::raii::Fence> fences;                // one per slot
  std::array<Submitted, kSlots> slots{};              // submission i is in slots[i % kSlots] until read back
  uint32_t submitted = 0;
  std::vector<vk::Fence> in_flight;                   // submitted and not yet waited for
  bool timed_out = false;                             // left running by a TimeoutError, not an interrupt
};

Renderer::Frame::Frame(const Context& ctx, std::shared_ptr<const TracePipeline> trace_pipeline_in,
                       std::shared_ptr<const SceneBuffers> scene_in, const ImageSettings& image, const SlotPlan& plan_in,
                       bool aovs)
    : trace_pipeline(std::move(trace_pipeline_in)), scene(std::move(scene_in)), plan(plan_in) {
  const FrameUniforms frame_uniforms = pack_frame(scene->scene(), scene->primitive_count(), scene->lighting(), image);
  uniforms = upload_buffer(ctx, &frame_uniforms, sizeof(frame_uniforms), vk::BufferUsageFlagBits::eUniformBuffer);
  using M = vk::MemoryPropertyFlagBits;
  const vk::DeviceSize output_bytes = kSlots * plan.slot_pixels * sizeof(glm::vec4);
  output = create_buffer(ctx, output_bytes, vk::BufferUsageFlagBits::eStorageBuffer, M::eHostVisible, M::eHostCached);
  const vk::DeviceSize aov_bytes = (aovs ? kSlots * plan.slot_pixels : 1) * sizeof(FirstHitTexels);
  aov_output = create_buffer(ctx, aov_bytes, vk::BufferUsageFlagBits::eStorageBuffer, M::eHostVisible, M::eHostCached);
  DescriptorWriter writer = trace_pipeline->descriptors().writer();
  writer.buffer(VKRAY_BINDING_FRAME, *uniforms.buffer).buffer(VKRAY_BINDING_OUTPUT, *output.buffer);
  writer.buffer(VKRAY_BINDING_AOVS, *aov_output.buffer);
  scene->bind(writer);
  descriptors = writer.write();
}

void Renderer::Frame::create_commands(const Context& ctx) {
  const vk::raii::Device& device = ctx.device();
  command_pool = vk::raii::CommandPool(device, {vk::CommandPoolCreateFlagBits::eResetCommandBuffer, ctx.queue_family()});
  command_buffers = vk::raii::CommandBuffers(device, {*command_pool, vk::CommandBufferLevel::ePrimary, kSlots});
  fences.reserve(kSlots);
  for (uint32_t slot = 0; slot < kSlots; ++slot) fences.emplace_back(device, vk::FenceCreateInfo{});
  in_flight.reserve(kSlots);  // so that recording a submission cannot fail after it is made
}

void Renderer::Frame::submit_tile(const Context& ctx, const TileRect& rect, uint32_t samples_per_pixel,
                                  uint32_t samples_per_dispatch) {
  const uint32_t slot = submitted++ % kSlots;
  slots[slot] = {rect, Clock::now()};
  TileConstants tile = tile_constants(rect, slot, plan.slot_pixels);
  const vk::PipelineLayout layout = *trace_pipeline->layout();
  const vk::raii::CommandBuffer& cb = command_buffers[slot];
  // The slot's command buffer and output were last used by the submission before the last, waited
  // for and read.
  cb.reset();
  cb.begin({vk::CommandBufferUsageFlagBits::eOneTimeSubmit});
  cb.bindPipeline(vk::PipelineBindPoint::eCompute, **pipeline);
  cb.bindDescriptorSets(vk::PipelineBindPoint::eCompute, layout, 0, descriptors->get(), {});
  record_sample_dispatches(cb, layout, tile, 0, samples_per_pixel, samples_per_dispatch);
  cb.end();
  const vk::CommandBuffer raw = *cb;
  const vk::Fence fence = *fences[slot];
  ctx.queue().submit(vk::SubmitInfo({}, {}, raw), fence);
  in_flight.push_back(fence);  // reserved: cannot throw
}

Clock::time_point Renderer::Frame::wait_for_tile(const Context& ctx, uint32_t index, std::chrono::milliseconds timeout) {
  const vk::raii::Fence& fence = fences[index % kSlots];
  ctx.wait(fence, timeout, "a render tile");
  const auto finished = Clock::now();
  std::erase(in_flight, *fence);
  ctx.device().resetFences(*fence);
  return finished;
}

bool Renderer::Frame::read_tile_back(const vk::raii::Device& device, uint32_t index, const PixelRegion& region, Image& result,
                                     Aovs* aovs, uint64_t& rays) const {
  const TileConstants tile = tile_constants(slots[index % kSlots].rect, index % kSlots, plan.slot_pixels);
  output.invalidate(device);
  const auto* texels = static_cast<const glm::vec4*>(output.mapped) + tile.output_offset;
  const RadianceUnscale unscale(scene->lighting().radiance_exponent);  // the shader's radiance is scaled
  // One pass: a tile whose loops were cut short is traced again, and what it left here is overwritten.
  uint64_t tile_rays = 0;
  uint32_t cut_short = 0;
  for (uint32_t y = 0; y < tile.height; ++y) {
    const glm::vec4* row = texels + size_t(y) * tile.width;
    glm::vec3* out = &result.at(tile.x0 - region.x0, tile.y0 - region.y0 + y);
    for (uint32_t x = 0; x < tile.width; ++x) {
      const uint32_t count = std::bit_cast<uint32_t>(row[x].w);
      out[x] = unscale(glm::vec3(row[x]));
      tile_rays += count;
      cut_short |= count & VKRAY_LOOPS_CUT_SHORT;
    }
  }
  if (cut_short != 0) return false;
  rays += tile_rays;
  if (aovs) {
    aov_output.invalidate(device);
    const auto* first_hits = static_cast<const FirstHitTexels*>(aov_output.mapped) + tile.output_offset;
    for (uint32_t y = 0; y < tile.height; ++y)
      for (uint32_t x = 0; x < tile.width; ++x)
        aovs->set(tile.x0 - region.x0 + x, tile.y0 - region.y0 + y, first_hit_sums(first_hits[size_t(y) * tile.width + x]));
  }
  return true;
}

Renderer::Renderer(std::shared_ptr<const Context> ctx) : ctx_(std::move(ctx)) {}

Renderer::~Renderer() {
  try {
    if (!busy(std::chrono::milliseconds(0))) return;
  } catch (...) {  // a failed wait says nothing of whether the work is done: leave it, as below
  }
  // The device is still running a tile that timed out. Destroying what it uses (or the device)
  // could hang or crash the driver: leave all of it, and the Context it keeps alive, to the process.
  for (auto& frame : abandoned_) static_cast<void>(frame.release());
  ctx_->abandon_work();
}

bool Renderer::busy_after_interrupts(std::chrono::milliseconds wait) {
  const auto deadline = Clock::now() + wait;
  for (auto it = abandoned_.begin(); it != abandoned_.end(); ++it) {
    if ((*it)->timed_out || (*it)->in_flight.empty()) continue;
    // In slices, so that a new interrupt request is not kept waiting (Cancelled).
    while (true) {
      const auto left = std::max(std::chrono::nanoseconds(0), std::chrono::nanoseconds(deadline - Clock::now()));
      const auto slice = std::min<std::chrono::nanoseconds>(left, std::chrono::milliseconds(50));
      try {
        if (ctx_->device().waitForFences((*it)->in_flight, VK_TRUE, uint64_t(slice.count())) != vk::Result::eTimeout) break;
      } catch (const vk::DeviceLostError&) {  // nothing runs on a lost device any more
        break;
      }
      if (left == std::chrono::nanoseconds(0)) return true;
      throw_if_interrupted();
    }
  }
  return busy(std::chrono::milliseconds(0));
}

bool Renderer::busy(std::chrono::milliseconds wait) {
  const auto deadline = Clock::now() + wait;
  for (auto it = abandoned_.begin(); it != abandoned_.end();) {
    const auto left = std::max(std::chrono::nanoseconds(0), std::chrono::nanoseconds(deadline - Clock::now()));
    try {
      const auto& fences = (*it)->in_flight;
      if (!fences.empty() &&
          ctx_->device().waitForFences(fences, VK_TRUE, uint64_t(left.count())) == vk::Result::eTimeout)
        return true;
    } catch (const vk::DeviceLostError&) {  // nothing runs on a lost device any more
    }
    it = abandoned_.erase(it);
  }
  return false;
}

Image Renderer::render(std::shared_ptr<const TracePipeline> trace_pipeline, std::shared_ptr<const SceneBuffers> scene,
                       const TraceRequest& request, TraceStats* stats_out, Aovs* aovs_out) {
  if (busy(request.tile_timeout))
    throw TimeoutError("the device is still running a render tile that timed out before, " +
                       std::to_string(request.tile_timeout.count()) + " ms later");
  const ImageSettings& image = request.image;
  const PixelRegion region = request.region.empty() ? full_region(image.width, image.height) : request.region;
  if (!region.within(image.width, image.height))
    throw InternalError("a render of pixels " + to_string(region) + " outside its image");
  const bool aovs = request.variant.aovs;
  if (aovs && !aovs_out) throw InternalError("a render of the first-hit passes with nowhere to put them");

  TraceStats stats;
  auto start = Clock::now();
  const SlotPlan plan = plan_slots(*ctx_, request, region);
  Image result(region.width(), region.height());  // the host's copy, filled tile by tile
  if (aovs) *aovs_out = Aovs(region.width(), region.height());
  auto frame = std::make_unique<Frame>(*ctx_, std::move(trace_pipeline), std::move(scene), image, plan, aovs);
  stats.upload_seconds = seconds_since(start);

  frame->pipeline = frame->trace_pipeline->pipeline(request.variant);  // compiled here unless asked for before
  start = Clock::now();
  frame->create_commands(*ctx_);
  abandoned_.reserve(abandoned_.size() + 1);  // so that keeping the frame when the device still runs it cannot fail
  try {
    trace_tiles(*frame, request, region, result, aovs ? aovs_out : nullptr, stats);
  } catch (...) {
    // Timed out, interrupted, or any other failure while a tile may still run: what it uses is kept
    // until the device is done with it (busy()), never destroyed under it.
    if (!frame->in_flight.empty()) {
      frame->timed_out = is_timeout(std::current_exception());
      abandoned_.push_back(std::move(frame));  // reserved: cannot throw
    }
    throw;
  }
  // Reading back overlaps tracing: the trace is the whole span (so rays/s are not flattered), the
  // read back its own part of it.
  stats.trace_seconds = seconds_since(start);
  stats.tiles = frame->submitted;
  if (stats_out) *stats_out = stats;
  return result;
}

void Renderer::trace_tiles(Frame& frame, const TraceRequest& request, const PixelRegion& region, Image& result, Aovs* aovs,
                           TraceStats& stats) {
  TileSource tiles(frame.scene->scene(), request, region, frame.plan);
  uint32_t samples_per_dispatch = samples_in_one_dispatch(frame.scene->scene(), request.variant);
  const uint32_t samples = request.image.samples_per_pixel;
  Clock::time_point last_finished;
  uint64_t pixels_done = 0;
  frame.submit_tile(*ctx_, tiles.next(), samples, samples_per_dispatch);
  for (uint32_t finished = 0; finished < frame.submitted; ++finished) {
    // The next one is queued behind the one waited for below: the device never idles.
    if (!tiles.done()) frame.submit_tile(*ctx_, tiles.next(), samples, samples_per_dispatch);
    const Frame::Submitted done = frame.slots[finished % kSlots];
    const Clock::time_point read_start = frame.wait_for_tile(*ctx_, finished, request.tile_timeout);
    // The device ran it from when it was submitted or, queued behind the one before, from when
    // that one finished. The first one's time also holds the driver's compile (lavapipe compiles
    // at the first dispatch): not a rate to go by.
    if (finished > 0) tiles.finished(done.rect.pixels(), seconds_between(std::max(done.at, last_finished), read_start));
    last_finished = read_start;
    const bool complete = frame.read_tile_back(ctx_->device(), finished, region, result, aovs, stats.rays);
    stats.readback_seconds += seconds_since(read_start);
    if (complete) {
      pixels_done += done.rect.pixels();
      if (request.progress) request.progress(uint32_t(pixels_done), uint32_t(region.pixels()));
    } else {
      if (samples_per_dispatch == 1)
        throw DeviceError(ctx_->device_name() + " cut the shader's loops short within one sample of a pixel (llvmpipe "
                          "stops an invocation after 65535 loop iterations): the scene needs more than that");
      samples_per_dispatch = std::max(1u, samples_per_dispatch / 2);  // the rest of the render too
      frame.submit_tile(*ctx_, done.rect, samples, samples_per_dispatch);
    }
    if (!tiles.done() && interrupt_requested()) throw Cancelled();
  }
}

}  // namespace vkray::gpu
