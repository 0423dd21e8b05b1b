#include "packing/scene_packing.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cfloat>
#include <cmath>
#include <numeric>

#include <glm/gtc/matrix_access.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "base/check.h"
#include "base/errors.h"
#include "base/interrupt.h"
#include "scene/camera.h"
#include "scene/emitters.h"
#include "shared/sampling.h"

namespace vkray::gpu {
namespace {

// Runs body(begin, end) over [0, count) in blocks on oneTBB's threads; a count of one block runs on
// the caller's thread, so that small scenes never start the workers.
template <typename Body>
void for_blocks(size_t count, const Body& body) {
  constexpr size_t kBlock = 4096;
  if (count <= kBlock) {
    body(size_t(0), count);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, kBlock),
                    [&](const tbb::blocked_range<size_t>& block) { body(block.begin(), block.end()); });
}

// Side q (0..255) of a quantized box along one axis, decoded by the shader's own code.
float dequantize(float origin, float scale, uint32_t q) { return node_child_sides(origin, scale, q).x; }

// The smallest power of two `scale` with 254 * scale >= extent: a box side spans at most 254 steps,
// leaving one step of room for rounding outward. Returned as a biased float exponent (1..254).
uint32_t scale_exponent(double extent) {
  int e = -126;
  if (extent > 0) {
    std::frexp(extent / 254.0, &e);  // extent / 254 = m * 2^e, m in [0.5, 1): 2^e >= extent / 254
    e = std::clamp(e, -126, 127);
  }
  return uint32_t(e + 127);
}

// Packs the binary tree into wide nodes: each wide node takes a binary node's children and, for
// each child that is an inner node, that node's children in its place. Wide nodes are numbered in
// depth-first order first (cheap, one pass), then written in parallel (the quantization is most of
// the work).
class NodePacker {
 public:
  explicit NodePacker(const Bvh& bvh) : bvh_(bvh), wide_of_(bvh.nodes.size(), 0) {}

  std::vector<glm::uvec4> pack() {
    if (bvh_.nodes.empty()) return {};
    number(0);
    texels_.resize(binary_of_.size() * VKRAY_TEXELS_PER_NODE);
    for_blocks(binary_of_.size(), [&](size_t begin, size_t end) {
      throw_if_interrupted();
      for (size_t wide = begin; wide < end; ++wide) {
        Child children[VKRAY_NODE_WIDTH];
        const int count = gather(binary_of_[wide], children);
        for (int c = 0; c < count; ++c)
          if (!is_leaf(children[c].link)) children[c].link = wide_of_[children[c].link];
        write(uint32_t(wide), children, count);
      }
    });
    return std::move(texels_);
  }

 private:
  struct Child {
    uint32_t link;  // a leaf, or a binary node's index (a wide node's once gathered)
    Aabb box;
  };

  // The children of the wide node made from binary node `index`. The root is 0, which is why 0
  // can mean "no child".
  int gather(uint32_t index, Child* children) const {
    int count = 0;
    const BvhNode& node = bvh_.nodes[index];
    for (int c = 0; c < 2; ++c) {
      const uint32_t link = node.link[c];
      if (is_leaf(link)) {
        if (leaf_count(link) > 0) children[count++] = {link, node.child[c]};  // count 0: the empty slot of a one-leaf root
        continue;
      }
      const BvhNode& child = bvh_.nodes[link];
      for (int g = 0; g < 2; ++g)
        if (!is_leaf(child.link[g]) || leaf_count(child.link[g]) > 0) children[count++] = {child.link[g], child.child[g]};
    }
    return count;
  }

  // Numbers the wide node made from binary node `index` and, after it, those below it.
  void number(uint32_t index) {
    wide_of_[index] = uint32_t(binary_of_.size());
    binary_of_.push_back(index);
    Child children[VKRAY_NODE_WIDTH];
    const int count = gather(index, children);
    for (int c = 0; c < count; ++c)
      if (!is_leaf(children[c].link)) number(children[c].link);
  }

