// The scene in the layout the shader reads (shaders/shared/scene_layout.h, types.h): texel arrays, frame uniforms
// and the tile constants' row order. No Vulkan here, so it is testable without a device.
#pragma once

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "bvh/bvh.h"
#include "scene/scene.h"
#include "packing/environment_packing.h"
#include "shared/scene_layout.h"
#include "shared/types.h"

namespace vkray::gpu {

// What the frame goes by that depends on the lighting: the area lights' table's entries
// (FrameUniforms::emitter_count), and the power of two by which every radiance the shader reads is
// scaled (shared/types.h): 2^radiance_exponent.
struct LightingFrame {
  uint32_t emitter_count = 0;
  int radiance_exponent = 0;
  uint32_t environment_width = 0, environment_height = 0;  // PackedEnvironment's
};

// The exponent k that brings the scene's brightest radiance (an emission, the background or the
// environment map's brightest texel, the ambient term, a light's intensity) to [2^19, 2^20) when multiplied by 2^k; 0 when all are 0.
// Headroom above of 2^108 (3e32) for the factors a sample picks up on its way (a point light's
// 1 / r^2, at least 1e-28 with the scene at least 1e-9 across; the area-light estimator's area /
// r^2; glass's eta^2); room below of 2^145 (4e43) before the floats a GPU may flush to zero, for the
// dimmest light (at most 1e30 times dimmer than the brightest, scene/emitters.h) times the factors
// that dim it. Powers of two scale floats exactly.
int radiance_exponent(const Scene& scene);

// The shader's radiance back in the scene's units: `scaled` times 2^-radiance_exponent, exactly,
// with values past the largest float held at it. A float times a power of two is exact in a double
// and rounds once on the way back to float, as ldexp does; the factor is made once, since reading
// an image back runs this for every pixel (three ldexp calls a pixel held a GPU's read back to
// 50 Mpixels/s).
class RadianceUnscale {
 public:
  explicit RadianceUnscale(int radiance_exponent) : factor_(std::ldexp(1.0, -radiance_exponent)) {}
  glm::vec3 operator()(glm::vec3 scaled) const {
    glm::vec3 out;
    for (int c = 0; c < 3; ++c) out[c] = float(std::min(double(scaled[c]) * factor_, double(FLT_MAX)));
    return out;
  }

 private:
  double factor_;
};

glm::vec3 unscale_radiance(glm::vec3 scaled, int radiance_exponent);

// Where the packed primitives lie, for the lighting to name an area light's slot.
struct PrimitiveSlots {
  std::vector<uint32_t> own;                   // the scene's own primitive (primitive_boxes order) -> its slot
  std::vector<std::vector<uint32_t>> meshes;   // a mesh's triangle -> its slot
  std::vector<uint32_t> instances;             // Scene::instances -> its entry in the instance buffer
};

// The buffers that depend on the primitives alone (same_geometry), which a scene whose camera,
// lights or materials change keeps on the device.
struct PackedGeometry {
  std::vector<glm::vec4> primitives;  // PrimitiveTexels (shared/scene_layout.h) each, in BVH leaf order
  std::vector<glm::vec4> normals;     // VKRAY_TEXELS_PER_PRIMITIVE texels each; empty when nothing is smooth
  std::vector<glm::uvec4> nodes;      // VKRAY_TEXELS_PER_NODE texels each (pack_nodes)
  std::vector<glm::vec4> texcoords;   // VKRAY_TEXELS_PER_TEXCOORDS texels each; empty when nothing is textured
  std::vector<glm::vec4> tangents;    // VKRAY_TEXELS_PER_PRIMITIVE texels each; empty when no material has a normal map
  std::vector<glm::vec4> colours;     // VKRAY_TEXELS_PER_PRIMITIVE texels each; empty when no triangle is coloured
  std::vector<glm::vec4> instances;   // VKRAY_TEXELS_PER_INSTANCE texels each; empty when the scene has none
  PrimitiveSlots slots;
  // Every texture's texels, in Scene::textures order: half floats, 4 a texel (an RGBA16F texel buffer).
  std::vector<uint16_t> textures;
};

// The buffers of what lights the scene.
struct PackedLighting {
  std::vector<glm::vec4> materials;   // VKRAY_TEXELS_PER_MATERIAL texels each
  std::vector<glm::vec4> lights;      // VKRAY_TEXELS_PER_LIGHT texels each
  std::vector<glm::vec4> emitters;    // VKRAY_TEXELS_PER_EMITTER texels each (scene/emitters.h)
  PackedEnvironment environment;
  double environment_seconds = 0;  // building the environment map's distribution (and packing its texels)
  LightingFrame frame;
};

// The scene's buffers; the per-frame uniforms come from pack_frame().
struct PackedScene : PackedGeometry, PackedLighting {};

PackedScene pack_scene(const Scene& scene, const SceneBvh& bvh);
// Where each of Scene::textures starts in PackedGeometry::textures, in texels. Throws LimitError when
// the textures together pass 2^31 texels.
std::vector<uint32_t> texture_offsets(const Scene& scene);
// Throws LimitError where the two levels together are deeper than the GPU's traversal stack holds.
PackedGeometry pack_geometry(const Scene& scene, const SceneBvh& bvh);
// `slots`: those of the primitive buffer the lighting goes with.
PackedLighting pack_lighting(const Scene& scene, const PrimitiveSlots& slots);

// The binary BVH as the shader reads it: 4-wide nodes, each a binary node with its children's
// children, child boxes quantized to 8 bits per side (layout in shaders/shared/scene_layout.h). Empty when
// the BVH is.
std::vector<glm::uvec4> pack_nodes(const Bvh& bvh);

// Child c's box as the shader decodes it from a packed node at `node` (texels node..node+3).
Aabb unpack_child_box(const glm::uvec4* node, int c);

// The per-frame uniforms (camera, image, counts). `image` is the resolution actually rendered (the
// scene's, or the command line's).
FrameUniforms pack_frame(const Scene& scene, uint32_t primitive_count, const LightingFrame& lighting, const ImageSettings& image);

// TileConstants::row_stride for a dispatch of `rows` workgroup rows: the integer nearest
// rows / golden ratio that is coprime with rows (so r -> r * stride mod rows is a permutation, and
// consecutive rows land far apart). 1 for rows <= 2.
uint32_t row_stride(uint32_t rows);

}  // namespace vkray::gpu
