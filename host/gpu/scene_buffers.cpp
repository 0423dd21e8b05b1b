#include "gpu/scene_buffers.h"

#include <algorithm>
#include <type_traits>
#include <vector>

#include "base/checked.h"
#include "base/errors.h"
#include "base/timing.h"
#include "bvh/bvh.h"
#include "gpu/buffer.h"
#include "packing/inline_scene.h"
#include "packing/scene_packing.h"
#include "shared/types.h"

namespace vkray::gpu {
namespace {

// A texel buffer and its view (RGBA32F for vec4 texels, RGBA32UI for uvec4, R32F for float); never
// empty (Vulkan has no zero-sized buffers), the shader is told the real count.
struct TexelBuffer {
  Buffer buffer;
  vk::raii::BufferView view{nullptr};
};

template <typename Texel>
TexelBuffer make_texel_buffer(const Context& ctx, const std::vector<Texel>& texels, const char* what) {
  static_assert(std::is_same_v<Texel, glm::uvec4> || std::is_same_v<Texel, glm::vec4> || std::is_same_v<Texel, float>);
  constexpr vk::Format format = std::is_same_v<Texel, glm::uvec4>  ? vk::Format::eR32G32B32A32Uint
                                : std::is_same_v<Texel, float> ? vk::Format::eR32Sfloat
                                                               : vk::Format::eR32G32B32A32Sfloat;
  if (texels.size() > ctx.limits().maxTexelBufferElements)
    throw DeviceError(std::string("scene too large for ") + ctx.device_name() + ": " + std::to_string(texels.size()) +
                      " " + what + " texels, maxTexelBufferElements is " +
                      std::to_string(ctx.limits().maxTexelBufferElements));
  static const Texel placeholder(0);  // (R32F is a format every device reads from uniform texel buffers, as RGBA32F)
  const Texel* data = texels.empty() ? &placeholder : texels.data();
  TexelBuffer t;
  const vk::DeviceSize bytes = checked_mul(std::max<size_t>(texels.size(), 1), sizeof(Texel), what);
  t.buffer = upload_buffer(ctx, data, bytes, vk::BufferUsageFlagBits::eUniformTexelBuffer);
  t.view = vk::raii::BufferView(ctx.device(), vk::BufferViewCreateInfo({}, *t.buffer.buffer, format, 0, bytes));
  return t;
}

// The textures' texels, half-float RGBA, in an RGBA16F texel buffer (a format every Vulkan device
// reads from uniform texel buffers; checked anyway, so that a device that does not says so).
TexelBuffer make_texture_buffer(const Context& ctx, const std::vector<uint16_t>& halves) {
  constexpr vk::Format format = vk::Format::eR16G16B16A16Sfloat;
  const size_t texels = halves.size() / 4;
  if (!(ctx.physical_device().getFormatProperties(format).bufferFeatures & vk::FormatFeatureFlagBits::eUniformTexelBuffer))
    throw DeviceError(ctx.device_name() + " cannot read RGBA16F uniform texel buffers, which vkray keeps textures in");
  if (texels > ctx.limits().maxTexelBufferElements)
    throw DeviceError("textures too large for " + ctx.device_name() + ": " + std::to_string(texels) +
                      " texels together, maxTexelBufferElements is " + std::to_string(ctx.limits().maxTexelBufferElements));
  static const uint16_t placeholder[4] = {};
  TexelBuffer t;
  const vk::DeviceSize bytes = checked_mul(std::max<size_t>(texels, 1), 4 * sizeof(uint16_t), "textures");
  t.buffer = upload_buffer(ctx, halves.empty() ? placeholder : halves.data(), bytes, vk::BufferUsageFlagBits::eUniformTexelBuffer);
  t.view = vk::raii::BufferView(ctx.device(), vk::BufferViewCreateInfo({}, *t.buffer.buffer, format, 0, bytes));
  return t;
}

// Refuses, before allocating anything, a scene whose buffers cannot fit the device's memory.
void check_memory(const Context& ctx, const PackedScene& packed) {
  uint64_t texels = packed.nodes.size();
  for (const auto* buffer : {&packed.primitives, &packed.normals, &packed.texcoords, &packed.tangents, &packed.colours, &packed.instances,
                             &packed.materials, &packed.lights, &packed.emitters})
    texels = checked_add(texels, buffer->size(), "scene buffers");
  texels = checked_add(texels, packed.environment.texels.size(), "scene buffers");
  const uint64_t bytes = checked_add(checked_add(checked_mul(texels, sizeof(glm::vec4), "scene buffers"),
                                                 checked_mul(packed.textures.size(), sizeof(uint16_t), "textures"), "scene buffers"),
                                     checked_mul(packed.environment.cdf.size(), sizeof(float), "environment"), "scene buffers");
  const auto memory = ctx.physical_device().getMemoryProperties();
  uint64_t largest_heap = 0;
  for (uint32_t h = 0; h < memory.memoryHeapCount; ++h)
    if (memory.memoryHeaps[h].flags & vk::MemoryHeapFlagBits::eDeviceLocal)
      largest_heap = std::max<uint64_t>(largest_heap, memory.memoryHeaps[h].size);
  if (bytes > largest_heap)
    throw DeviceError("scene too large for " + ctx.device_name() + ": its buffers need " + std::to_string(bytes >> 20) +
                      " MiB, the largest device-local memory heap has " + std::to_string(largest_heap >> 20) + " MiB");
}

// Primitives stored: the scene's own and each mesh's once.
size_t packed_primitive_count(const SceneBvh& bvh) {
  size_t count = bvh.primitives.order.size();
  for (const Bvh& mesh : bvh.meshes) count += mesh.order.size();
  return count;
}

}  // namespace

struct SceneBuffers::Geometry {
  TexelBuffer primitives, normals, nodes, texcoords, textures, tangents, colours, instances;
  PrimitiveSlots slots;  // the lighting's area lights name slots in the primitive buffer
};

struct SceneBuffers::Lighting {
  TexelBuffer materials, lights, emitters, environment, environment_cdf;