  void write(uint32_t wide, const Child* children, int count) {
    Aabb all;
    for (int c = 0; c < count; ++c) all.grow(children[c].box);
    glm::uvec4* t = &texels_[size_t(wide) * VKRAY_TEXELS_PER_NODE];
    uint32_t exponents = 0;
    for (int axis = 0; axis < 3; ++axis)
      exponents |= scale_exponent(double(all.max[axis]) - double(all.min[axis])) << (8 * axis);
    t[VKRAY_NODE_HEADER] = glm::uvec4(floatBitsToUint(all.min), exponents);
    const glm::vec3 scale = node_scale(exponents);
    NodeCorners corners{glm::uvec3(0u), glm::uvec3(0u)};
    for (int c = 0; c < count; ++c) {
      t[VKRAY_NODE_LINKS][c] = children[c].link;
      for (int axis = 0; axis < 3; ++axis) {
        const float origin = all.min[axis], lo = children[c].box.min[axis], hi = children[c].box.max[axis];
        // Round outward: the largest step at or below lo, the smallest at or above hi.
        uint32_t q_lo = uint32_t(std::clamp(std::floor((double(lo) - origin) / scale[axis]), 0.0, 255.0));
        while (q_lo > 0 && dequantize(origin, scale[axis], q_lo) > lo) --q_lo;
        uint32_t q_hi = uint32_t(std::clamp(std::ceil((double(hi) - origin) / scale[axis]), 0.0, 255.0));
        while (q_hi < 255 && dequantize(origin, scale[axis], q_hi) < hi) ++q_hi;
        VKRAY_CHECK(dequantize(origin, scale[axis], q_hi) >= hi, "BVH node quantization lost a box side");
        set_byte(corners.lo[axis], c, q_lo);
        set_byte(corners.hi[axis], c, q_hi);
      }
    }
    const NodeCornerTexels corner_texels = node_corner_texels(corners);
    t[VKRAY_NODE_CORNERS] = corner_texels.first;
    t[VKRAY_NODE_CORNERS + 1] = corner_texels.second;
  }

  static void set_byte(uint32_t& word, int c, uint32_t value) { word |= value << (8 * c); }

  const Bvh& bvh_;
  std::vector<uint32_t> wide_of_;    // binary node -> its wide node, for binary nodes that start one
  std::vector<uint32_t> binary_of_;  // wide node -> the binary node it is made from
  std::vector<glm::uvec4> texels_;
};

}  // namespace

std::vector<glm::uvec4> pack_nodes(const Bvh& bvh) { return NodePacker(bvh).pack(); }

Aabb unpack_child_box(const glm::uvec4* node, int c) {
  const glm::vec3 origin = uintBitsToFloat(glm::uvec3(node[VKRAY_NODE_HEADER]));
  const glm::vec3 scale = node_scale(node[VKRAY_NODE_HEADER].w);
  const NodeCorners corners = node_corners(node[VKRAY_NODE_CORNERS], node[VKRAY_NODE_CORNERS + 1]);
  Aabb box;
  for (int axis = 0; axis < 3; ++axis) {
    box.min[axis] = node_child_sides(origin[axis], scale[axis], corners.lo[axis])[c];
    box.max[axis] = node_child_sides(origin[axis], scale[axis], corners.hi[axis])[c];
  }
  return box;
}

namespace {

// `radiance` times 2^exponent: exact for every normal float result.
glm::vec3 scale_radiance(glm::vec3 radiance, int exponent) {
  return {std::ldexp(radiance.r, exponent), std::ldexp(radiance.g, exponent), std::ldexp(radiance.b, exponent)};
}

}  // namespace

uint32_t row_stride(uint32_t rows) {
  if (rows <= 2) return 1;
  uint32_t stride = static_cast<uint32_t>(std::lround(double(rows) * 0.6180339887498949));
  while (std::gcd(stride, rows) != 1) ++stride;  // ends by rows - 1 at the latest
  return stride;
}

FrameUniforms pack_frame(const Scene& scene, uint32_t primitive_count, const LightingFrame& lighting, const ImageSettings& image) {
  FrameUniforms f{};
  const CameraBasis cam = camera_basis(scene.camera, image.height);
  f.origin = glm::vec4(cam.origin, 0.0f);
  f.right = glm::vec4(cam.right, 0.0f);
  f.up = glm::vec4(cam.up, 0.0f);
  f.forward = glm::vec4(cam.forward, cam.focal_px);
  f.background = glm::vec4(scale_radiance(scene.background, lighting.radiance_exponent), 0.0f);
  f.ambient = glm::vec4(scale_radiance(scene.ambient, lighting.radiance_exponent), 0.0f);
  f.width = image.width;
  f.height = image.height;
  f.samples_per_pixel = image.samples_per_pixel;
  f.primitive_count = primitive_count;
  f.light_count = static_cast<uint32_t>(scene.lights.size());
  const SampleStrata strata = sample_strata(image.samples_per_pixel);
  f.strata_x = strata.x;
  f.strata_y = strata.y;
  f.inv_strata_x = strata.inv_x;
  f.inv_strata_y = strata.inv_y;
  f.inv_samples_per_pixel = 1.0f / static_cast<float>(image.samples_per_pixel);
  f.epsilon = scene.epsilon();
  f.seed_key = seed_key(image.seed);
  f.aperture_radius = scene.camera.aperture_radius;
  f.focus_distance = scene.camera.focus_distance;
  f.max_depth = scene.integrator.max_depth;
  f.rr_depth = scene.integrator.rr_depth;
  f.emitter_count = lighting.emitter_count;
  f.environment_width = lighting.environment_width;
  f.environment_height = lighting.environment_height;
  if (scene.environment) {
    // World to map: the rotation's inverse, its transpose.
    const glm::mat3 to_map = glm::transpose(scene.environment->to_world);
    f.environment_row0 = glm::vec4(glm::row(to_map, 0), 0.0f);
    f.environment_row1 = glm::vec4(glm::row(to_map, 1), 0.0f);
    f.environment_row2 = glm::vec4(glm::row(to_map, 2), 0.0f);
  }
  return f;
}

PackedScene pack_scene(const Scene& scene, const SceneBvh& bvh) {
  PackedScene packed;
  static_cast<PackedGeometry&>(packed) = pack_geometry(scene, bvh);
  static_cast<PackedLighting&>(packed) = pack_lighting(scene, packed.slots);
  return packed;
}

namespace {

// The links of a BVH's packed nodes moved to where they land in the node buffer: inner nodes by
// `node_base` wide nodes, leaves by `first_base` primitives (or instance entries). 0 stays "no child".
void append_nodes(std::vector<glm::uvec4>& out, std::vector<glm::uvec4> texels, uint32_t first_base) {
  const auto node_base = uint32_t(out.size() / VKRAY_TEXELS_PER_NODE);
  for (size_t node = 0; node < texels.size(); node += VKRAY_TEXELS_PER_NODE) {
    glm::uvec4& links = texels[node + VKRAY_NODE_LINKS];
    for (int c = 0; c < VKRAY_NODE_WIDTH; ++c) {
      if (links[c] == 0u) continue;
      links[c] = is_leaf(links[c]) ? leaf_link(leaf_first(links[c]) + first_base, leaf_count(links[c])) : links[c] + node_base;
    }
  }
  out.insert(out.end(), texels.begin(), texels.end());
}

// The box of everything a BVH holds: its root's children's.
Aabb root_box(const Bvh& bvh) {
  Aabb box = bvh.nodes[0].child[0];
  if (!is_leaf(bvh.nodes[0].link[1]) || leaf_count(bvh.nodes[0].link[1]) > 0) box.grow(bvh.nodes[0].child[1]);
  return box;
}

// An affine transform's rows (the last row, 0 0 0 1, left out), as texels.
void transform_rows(const glm::dmat4& m, glm::vec4* rows) {
  for (int r = 0; r < 3; ++r) rows[r] = glm::vec4(glm::dvec4(m[0][r], m[1][r], m[2][r], m[3][r]));
}

}  // namespace