  Lighting(const Context& ctx, const PackedLighting& packed)
      : materials(make_texel_buffer(ctx, packed.materials, "material")),
        lights(make_texel_buffer(ctx, packed.lights, "light")),
        emitters(make_texel_buffer(ctx, packed.emitters, "area light")),
        environment(make_texel_buffer(ctx, packed.environment.texels, "environment map")),
        environment_cdf(make_texel_buffer(ctx, packed.environment.cdf, "environment distribution")) {}
};

SceneBuffers::SceneBuffers(std::shared_ptr<const Context> ctx, std::shared_ptr<const Scene> scene, const SceneBvh* prebuilt)
    : ctx_(std::move(ctx)), scene_(std::move(scene)) {
  const auto start = Clock::now();
  SceneBvh built;
  if (!prebuilt) built = build_scene_bvh(*scene_);
  const SceneBvh& bvh = prebuilt ? *prebuilt : built;
  bvh_seconds_ = bvh.build_seconds;
  primitive_count_ = uint32_t(packed_primitive_count(bvh));
  PackedScene packed = pack_scene(*scene_, bvh);
  vertex_normals_ = !packed.normals.empty();
  vertex_colours_ = !packed.colours.empty();
  instances_ = !packed.instances.empty();
  for (size_t p = 0; p < packed.primitives.size() && !see_through_; p += VKRAY_TEXELS_PER_PRIMITIVE)
    see_through_ = (primitive_flags(packed.primitives[p]) & VKRAY_PRIM_ALPHA) != 0u;
  // A scene with instances is walked in two levels; the compiled-in form holds one.
  if (primitive_count_ <= kMaxInlinePrimitives && !instances_) inline_scene_ = inline_scene_glsl(packed);
  check_memory(*ctx_, packed);
  geometry_ = std::make_shared<const Geometry>(Geometry{make_texel_buffer(*ctx_, packed.primitives, "primitive"),
                                                        make_texel_buffer(*ctx_, packed.normals, "normal"),
                                                        make_texel_buffer(*ctx_, packed.nodes, "BVH node"),
                                                        make_texel_buffer(*ctx_, packed.texcoords, "texture coordinate"),
                                                        make_texture_buffer(*ctx_, packed.textures),
                                                        make_texel_buffer(*ctx_, packed.tangents, "tangent"),
                                                        make_texel_buffer(*ctx_, packed.colours, "vertex colour"),
                                                        make_texel_buffer(*ctx_, packed.instances, "instance"), std::move(packed.slots)});
  lighting_ = std::make_unique<Lighting>(*ctx_, packed);
  lighting_frame_ = packed.frame;
  environment_seconds_ = packed.environment_seconds;
  // A BVH built beforehand (perhaps while the shaders compiled) still counts: the upload stage
  // reports the build's own time.
  upload_seconds_ = seconds_since(start) + (prebuilt ? prebuilt->build_seconds : 0.0);
}

SceneBuffers::SceneBuffers(const SceneBuffers& same, std::shared_ptr<const Scene> scene)
    : ctx_(same.ctx_),
      scene_(std::move(scene)),
      geometry_(same.geometry_),
      primitive_count_(same.primitive_count_),
      inline_scene_(same.inline_scene_),
      shares_geometry_(true),
      vertex_normals_(same.vertex_normals_),
      vertex_colours_(same.vertex_colours_),
      instances_(same.instances_),
      see_through_(same.see_through_) {
  if (!same_geometry(same.scene(), *scene_)) throw InternalError("a scene shares the device buffers of one with other geometry");
  const auto start = Clock::now();
  const PackedLighting packed = pack_lighting(*scene_, geometry_->slots);
  lighting_ = std::make_unique<Lighting>(*ctx_, packed);
  lighting_frame_ = packed.frame;
  environment_seconds_ = packed.environment_seconds;
  upload_seconds_ = seconds_since(start);
}

SceneBuffers::~SceneBuffers() = default;

void SceneBuffers::bind(DescriptorWriter& writer) const {
  writer.texel_buffer(VKRAY_BINDING_PRIMITIVES, *geometry_->primitives.view)
      .texel_buffer(VKRAY_BINDING_NORMALS, *geometry_->normals.view)
      .texel_buffer(VKRAY_BINDING_NODES, *geometry_->nodes.view)
      .texel_buffer(VKRAY_BINDING_MATERIALS, *lighting_->materials.view)
      .texel_buffer(VKRAY_BINDING_LIGHTS, *lighting_->lights.view)
      .texel_buffer(VKRAY_BINDING_EMITTERS, *lighting_->emitters.view)
      .texel_buffer(VKRAY_BINDING_TEXCOORDS, *geometry_->texcoords.view)
      .texel_buffer(VKRAY_BINDING_TEXTURES, *geometry_->textures.view)
      .texel_buffer(VKRAY_BINDING_TANGENTS, *geometry_->tangents.view)
      .texel_buffer(VKRAY_BINDING_COLOURS, *geometry_->colours.view)
      .texel_buffer(VKRAY_BINDING_INSTANCES, *geometry_->instances.view)
      .texel_buffer(VKRAY_BINDING_ENVIRONMENT, *lighting_->environment.view)
      .texel_buffer(VKRAY_BINDING_ENVIRONMENT_CDF, *lighting_->environment_cdf.view);
}

}  // namespace vkray::gpu