PackedGeometry pack_geometry(const Scene& scene, const SceneBvh& bvh) {
  PackedGeometry packed;
  // A primitive's flags hold its material's index.
  if (scene.materials.size() > size_t(VKRAY_PRIM_MATERIAL_MASK) + 1)
    throw LimitError(scene.file.string() + ": " + std::to_string(scene.materials.size()) + " materials; vkray renders at most " +
                     std::to_string(size_t(VKRAY_PRIM_MATERIAL_MASK) + 1));
  const size_t triangle_count = scene.triangles.size();
  const bool any_smooth = scene.any_triangle([](const Triangle& t) { return t.smooth; });
  const bool textured = std::any_of(scene.materials.begin(), scene.materials.end(), [](const Material& m) { return m.textured(); });
  const bool normal_mapped = std::any_of(scene.materials.begin(), scene.materials.end(), [](const Material& m) { return m.normal_texture.present(); });
  const bool coloured = scene.any_triangle([](const Triangle& t) { return t.coloured(); });
  // The slots: the scene's own primitives first, then each mesh's, each in its BVH's leaf order.
  std::vector<size_t> mesh_base(bvh.meshes.size());
  size_t slots = bvh.primitives.order.size();
  for (size_t m = 0; m < bvh.meshes.size(); ++m) {
    mesh_base[m] = slots;
    slots += bvh.meshes[m].order.size();
  }
  if (slots > kMaxScenePrimitives)
    throw LimitError(scene.file.string() + ": " + std::to_string(slots) + " primitives stored, meshes that instances place counted once; vkray renders at most " +
                     std::to_string(kMaxScenePrimitives));
  packed.primitives.resize(slots * VKRAY_TEXELS_PER_PRIMITIVE);
  if (normal_mapped) packed.tangents.resize(slots * VKRAY_TEXELS_PER_PRIMITIVE, glm::vec4(0.0f));
  if (any_smooth) packed.normals.resize(slots * VKRAY_TEXELS_PER_PRIMITIVE, glm::vec4(0.0f));
  if (textured) packed.texcoords.resize(slots * VKRAY_TEXELS_PER_TEXCOORDS, glm::vec4(0.0f));
  if (coloured) packed.colours.resize(slots * VKRAY_TEXELS_PER_PRIMITIVE, glm::vec4(1.0f));
  const auto pack_triangle = [&](size_t slot, const Triangle& t, uint32_t scene_index, uint32_t object) {
    const Material& m = scene.materials[t.material];
    const uint32_t flags = t.material | (t.smooth ? VKRAY_PRIM_SMOOTH : 0u) | (m.double_sided ? 0u : VKRAY_PRIM_SINGLE_SIDED) |
                           (scene.see_through(t) ? VKRAY_PRIM_ALPHA : 0u) | (t.coloured() ? VKRAY_PRIM_COLOURED : 0u);
    if (t.coloured())
      for (size_t k = 0; k < 3; ++k) packed.colours[slot * VKRAY_TEXELS_PER_PRIMITIVE + k] = t.colours[k];
    if (t.smooth)
      for (size_t k = 0; k < 3; ++k) packed.normals[slot * VKRAY_TEXELS_PER_PRIMITIVE + k] = glm::vec4(t.normals[k], 0.0f);
    if (normal_mapped)
      for (size_t k = 0; k < 3; ++k) packed.tangents[slot * VKRAY_TEXELS_PER_PRIMITIVE + k] = t.tangents[k];
    if (textured) {
      packed.texcoords[slot * VKRAY_TEXELS_PER_TEXCOORDS] = glm::vec4(t.uv[0], t.uv[1]);
      packed.texcoords[slot * VKRAY_TEXELS_PER_TEXCOORDS + 1] = glm::vec4(t.uv[2], t.uv1[0]);
      packed.texcoords[slot * VKRAY_TEXELS_PER_TEXCOORDS + 2] = glm::vec4(t.uv1[1], t.uv1[2]);
    }
    return triangle_texels(t.v[0], t.v[1], t.v[2], flags, scene_index, object);
  };
  const auto store = [&](size_t slot, const PrimitiveTexels& texels) {
    glm::vec4* out = &packed.primitives[slot * VKRAY_TEXELS_PER_PRIMITIVE];
    out[0] = texels.a;
    out[1] = texels.b;
    out[2] = texels.c;
  };
  const PrimitiveNumbering numbering(scene);
  const std::vector<uint32_t>& order = bvh.primitives.order;
  for_blocks(order.size(), [&](size_t begin, size_t end) {
    throw_if_interrupted();
    for (size_t slot = begin; slot < end; ++slot) {
      const uint32_t p = order[slot];
      if (p < triangle_count) {
        store(slot, pack_triangle(slot, scene.triangles[p], p, scene.triangles[p].object));
      } else {
        const Sphere& sphere = scene.spheres[p - triangle_count];
        store(slot, sphere_texels(sphere.center, sphere.radius,
                                  sphere.material | (sphere.inward ? VKRAY_PRIM_INWARD : 0u) |
                                      (scene.materials[sphere.material].see_through() ? VKRAY_PRIM_ALPHA : 0u),
                                  uint32_t(numbering.sphere_first() + (p - triangle_count)), sphere.object));
      }
    }
  });
  packed.slots.own.resize(order.size());
  for (size_t slot = 0; slot < order.size(); ++slot) packed.slots.own[order[slot]] = uint32_t(slot);
  // A mesh's triangles hold their place in the mesh; the instance adds where it starts.
  packed.slots.meshes.resize(bvh.meshes.size());
  for (size_t m = 0; m < bvh.meshes.size(); ++m) {
    const std::vector<uint32_t>& mesh_order = bvh.meshes[m].order;
    for_blocks(mesh_order.size(), [&](size_t begin, size_t end) {
      throw_if_interrupted();
      for (size_t s = begin; s < end; ++s)
        store(mesh_base[m] + s, pack_triangle(mesh_base[m] + s, scene.meshes[m].triangles[mesh_order[s]], mesh_order[s], 0u));
    });
    packed.slots.meshes[m].resize(mesh_order.size());
    for (size_t s = 0; s < mesh_order.size(); ++s) packed.slots.meshes[m][mesh_order[s]] = uint32_t(mesh_base[m] + s);
  }
  if (scene.instances.empty()) {
    packed.nodes = pack_nodes(bvh.primitives);
  } else {
    // Two levels: a top BVH over the instances and, as one more entry, the scene's own primitives.
    std::vector<Aabb> boxes = instance_boxes(scene, bvh.meshes);
    const bool own = !bvh.primitives.nodes.empty();
    if (own) boxes.push_back(root_box(bvh.primitives));
    const Bvh top = build_bvh(boxes, 0, nullptr, 1);
    // (Each level has a traversal stack of its own on the GPU, each as deep as one BVH can be.)
    VKRAY_CHECK(top.nodes.size() + top.order.size() < kMaxPrimitives, "the instances' nodes pass the leaf encoding");
    // The node buffer: the top BVH, its leaves' instance nodes, then each entry's BVH.
    const std::vector<glm::uvec4> top_nodes = pack_nodes(top);
    const auto instance_nodes = uint32_t(top_nodes.size() / VKRAY_TEXELS_PER_NODE);
    append_nodes(packed.nodes, top_nodes, instance_nodes);
    packed.nodes.resize(packed.nodes.size() + top.order.size() * VKRAY_TEXELS_PER_NODE);
    std::vector<uint32_t> root(bvh.meshes.size());
    uint32_t own_root = 0;
    if (own) {
      own_root = uint32_t(packed.nodes.size() / VKRAY_TEXELS_PER_NODE);
      append_nodes(packed.nodes, pack_nodes(bvh.primitives), 0);
    }
    for (size_t m = 0; m < bvh.meshes.size(); ++m) {
      root[m] = uint32_t(packed.nodes.size() / VKRAY_TEXELS_PER_NODE);
      append_nodes(packed.nodes, pack_nodes(bvh.meshes[m]), uint32_t(mesh_base[m]));
    }
    packed.instances.resize(top.order.size() * VKRAY_TEXELS_PER_INSTANCE);
    packed.slots.instances.resize(scene.instances.size());
    for (size_t entry = 0; entry < top.order.size(); ++entry) {
      glm::vec4* texels = &packed.instances[entry * VKRAY_TEXELS_PER_INSTANCE];
      glm::uvec4* node = &packed.nodes[(instance_nodes + entry) * VKRAY_TEXELS_PER_NODE];
      const uint32_t k = top.order[entry];
      const bool own_entry = k == scene.instances.size();  // the scene's own primitives
      const glm::dmat4 to_world = own_entry ? glm::dmat4(1.0) : glm::dmat4(scene.instances[k].to_world);
      transform_rows(glm::inverse(to_world), texels + VKRAY_INSTANCE_TO_MESH);
      transform_rows(to_world, texels + VKRAY_INSTANCE_TO_WORLD);
      for (int r = 0; r < 3; ++r) node[r] = floatBitsToUint(texels[VKRAY_INSTANCE_TO_MESH + r]);
      if (own_entry) {
        texels[VKRAY_INSTANCE_HEADER] = instance_header_texel(own_root, 0u, 0u, 0u);
        node[3] = glm::uvec4(own_root, 0u, VKRAY_NO_INSTANCE, 0u);
        continue;
      }
      const Instance& instance = scene.instances[k];
      const auto first = uint32_t(numbering.instance_first(k));
      texels[VKRAY_INSTANCE_HEADER] = instance_header_texel(root[instance.mesh], first, instance.object, 1u);
      node[3] = glm::uvec4(root[instance.mesh], first, uint32_t(entry), 0u);
      packed.slots.instances[k] = uint32_t(entry);
    }
  }
  const std::vector<uint32_t> offsets = texture_offsets(scene);
  packed.textures.resize(scene.textures.empty() ? 0 : (size_t(offsets.back()) + scene.textures.back()->texels.size() / 4) * 4);
  for (size_t i = 0; i < scene.textures.size(); ++i)
    std::copy(scene.textures[i]->texels.begin(), scene.textures[i]->texels.end(), packed.textures.begin() + ptrdiff_t(offsets[i]) * 4);
  return packed;
}

std::vector<uint32_t> texture_offsets(const Scene& scene) {
  std::vector<uint32_t> offsets;
  uint64_t next = 0;
  for (const auto& texture : scene.textures) {
    offsets.push_back(uint32_t(next));
    next += uint64_t(texture->width) * texture->height;
    if (next > uint64_t(INT32_MAX))
      throw LimitError(scene.file.string() + ": the textures have " + std::to_string(next) +
                       " texels together or more; vkray renders at most 2^31");
  }
  return offsets;
}

int radiance_exponent(const Scene& scene) {
  float brightest = std::max({scene.background.r, scene.background.g, scene.background.b, scene.ambient.r, scene.ambient.g,
                              scene.ambient.b});
  for (const Material& m : scene.materials) brightest = std::max({brightest, m.emission.r, m.emission.g, m.emission.b});
  for (const Light& l : scene.lights) brightest = std::max({brightest, l.intensity.r, l.intensity.g, l.intensity.b});
  if (scene.environment) brightest = std::max(brightest, scene.environment->brightest);
  if (!(brightest > 0.0f)) return 0;
  int exponent = 0;
  std::frexp(brightest, &exponent);  // brightest = m 2^exponent, m in [0.5, 1)
  return 20 - exponent;
}

glm::vec3 unscale_radiance(glm::vec3 scaled, int radiance_exponent) { return RadianceUnscale(radiance_exponent)(scaled); }

PackedLighting pack_lighting(const Scene& scene, const PrimitiveSlots& slots) {
  PackedLighting packed;
  const int exponent = radiance_exponent(scene);
  const EmitterTable table = build_emitter_table(scene);
  packed.materials.resize(scene.materials.size() * VKRAY_TEXELS_PER_MATERIAL);
  const std::vector<uint32_t> offsets = texture_offsets(scene);
  // A texture slot: the header, then the transform's two rows (shared/materials.h).
  const auto texture_slot = [&](glm::vec4* texels, const TextureRef& ref) {
    if (!ref.present()) {  // width 0: none
      texels[0] = texels[1] = texels[2] = glm::vec4(0.0f);
      return;
    }
    const Texture& t = *scene.textures[size_t(ref.texture)];
    texels[0] = texture_texel(offsets[size_t(ref.texture)], t.width, t.height, uint32_t(ref.wrap_s), uint32_t(ref.wrap_t),
                              uint32_t(ref.filter), ref.transformed() ? 1u : 0u, ref.texcoord);
    texels[1] = glm::vec4(ref.to_u, 0.0f);
    texels[2] = glm::vec4(ref.to_v, 0.0f);
  };
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    glm::vec4* texels = &packed.materials[i * VKRAY_TEXELS_PER_MATERIAL];
    const MaterialValueTexels values = material_value_texels(
        {m.albedo, uint32_t(m.type), scale_radiance(m.emission, exponent), m.ior, m.eta, m.alpha.x, m.k, m.alpha.y, m.metallic,
         m.roughness, m.normal_scale, m.transmission});
    texels[VKRAY_MATERIAL_COLOR] = values.color;
    texels[VKRAY_MATERIAL_EMISSION] = values.emission;
    texels[VKRAY_MATERIAL_ETA] = values.eta;
    texels[VKRAY_MATERIAL_K] = values.k;
    texels[VKRAY_MATERIAL_LAYERS] = values.layers;
    texture_slot(texels + VKRAY_MATERIAL_ALBEDO_TEXTURE, m.albedo_texture);
    texture_slot(texels + VKRAY_MATERIAL_EMISSION_TEXTURE, m.emission_texture);
    texture_slot(texels + VKRAY_MATERIAL_LAYERS_TEXTURE, m.metallic_roughness_texture);
    texture_slot(texels + VKRAY_MATERIAL_NORMAL_TEXTURE, m.normal_texture);
    texels[VKRAY_MATERIAL_OPACITY] = opacity_texel(m.opacity, m.alpha_cutoff, uint32_t(m.alpha_mode), m.vertex_colours_emit);
    texture_slot(texels + VKRAY_MATERIAL_OPACITY_TEXTURE, m.opacity_texture);
    texture_slot(texels + VKRAY_MATERIAL_TRANSMISSION_TEXTURE, m.transmission_texture);
    // In double on the host, then one rounding: no 1 / total power in float that could overflow.
    texels[VKRAY_MATERIAL_LIGHT] = glm::vec4(float(table.density[i]), m.emits_both_sides ? 1.0f : 0.0f, 0.0f, 0.0f);
  }
  // The area lights, their primitives as slots in the primitive buffer (and an instance's as its entry).
  if (!table.entries.empty()) {
    const PrimitiveNumbering numbering(scene);
    const uint64_t triangles = scene.triangles.size();
    for (const EmitterTable::Entry& e : table.entries) {
      const PrimitiveNumbering::Placed placed = numbering.at(e.primitive);
      uint32_t slot = 0, entry = 0;
      if (placed.instance >= 0) {
        const auto k = size_t(placed.instance);
        slot = slots.meshes[scene.instances[k].mesh][e.primitive - numbering.instance_first(k)];
        entry = slots.instances[k] + 1;
      } else {
        slot = slots.own[e.primitive < triangles ? e.primitive : triangles + (e.primitive - numbering.sphere_first())];
      }
      packed.emitters.push_back(glm::vec4(e.probability, uintBitsToFloat(e.alias), uintBitsToFloat(slot), uintBitsToFloat(entry)));
    }
  }
  if (scene.environment) {
    const auto packing = std::chrono::steady_clock::now();
    packed.environment = pack_environment(*scene.environment, exponent);
    packed.environment_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - packing).count();
  }
  packed.frame = {uint32_t(table.entries.size()), exponent, packed.environment.width, packed.environment.height};
  packed.lights.resize(scene.lights.size() * VKRAY_TEXELS_PER_LIGHT);
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    glm::vec4* texels = &packed.lights[i * VKRAY_TEXELS_PER_LIGHT];
    uint32_t kind = VKRAY_LIGHT_POINT;
    glm::vec4 cone(0.0f);
    if (l.type == Light::Type::directional) {
      kind = VKRAY_LIGHT_DIRECTIONAL;
    } else if (l.type == Light::Type::spot) {
      // The cosines and the ramp's slope in double, then one rounding each.
      const double cos_cutoff = std::cos(double(l.cutoff_angle)), cos_beam = std::cos(double(l.beam_width));
      if (l.falloff == Light::Falloff::mitsuba) {
        kind = VKRAY_LIGHT_SPOT;
        // A beam as wide as the cutoff has no ramp: the slope is never used (the cosine is past one end).
        const double transition = double(l.cutoff_angle) - double(l.beam_width);
        cone = glm::vec4(float(cos_cutoff), float(cos_beam), l.cutoff_angle, transition > 0 ? float(1 / transition) : 0.0f);
      } else {
        // KHR_lights_punctual's own form, its 0.001 included.
        kind = VKRAY_LIGHT_GLTF_SPOT;
        const double scale = 1 / std::max(0.001, cos_beam - cos_cutoff);
        cone = glm::vec4(float(scale), float(-cos_cutoff * scale), 0.0f, 0.0f);
      }
    }
    texels[VKRAY_LIGHT_POSITION] = glm::vec4(l.position, uintBitsToFloat(kind));
    texels[VKRAY_LIGHT_INTENSITY] = glm::vec4(scale_radiance(l.intensity, exponent), 0.0f);
    texels[VKRAY_LIGHT_DIRECTION] = glm::vec4(l.direction, 0.0f);
    texels[VKRAY_LIGHT_CONE] = cone;
  }
  return packed;
}

}  // namespace vkray::gpu
