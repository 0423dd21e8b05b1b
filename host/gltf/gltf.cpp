#include "gltf/gltf.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <optional>
#include <set>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "base/errors.h"
#include "base/grow.h"
#include "base/input_file.h"
#include "base/interrupt.h"
#include "base/json_document.h"
#include "gltf/gltf_schema.h"
#include "gltf/gltf_uri.h"
#include "gltf/tinygltf.h"
#include "image/decode.h"

namespace vkray {
namespace {

using glm::dmat4;
using glm::dvec3;

// Extensions whose content vkray reads; a file that requires any other is refused.
const std::set<std::string> kReadExtensions = {"EXT_mesh_gpu_instancing",    "KHR_lights_punctual",        "KHR_materials_emissive_strength",
                                               "KHR_materials_ior",          "KHR_materials_transmission", "KHR_materials_unlit",
                                               "KHR_texture_transform"};
// Extensions that carry metadata only (XMP packets: authors, licences), with nothing to render.
const std::set<std::string> kMetadataExtensions = {"KHR_xmp", "KHR_xmp_json_ld"};

std::string element(const char* array, size_t index) { return std::string(array) + "[" + std::to_string(index) + "]"; }

// Keeps a picture's bytes as they are (image.image); vkray decodes the pictures a material uses.
bool keep_encoded(tinygltf::Image* image, const int, std::string*, std::string*, int, int, const unsigned char* bytes, int size, void*) {
  image->image.assign(bytes, bytes + std::max(size, 0));
  image->as_is = true;
  return true;
}

// A primitive vkray leaves out, with the reason, named in a warning.
struct Skip {
  std::string kind;  // one warning per kind
  std::string what;
};

// An accessor's elements, checked to lie inside their buffer, with a sparse accessor's substitutions.
struct AccessorView {
  const unsigned char* data = nullptr;  // null: every element is zero (an accessor without a buffer view)
  size_t count = 0;
  size_t stride = 0;
  int component_type = 0;
  int components = 0;
  bool normalized = false;
  // A sparse accessor's (glTF 3.6.2.3): element (*sparse_indices)[k] (strictly increasing) is the k-th
  // element at sparse_values, tightly packed, instead of its element in `data`. Both hold as many
  // entries as the file stores, so a small file describes no large allocation; the indices are read
  // once per accessor, however often it is used (GltfReader::sparse_indices_).
  std::shared_ptr<const std::vector<uint32_t>> sparse_indices;
  const unsigned char* sparse_values = nullptr;

  size_t element_size() const;
  // Where element i's bytes are; null where it is zero.
  const unsigned char* element(size_t i) const {
    if (sparse_indices) {
      const auto at = std::lower_bound(sparse_indices->begin(), sparse_indices->end(), i);
      if (at != sparse_indices->end() && *at == i) return sparse_values + size_t(at - sparse_indices->begin()) * element_size();
    }
    return data ? data + i * stride : nullptr;
  }
  bool all_zero() const { return !data && !sparse_indices; }

  // Component c of element i, normalized integers mapped to [0, 1] or [-1, 1] as glTF defines.
  double get(size_t i, int c) const {
    const unsigned char* p = element(i);
    if (!p) return 0.0;
    switch (component_type) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float f;
        std::memcpy(&f, p + 4 * c, 4);
        return f;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return normalized ? p[c] / 255.0 : p[c];
      case TINYGLTF_COMPONENT_TYPE_BYTE: {
        const auto v = static_cast<signed char>(p[c]);
        return normalized ? std::max(v / 127.0, -1.0) : v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p + 2 * c, 2);
        return normalized ? v / 65535.0 : v;
      }
      case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t v;
        std::memcpy(&v, p + 2 * c, 2);
        return normalized ? std::max(v / 32767.0, -1.0) : v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v;
        std::memcpy(&v, p + 4 * c, 4);
        return v;
      }
    }
    return 0.0;
  }

  uint32_t index(size_t i) const { return index_at(element(i), component_type); }
  // An unsigned index of the given component type at p (0 where p is null).
  static uint32_t index_at(const unsigned char* p, int component_type) {
    if (!p) return 0;
    if (component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) return p[0];
    if (component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
  }
};

// A vertex attribute with its morph targets' displacements added at their weights (glTF 3.7.2.2):
// base + sum of weight * target, in double.
struct MorphedAttribute {
  AccessorView base;
  std::vector<std::pair<double, AccessorView>> targets;  // those of a weight other than 0

  double get(size_t i, int c) const {
    double v = base.get(i, c);
    for (const auto& [weight, target] : targets)
      if (c < target.components) v += weight * target.get(i, c);  // a tangent's target has no w
    return v;
  }
  bool all_zero() const {
    return base.all_zero() && std::all_of(targets.begin(), targets.end(), [](const auto& t) { return t.second.all_zero(); });
  }
};

size_t component_size(int type) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
  }
  return 0;
}

size_t AccessorView::element_size() const { return component_size(component_type) * size_t(components); }

const char* type_name(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    case TINYGLTF_TYPE_MAT2: return "MAT2";
    case TINYGLTF_TYPE_MAT3: return "MAT3";
    case TINYGLTF_TYPE_MAT4: return "MAT4";
  }
  return "an unknown type";
}

class GltfReader {
 public:
  GltfReader(const std::filesystem::path& file, const GltfLimits& limits) : file_(file), limits_(limits) {}

  GltfScene read(std::string_view bytes);

 private:
  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw SceneError(file_.string() + ": " + (where.empty() ? "" : where + ": ") + what);
  }
  // One warning for each kind of thing vkray cannot render, naming where it was first seen.
  void warn_once(const std::string& kind, const std::string& where, const std::string& what) {
    if (warned_.insert(kind).second)
      scene_.warnings.push_back(printable(file_.string() + ": " + (where.empty() ? "" : where + ": ") + what, 400));
  }

  // Whether the .glb file has a binary chunk.
  bool check_glb(std::string_view bytes) const;
  void check_buffer_views(const nlohmann::json& doc) const;
  void check_required_extensions(const nlohmann::json& doc) const;
  void warn_used_extensions();
  // `integers`: whether integer components may be read as they are (indices); otherwise an integer
  // component must be normalized (texture coordinates).
  AccessorView accessor(int index, const std::string& where, std::initializer_list<int> types,
                        std::initializer_list<int> component_types, bool integers = false) const;
  // The bytes of `count` elements of `element_size` from `byte_offset` in a buffer view, checked to lie
  // inside it; `stride` receives the view's byteStride, or element_size where it has none. Null for 0.
  const unsigned char* view_bytes(int buffer_view, size_t byte_offset, size_t element_size, size_t count, size_t* stride,
                                  const std::string& name) const;
  dmat4 local_transform(size_t node) const;
  void walk_nodes();
  // The transforms that place a node's mesh, one for each instance its EXT_mesh_gpu_instancing lists.
  std::vector<dmat4> gpu_instances(size_t node, const dmat4& world);
  // Places every mesh the walk found (placements_): read in place, or read once and placed by instances.
  void place_meshes();
  // The mesh of a node (with its morph weights), placed by `world`.
  void add_mesh(size_t node, const dmat4& world);
  void add_primitive(const tinygltf::Primitive& p, const std::string& where, const dmat4& world, const std::vector<double>& weights);
  // A primitive's attribute `name` with its morph targets' displacements at `weights`; nullopt where
  // the primitive has no such attribute. Each has `vertices` elements.
  std::optional<MorphedAttribute> attribute(const tinygltf::Primitive& p, const std::string& name, const std::string& where,
                                            const std::vector<double>& weights, size_t vertices, std::initializer_list<int> types,
                                            std::initializer_list<int> component_types) const;
  uint32_t material(int index, const std::string& where);
  TextureRef texture(const tinygltf::TextureInfo& info, const std::string& where, bool srgb);
  int32_t image_texture(int image, const std::string& where, bool srgb);
  void add_camera(size_t node, const dmat4& world);
  void add_light(size_t node, const dmat4& world);

  const std::filesystem::path& file_;
  GltfLimits limits_;
  tinygltf::Model model_;
  GltfScene scene_;
  std::set<std::string> warned_;
  std::map<int, uint32_t> materials_;     // glTF material (-1: the default) -> scene_.materials
  std::map<int, std::vector<int>> texcoord_sets_;  // glTF material -> the TEXCOORD_n its textures read, as uv and uv1
  // A picture is decoded once for each way it is read: as sRGB colour, or as linear data.
  std::map<std::pair<int, bool>, int32_t> image_textures_;  // (glTF image, sRGB) -> scene_.textures
  std::map<std::pair<std::string, bool>, int32_t> sources_;  // (where its bytes are: "view 3", "file /x/y.png"; sRGB) -> scene_.textures
  uint64_t texels_ = 0;                     // in scene_.textures so far
  // A sparse accessor's indices, checked and read once (accessor() is const: a cache, not state).
  mutable std::map<int, std::shared_ptr<const std::vector<uint32_t>>> sparse_indices_;
  // Morph displacements applied so far (corners times targets): held to GltfLimits::max_morph_displacements.
  uint64_t morph_work_ = 0;
  bool camera_found_ = false;
  // Where the default scene places meshes: a node with a mesh, and the transform that places it.
  struct Placement {
    size_t node;
    dmat4 world;
  };
  std::vector<Placement> placements_;
  size_t stored_apart_ = 0;  // triangles stored other than in scene_.triangles (meshes'), held to the limit too
};

// The texture coordinate set a texture reads: KHR_texture_transform's texCoord overrides the
// textureInfo's where it gives one (GltfReader::texture checks that it is a whole number).
int texcoord_of(const tinygltf::TextureInfo& info) {
  if (const auto ext = info.extensions.find("KHR_texture_transform"); ext != info.extensions.end()) {
    const tinygltf::Value& set = ext->second.Get("texCoord");
    if (set.IsInt()) return set.GetNumberAsInt();
  }
  return info.texCoord;
}

bool GltfReader::check_glb(std::string_view bytes) const {
  // The 12-byte header, then chunks of (length, type, data): JSON first, BIN optionally second.
  const auto word = [&](size_t at) {
    uint32_t w;
    std::memcpy(&w, bytes.data() + at, 4);
    return w;
  };
  if (bytes.size() < 20) fail("", "a .glb file shorter than its header (" + std::to_string(bytes.size()) + " bytes)");
  if (word(4) != 2) fail("", "glTF binary version " + std::to_string(word(4)) + "; vkray reads version 2");
  if (word(8) > bytes.size())
    fail("", "the header gives a length of " + std::to_string(word(8)) + " bytes, the file has " + std::to_string(bytes.size()));
  const uint64_t json_length = word(12);
  if (word(16) != 0x4E4F534Au) fail("", "the first chunk is not JSON");
  // Chunks are padded to 4 bytes (glTF 4.4.3); tinygltf looks for the binary chunk at the unpadded end.
  if (json_length % 4 != 0) fail("", "the JSON chunk's length (" + std::to_string(json_length) + ") is not a multiple of 4");
  if (20 + json_length > word(8)) fail("", "the JSON chunk (" + std::to_string(json_length) + " bytes) runs past the file's end");
  const uint64_t bin_at = 20 + ((json_length + 3) & ~uint64_t(3));
  if (bin_at + 8 > word(8)) return false;
  const uint64_t bin_length = word(size_t(bin_at));
  if (bin_at + 8 + bin_length > word(8)) fail("", "the binary chunk (" + std::to_string(bin_length) + " bytes) runs past the file's end");
  return true;
}

// tinygltf 2.7.0 hands a picture in a buffer view to the image callback without checking that the
// view lies inside its buffer (tiny_gltf.h, LoadFromString: &buffer.data[byteOffset], byteLength),
// which fuzz_gltf found as a heap overflow. So every view is checked here first (the schema check
// has made its numbers whole), against its buffer's declared byteLength, which tinygltf holds each
// buffer's data to exactly.
void GltfReader::check_buffer_views(const nlohmann::json& doc) const {
  if (!doc.contains("bufferViews")) return;
  const nlohmann::json& views = doc["bufferViews"];
  for (size_t v = 0; v < views.size(); ++v) {
    const uint64_t buffer = views[v]["buffer"].get<uint64_t>(), length = views[v]["byteLength"].get<uint64_t>();
    const uint64_t offset = views[v].value("byteOffset", uint64_t(0));
    const uint64_t size = doc["buffers"][buffer]["byteLength"].get<uint64_t>();
    if (offset > size || length > size - offset)
      fail(element("bufferViews", v), "bytes " + std::to_string(offset) + " + " + std::to_string(length) + " run past the end of " +
                                          element("buffers", buffer) + " (" + std::to_string(size) + " bytes)");
  }
}

// Before tinygltf, which would otherwise report what the extension changes (a Draco-compressed
// accessor has no buffer view) instead of the extension.
void GltfReader::check_required_extensions(const nlohmann::json& doc) const {
  if (!doc.contains("extensionsRequired") || !doc["extensionsRequired"].is_array()) return;
  for (const auto& name : doc["extensionsRequired"])
    if (name.is_string() && !kReadExtensions.count(name.get<std::string>()))
      fail("extensionsRequired", "the file requires " + printable(name.get<std::string>()) + ", which vkray does not read");
}

void GltfReader::warn_used_extensions() {
  for (const std::string& name : model_.extensionsUsed)
    if (!kReadExtensions.count(name) && !kMetadataExtensions.count(name))
      warn_once("extension " + name, "extensionsUsed", printable(name) + " is not read; what it adds is not rendered");
}

const unsigned char* GltfReader::view_bytes(int buffer_view, size_t byte_offset, size_t element_size, size_t count, size_t* stride,
                                            const std::string& name) const {
  if (buffer_view < 0 || size_t(buffer_view) >= model_.bufferViews.size())
    fail(name, "bufferViews[" + std::to_string(buffer_view) + "] does not exist (the file has " +
                   std::to_string(model_.bufferViews.size()) + ")");
  const tinygltf::BufferView& bv = model_.bufferViews[size_t(buffer_view)];
  const std::string bv_name = element("bufferViews", size_t(buffer_view));
  if (bv.buffer < 0 || size_t(bv.buffer) >= model_.buffers.size())
    fail(bv_name, "buffers[" + std::to_string(bv.buffer) + "] does not exist (the file has " + std::to_string(model_.buffers.size()) + ")");
  const std::vector<unsigned char>& data = model_.buffers[size_t(bv.buffer)].data;
  if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset)
    fail(bv_name, "bytes " + std::to_string(bv.byteOffset) + " + " + std::to_string(bv.byteLength) + " run past the end of buffers[" +
                      std::to_string(bv.buffer) + "] (" + std::to_string(data.size()) + " bytes)");
  *stride = element_size;
  if (bv.byteStride != 0) {
    if (bv.byteStride < element_size) fail(bv_name, "byteStride " + std::to_string(bv.byteStride) + " is less than an element of " + name);
    *stride = bv.byteStride;
  }
  if (count == 0) return nullptr;
  const size_t room = bv.byteLength;
  const bool fits = byte_offset <= room && element_size <= room - byte_offset && (count - 1) <= (room - byte_offset - element_size) / *stride;
  if (!fits)
    fail(name, std::to_string(count) + " elements from byte " + std::to_string(byte_offset) + " run past the end of " + bv_name + " (" +
                   std::to_string(room) + " bytes)");
  return data.data() + bv.byteOffset + byte_offset;
}

AccessorView GltfReader::accessor(int index, const std::string& where, std::initializer_list<int> types,
                                  std::initializer_list<int> component_types, bool integers) const {
  if (index < 0 || size_t(index) >= model_.accessors.size())
    fail(where, "accessors[" + std::to_string(index) + "] does not exist (the file has " + std::to_string(model_.accessors.size()) + ")");
  const tinygltf::Accessor& a = model_.accessors[size_t(index)];
  const std::string name = where + ": " + element("accessors", size_t(index));
  if (std::find(types.begin(), types.end(), a.type) == types.end()) {
    std::string expected;
    for (const int t : types) expected += (expected.empty() ? "" : " or ") + std::string(type_name(t));
    fail(name, std::string("expected ") + expected + ", got " + type_name(a.type));
  }
  if (std::find(component_types.begin(), component_types.end(), a.componentType) == component_types.end())
    fail(name, "componentType " + std::to_string(a.componentType) + " is not one glTF allows here");
  if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT && !integers && !a.normalized)
    fail(name, "integer components here must be normalized (KHR_mesh_quantization is not read)");
  AccessorView view;
  view.count = a.count;
  view.component_type = a.componentType;
  view.components = a.type == TINYGLTF_TYPE_SCALAR ? 1 : a.type;  // VEC2..VEC4 are 2..4
  view.normalized = a.normalized;
  const size_t element_size = view.element_size();
  view.stride = element_size;
  if (a.bufferView >= 0) view.data = view_bytes(a.bufferView, a.byteOffset, element_size, a.count, &view.stride, name);
  if (a.sparse.isSparse) {
    // Indices and values tightly packed in views without a stride (glTF 3.6.2.3); the indices strictly
    // increase and name elements of the accessor.
    const std::string at = name + ".sparse";
    const auto count = size_t(a.sparse.count);
    if (count < 1 || count > a.count)
      fail(at + ".count", std::to_string(a.sparse.count) + " substitutions for an accessor of " + std::to_string(a.count) + " elements");
    const int index_type = a.sparse.indices.componentType;
    if (index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      fail(at + ".indices.componentType", std::to_string(index_type) + " is not an unsigned integer type");
    for (const auto& [view_index, what] : {std::pair{a.sparse.indices.bufferView, "indices"}, std::pair{a.sparse.values.bufferView, "values"}})
      if (view_index >= 0 && size_t(view_index) < model_.bufferViews.size() && model_.bufferViews[size_t(view_index)].byteStride != 0)
        fail(at + "." + what, element("bufferViews", size_t(view_index)) + " has a byteStride; a sparse accessor's may not");
    size_t stride = 0;
    const unsigned char* indices = view_bytes(a.sparse.indices.bufferView, size_t(std::max(a.sparse.indices.byteOffset, 0)),
                                              component_size(index_type), count, &stride, at + ".indices");
    view.sparse_values = view_bytes(a.sparse.values.bufferView, size_t(std::max(a.sparse.values.byteOffset, 0)), element_size, count,
                                    &stride, at + ".values");
    std::shared_ptr<const std::vector<uint32_t>>& read = sparse_indices_[index];
    if (!read) {
      auto checked = std::make_shared<std::vector<uint32_t>>();
      checked->reserve(count);
      for (size_t k = 0; k < count; ++k) {
        const uint32_t i = AccessorView::index_at(indices + k * component_size(index_type), index_type);
        if (i >= a.count) fail(at + ".indices", "index " + std::to_string(i) + " at " + std::to_string(k) + " is past the accessor's " +
                                                    std::to_string(a.count) + " elements");
        if (!checked->empty() && i <= checked->back())
          fail(at + ".indices", "index " + std::to_string(i) + " at " + std::to_string(k) + " does not increase on the one before");
        checked->push_back(i);
      }
      read = std::move(checked);
    }
    view.sparse_indices = read;
  }
  return view;
}

dmat4 GltfReader::local_transform(size_t node) const {
  const tinygltf::Node& n = model_.nodes[node];
  const std::string where = element("nodes", node);
  const auto finite = [&](const std::vector<double>& values, size_t size, const char* key) {
    if (values.empty()) return false;
    if (values.size() != size) fail(where + "." + key, "expected " + std::to_string(size) + " numbers, got " + std::to_string(values.size()));
    for (const double v : values)
      if (!std::isfinite(v) || std::abs(v) > FLT_MAX) fail(where + "." + key, "a number that is not a finite 32-bit float");
    return true;
  };
  if (finite(n.matrix, 16, "matrix")) {
    dmat4 m;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m[c][r] = n.matrix[size_t(c * 4 + r)];  // column-major, as glm
    return m;
  }
  dmat4 m(1.0);
  if (finite(n.translation, 3, "translation")) m = glm::translate(m, dvec3(n.translation[0], n.translation[1], n.translation[2]));
  if (finite(n.rotation, 4, "rotation")) {
    glm::dquat q(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);  // glTF: x, y, z, w
    if (!(glm::length(q) > 0)) fail(where + ".rotation", "a zero quaternion is no rotation");
    m *= glm::mat4_cast(glm::normalize(q));
  }
  if (finite(n.scale, 3, "scale")) m = glm::scale(m, dvec3(n.scale[0], n.scale[1], n.scale[2]));
  return m;
}

void GltfReader::walk_nodes() {
  // The hierarchy is a forest: every node has at most one parent and no node is its own ancestor.
  // Checked first, so that the walk below cannot loop or recurse without end.
  const size_t count = model_.nodes.size();
  std::vector<int64_t> parent(count, -1);
  for (size_t n = 0; n < count; ++n)
    for (const int child : model_.nodes[n].children) {
      const std::string where = element("nodes", n) + ".children";
      if (child < 0 || size_t(child) >= count)
        fail(where, "nodes[" + std::to_string(child) + "] does not exist (the file has " + std::to_string(count) + ")");
      if (parent[size_t(child)] >= 0 || size_t(child) == n)
        fail(where, element("nodes", size_t(child)) + " has two parents (or is its own child); glTF's nodes form trees");
      parent[size_t(child)] = int64_t(n);
    }
  std::vector<size_t> roots;
  if (!model_.scenes.empty()) {
    const int chosen = model_.defaultScene >= 0 ? model_.defaultScene : 0;
    if (size_t(chosen) >= model_.scenes.size())
      fail("scene", "scenes[" + std::to_string(chosen) + "] does not exist (the file has " + std::to_string(model_.scenes.size()) + ")");
    std::set<size_t> seen;
    for (const int root : model_.scenes[size_t(chosen)].nodes) {
      const std::string where = element("scenes", size_t(chosen)) + ".nodes";
      if (root < 0 || size_t(root) >= count)
        fail(where, "nodes[" + std::to_string(root) + "] does not exist (the file has " + std::to_string(count) + ")");
      if (parent[size_t(root)] >= 0) fail(where, element("nodes", size_t(root)) + " is a child of another node, not a root");
      if (!seen.insert(size_t(root)).second) fail(where, element("nodes", size_t(root)) + " is listed twice");
      roots.push_back(size_t(root));
    }
  } else {
    // No scenes: the file is a library of nodes; render its root nodes.
    for (size_t n = 0; n < count; ++n)
      if (parent[n] < 0) roots.push_back(n);
  }
  // A node whose ancestors form a cycle has a parent, so no root leads into the cycle; but a cycle
  // with no root at all is unreachable, which is fine. Depth-first, in the file's order.
  std::vector<std::pair<size_t, dmat4>> stack;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.emplace_back(*it, dmat4(1.0));
  size_t visited = 0;
  while (!stack.empty()) {
    auto [node, parent_world] = stack.back();
    stack.pop_back();
    if (++visited % 1024 == 0) throw_if_interrupted();
    if (visited > count) fail("nodes", "the hierarchy visits more nodes than the file has");  // cannot happen in a forest
    const dmat4 world = parent_world * local_transform(node);
    const tinygltf::Node& n = model_.nodes[node];
    if (n.camera >= 0) add_camera(node, world);
    if (n.extensions.count("KHR_lights_punctual")) add_light(node, world);
    if (n.mesh >= 0) {
      if (size_t(n.mesh) >= model_.meshes.size())
        fail(element("nodes", node) + ".mesh", "meshes[" + std::to_string(n.mesh) + "] does not exist (the file has " +
                                                  std::to_string(model_.meshes.size()) + ")");
      if (n.skin >= 0) warn_once("skin", element("nodes", node), "skins are not rendered: the mesh is shown in its bind pose");
      if (n.extensions.count("EXT_mesh_gpu_instancing"))
        for (const dmat4& placed : gpu_instances(node, world)) placements_.push_back({node, placed});
      else
        placements_.push_back({node, world});  // (at most one a node: the file's size bounds them)
    }
    for (auto child = n.children.rbegin(); child != n.children.rend(); ++child) stack.emplace_back(size_t(*child), world);
  }
}

std::vector<dmat4> GltfReader::gpu_instances(size_t node, const dmat4& world) {
  // Each instance is the node's mesh placed by the instance's translation, rotation and scale (T R S),
  // then by the node's world transform; absent attributes are the identity's.
  const std::string where = element("nodes", node) + ".extensions.EXT_mesh_gpu_instancing";
  const tinygltf::Value& ext = model_.nodes[node].extensions.at("EXT_mesh_gpu_instancing");
  if (!ext.Has("attributes") || !ext.Get("attributes").IsObject()) fail(where, "expected an object \"attributes\"");
  const tinygltf::Value& attributes = ext.Get("attributes");
  std::optional<AccessorView> translation, rotation, scale;
  size_t count = 0;
  bool counted = false;
  for (const std::string& key : attributes.Keys()) {
    const tinygltf::Value& v = attributes.Get(key);
    if (!v.IsInt()) fail(where + ".attributes." + key, "expected the index of an accessor");
    const std::string at = where + ".attributes." + key;
    std::optional<AccessorView>* slot = key == "TRANSLATION" ? &translation : key == "ROTATION" ? &rotation : key == "SCALE" ? &scale : nullptr;
    if (!slot) continue;  // an application's own attribute (its name starts with an underscore): nothing to render
    *slot = key == "ROTATION" ? accessor(v.GetNumberAsInt(), at, {TINYGLTF_TYPE_VEC4},
                                         {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT})
                              : accessor(v.GetNumberAsInt(), at, {TINYGLTF_TYPE_VEC3}, {TINYGLTF_COMPONENT_TYPE_FLOAT});
    if (counted && (*slot)->count != count)
      fail(at, std::to_string((*slot)->count) + " instances, where another attribute has " + std::to_string(count));
    count = (*slot)->count;
    counted = true;
  }
  const auto finite = [&](const char* key, size_t i, std::initializer_list<double> values) {
    for (const double v : values)
      if (!(std::abs(v) <= FLT_MAX)) fail(where + ".attributes." + key, "instance " + std::to_string(i) + " is not finite");
  };
  // Every instance a placement: held to the most primitives a scene places before any is made.
  if (count > limits_.max_placed_triangles || count > kMaxInstances - std::min(kMaxInstances, placements_.size()))
    throw LimitError(file_.string() + ": " + where + ": " + std::to_string(count) + " instances; vkray places at most " +
                     std::to_string(kMaxInstances) + " meshes and " + std::to_string(limits_.max_placed_triangles) + " triangles");
  std::vector<dmat4> placed;
  placed.reserve(count);
  for (size_t i = 0; i < count; ++i) {
    if (i % 256 == 0) throw_if_interrupted();
    dmat4 m(1.0);
    if (translation) {
      const dvec3 t(translation->get(i, 0), translation->get(i, 1), translation->get(i, 2));
      finite("TRANSLATION", i, {t.x, t.y, t.z});
      m = glm::translate(m, t);
    }
    if (rotation) {
      const glm::dquat q(rotation->get(i, 3), rotation->get(i, 0), rotation->get(i, 1), rotation->get(i, 2));  // x, y, z, w
      finite("ROTATION", i, {q.x, q.y, q.z, q.w});
      if (!(glm::length(q) > 0)) fail(where + ".attributes.ROTATION", "instance " + std::to_string(i) + ": a zero quaternion is no rotation");
      m *= glm::mat4_cast(glm::normalize(q));
    }
    if (scale) {
      const dvec3 s(scale->get(i, 0), scale->get(i, 1), scale->get(i, 2));
      finite("SCALE", i, {s.x, s.y, s.z});
      m = glm::scale(m, s);
    }
    placed.push_back(world * m);
  }
  return placed;
}

void GltfReader::place_meshes() {
  // A mesh (with its morph weights) placed more than once is read once, in its own space, and placed
  // by instances; one placed once, and a placement whose transform cannot be inverted (a zero scale
  // hides it), is read in place as always.
  // The affine part of a placement, as the copies are placed (a node's matrix may have a last row of
  // its own); and whether it is invertible as the scene's loader asks of an instance: as floats,
  // inverted, it fits floats.
  const auto affine = [](dmat4 world) {
    world[0][3] = world[1][3] = world[2][3] = 0.0;
    world[3][3] = 1.0;
    return glm::mat4(world);
  };
  const auto invertible = [&](const dmat4& world) {
    const glm::dmat4 as_floats(affine(world));
    if (glm::determinant(glm::dmat3(as_floats)) == 0.0) return false;
    const glm::dmat4 inverse = glm::inverse(as_floats);
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 3; ++r)
        if (!(std::abs(inverse[c][r]) <= double(FLT_MAX))) return false;
    return true;
  };
  const auto key = [&](size_t node) {
    const tinygltf::Node& n = model_.nodes[node];
    return std::make_pair(n.mesh, n.weights.empty() ? model_.meshes[size_t(n.mesh)].weights : n.weights);
  };
  std::map<std::pair<int, std::vector<double>>, std::vector<const Placement*>> uses;
  for (const Placement& p : placements_)
    if (invertible(p.world)) uses[key(p.node)].push_back(&p);
  std::map<std::pair<int, std::vector<double>>, int64_t> shared;  // key -> scene_.meshes, -1: placed nothing
  uint64_t placed = 0;
  for (const Placement& p : placements_) {
    const auto found = invertible(p.world) ? uses.find(key(p.node)) : uses.end();
    if (found == uses.end() || found->second.size() < 2) {
      add_mesh(p.node, p.world);
      continue;
    }
    auto mesh = shared.find(found->first);
    if (mesh == shared.end()) {
      // Read once: its triangles gathered apart from the scene's own.
      std::vector<Triangle> own;
      std::swap(own, scene_.triangles);
      stored_apart_ += own.size();  // (the file's own triangles, held to the limit meanwhile)
      add_mesh(p.node, dmat4(1.0));
      std::swap(own, scene_.triangles);
      stored_apart_ -= scene_.triangles.size();
      int64_t index = -1;
      if (!own.empty()) {
        index = int64_t(scene_.meshes.size());
        stored_apart_ += own.size();
        scene_.meshes.push_back({std::move(own)});
      }
      mesh = shared.emplace(found->first, index).first;
    }
    if (mesh->second < 0) continue;
    placed += scene_.meshes[size_t(mesh->second)].triangles.size();
    if (placed > limits_.max_placed_triangles)
      throw LimitError(file_.string() + ": " + element("nodes", p.node) + ": the file places more than " +
                       std::to_string(limits_.max_placed_triangles) + " triangles; vkray renders at most that many");
    scene_.instances.push_back({uint32_t(mesh->second), affine(p.world), 0u});
  }
}

void GltfReader::add_mesh(size_t node, const dmat4& world) {
  const auto mesh_index = size_t(model_.nodes[node].mesh);
  const tinygltf::Mesh& mesh = model_.meshes[mesh_index];
  // The morph targets' weights: the node's, else the mesh's, else none (glTF 3.7.2.2); animations,
  // which would change them, are not played.
  const std::vector<double>& weights = model_.nodes[node].weights.empty() ? mesh.weights : model_.nodes[node].weights;
  const std::string weights_at = model_.nodes[node].weights.empty() ? element("meshes", mesh_index) + ".weights" : element("nodes", node) + ".weights";
  for (const double w : weights)
    if (!(std::abs(w) <= 1e6)) fail(weights_at, "a weight that is not a number of at most 1e6 in magnitude");
  for (size_t p = 0; p < mesh.primitives.size(); ++p) {
    const std::string where = element("meshes", mesh_index) + "." + element("primitives", p);
    if (!weights.empty() && weights.size() != mesh.primitives[p].targets.size())
      fail(weights_at, std::to_string(weights.size()) + " weights for the " + std::to_string(mesh.primitives[p].targets.size()) +
                           " morph targets of " + where);
    try {
      add_primitive(mesh.primitives[p], where, world, weights);
    } catch (const Skip& skip) {
      warn_once(skip.kind, "", skip.what + "; the primitive is left out");
    }
  }
}

std::optional<MorphedAttribute> GltfReader::attribute(const tinygltf::Primitive& p, const std::string& name, const std::string& where,
                                                      const std::vector<double>& weights, size_t vertices, std::initializer_list<int> types,
                                                      std::initializer_list<int> component_types) const {
  const auto at = p.attributes.find(name);
  if (at == p.attributes.end()) return std::nullopt;
  MorphedAttribute a{accessor(at->second, where + ".attributes." + name, types, component_types), {}};
  if (a.base.count != vertices)
    fail(where + ".attributes." + name, std::to_string(a.base.count) + " elements, where POSITION has " + std::to_string(vertices));
  // A target displaces positions, normals and tangents by 3-vectors (a tangent's w stays), and takes
  // signed normalized integers for the rest (glTF 3.7.2.2).
  const bool direction = name == "POSITION" || name == "NORMAL" || name == "TANGENT";
  // Targets that displace nothing (weight 0, or an accessor of zeros) are left out, and targets that
  // name the same accessor are one, weighed by the sum of their weights: the work per vertex is the
  // number of distinct displacements.
  std::map<int, size_t> by_accessor;  // accessor -> its place in a.targets
  for (size_t t = 0; t < weights.size(); ++t) {
    const auto target = p.targets[t].find(name);
    if (weights[t] == 0.0 || target == p.targets[t].end()) continue;
    const std::string target_at = where + "." + element("targets", t) + "." + name;
    AccessorView d = direction ? accessor(target->second, target_at, {TINYGLTF_TYPE_VEC3}, {TINYGLTF_COMPONENT_TYPE_FLOAT})
                               : accessor(target->second, target_at, types,
                                          {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                           TINYGLTF_COMPONENT_TYPE_SHORT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
    if (d.count != vertices) fail(target_at, std::to_string(d.count) + " elements, where POSITION has " + std::to_string(vertices));
    if (d.all_zero()) continue;
    if (const auto same = by_accessor.find(target->second); same != by_accessor.end()) {
      a.targets[same->second].first += weights[t];
      continue;
    }
    by_accessor[target->second] = a.targets.size();
    a.targets.emplace_back(weights[t], std::move(d));
  }
  return a;
}

void GltfReader::add_primitive(const tinygltf::Primitive& p, const std::string& where, const dmat4& world, const std::vector<double>& weights) {
  const int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
  if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
    if (mode >= TINYGLTF_MODE_POINTS && mode <= TINYGLTF_MODE_LINE_STRIP)
      throw Skip{"points and lines", where + ": points and lines (mode " + std::to_string(mode) + ") are not rendered"};
    fail(where + ".mode", "unknown mode " + std::to_string(mode));
  }
  const auto position_at = p.attributes.find("POSITION");
  if (position_at == p.attributes.end()) fail(where + ".attributes", "no POSITION");
  const size_t vertices = model_.accessors.size() > size_t(std::max(position_at->second, 0)) ? model_.accessors[size_t(position_at->second)].count : 0;
  const std::optional<MorphedAttribute> positions =
      attribute(p, "POSITION", where, weights, vertices, {TINYGLTF_TYPE_VEC3}, {TINYGLTF_COMPONENT_TYPE_FLOAT});
  if (positions->all_zero()) return;  // every vertex at the origin: nothing to see

  const uint32_t mat = material(p.material, where + ".material");
  const std::optional<MorphedAttribute> normals =
      attribute(p, "NORMAL", where, weights, vertices, {TINYGLTF_TYPE_VEC3}, {TINYGLTF_COMPONENT_TYPE_FLOAT});
  // The texture coordinate sets the material's textures read, as uv and uv1.
  std::array<std::optional<MorphedAttribute>, 2> uvs;
  std::array<std::string, 2> uv_names;
  const std::vector<int> sets = scene_.materials[mat].textured() ? texcoord_sets_[p.material] : std::vector<int>{};
  for (size_t k = 0; k < sets.size(); ++k) {
    uv_names[k] = "TEXCOORD_" + std::to_string(sets[k]);
    uvs[k] = attribute(p, uv_names[k], where, weights, vertices, {TINYGLTF_TYPE_VEC2},
                       {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
    if (!uvs[k])
      warn_once("no " + uv_names[k], where + ".attributes",
                "no " + uv_names[k] + " for its material's texture: every point takes the texture's value at (0, 0)");
  }
  // COLOR_0 multiplies the base colour (its alpha the base colour's alpha); later sets are for an
  // application's own use (glTF 3.7.2.1).
  const std::optional<MorphedAttribute> colours =
      attribute(p, "COLOR_0", where, weights, vertices, {TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4},
                {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
  // Tangents where the material has a normal map and the primitive has normals (without them, glTF
  // says a file's tangents are ignored); MikkTSpace's otherwise (load/scene_loader.cpp).
  std::optional<MorphedAttribute> tangents;
  if (normals && scene_.materials[mat].normal_texture.present())
    tangents = attribute(p, "TANGENT", where, weights, vertices, {TINYGLTF_TYPE_VEC4}, {TINYGLTF_COMPONENT_TYPE_FLOAT});

  // The corners: indexed, or the vertices in order.
  std::optional<AccessorView> indices;
  if (p.indices >= 0)
    indices = accessor(p.indices, where + ".indices", {TINYGLTF_TYPE_SCALAR},
                       {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
                       true);
  const size_t corners = indices ? indices->count : vertices;
  const auto corner = [&](size_t i) -> uint32_t {
    if (!indices) return uint32_t(i);
    const uint32_t v = indices->index(i);
    if (v >= vertices)
      fail(where + ".indices", "index " + std::to_string(v) + " at " + std::to_string(i) + " is out of range (POSITION has " +
                                   std::to_string(vertices) + " vertices)");
    return v;
  };
  size_t triangles = 0;
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    triangles = corners / 3;
    if (corners % 3 != 0) warn_once("loose corners", where, std::to_string(corners % 3) + " corners past the last whole triangle are left out");
  } else {
    triangles = corners >= 3 ? corners - 2 : 0;
  }
  if (triangles > limits_.max_triangles - std::min(limits_.max_triangles, scene_.triangles.size() + stored_apart_))
    throw LimitError(file_.string() + ": " + where + ": the file places more than " + std::to_string(limits_.max_triangles) +
                     " triangles; vkray renders at most that many");
  // Each corner adds up every displacement of every morphed attribute: held to a budget for the file,
  // so that many targets on a large mesh (or placed many times) cannot take without end.
  size_t displacements = 0;
  for (const std::optional<MorphedAttribute>* a :
       std::initializer_list<const std::optional<MorphedAttribute>*>{&positions, &normals, &colours, &tangents, &uvs[0], &uvs[1]})
    if (*a) displacements += (*a)->targets.size();
  morph_work_ += uint64_t(displacements) * 3 * triangles;
  if (morph_work_ > limits_.max_morph_displacements)
    throw LimitError(file_.string() + ": " + where + ": the file's morph targets take more than " +
                     std::to_string(limits_.max_morph_displacements) + " vertex displacements to apply; vkray applies at most that many");

  // Positions and normals in world space: normals by the inverse transpose, here the cofactor matrix
  // (the inverse transpose times the determinant: columns b x c, c x a, a x b) turned by the
  // determinant's sign, which also serves a transform that flattens the mesh (a zero scale keeps the
  // triangles in the remaining plane; those it collapses are left out as degenerate). A negative
  // determinant mirrors the mesh, which turns its front faces' winding around (glTF 3.7.2.1).
  const glm::dmat3 linear(world);
  const double det = glm::determinant(linear);
  const glm::dmat3 cofactor(glm::cross(linear[1], linear[2]), glm::cross(linear[2], linear[0]), glm::cross(linear[0], linear[1]));
  const glm::dmat3 normal_matrix = det < 0 ? -cofactor : cofactor;
  const bool mirrored = det < 0;
  const auto position = [&](uint32_t v) {
    const dvec3 p_local(positions->get(v, 0), positions->get(v, 1), positions->get(v, 2));
    if (!std::isfinite(p_local.x) || !std::isfinite(p_local.y) || !std::isfinite(p_local.z))
      fail(where + ".attributes.POSITION", "vertex " + std::to_string(v) + " is not finite");
    return glm::vec3(dvec3(world * glm::dvec4(p_local, 1.0)));
  };
  const auto normal = [&](uint32_t v) {
    const dvec3 n = normal_matrix * dvec3(normals->get(v, 0), normals->get(v, 1), normals->get(v, 2));
    const double length = glm::length(n);
    return length > 0 && std::isfinite(length) ? glm::vec3(n / length) : glm::vec3(0.0f);
  };
  // A tangent is a direction along the surface: it turns as positions do, and a transform that mirrors
  // the mesh turns the bitangent's sign around with its winding. Unit, or zero where the file's is.
  const auto tangent = [&](uint32_t v) {
    const glm::dvec4 t(tangents->get(v, 0), tangents->get(v, 1), tangents->get(v, 2), tangents->get(v, 3));
    if (!std::isfinite(t.x) || !std::isfinite(t.y) || !std::isfinite(t.z) || !std::isfinite(t.w))
      fail(where + ".attributes.TANGENT", "tangent " + std::to_string(v) + " is not finite");
    const dvec3 d = linear * dvec3(t);
    const double length = glm::length(d);
    const float sign = (t.w < 0) != mirrored ? -1.0f : 1.0f;
    return length > 0 && std::isfinite(length) ? glm::vec4(glm::vec3(d / length), sign) : glm::vec4(0.0f);
  };
  // A colour's components in [0, 1] (a float file's, or a morphed one's, may stray; glTF allows clamping).
  const auto colour = [&](uint32_t v) {
    glm::vec4 c(1.0f);
    for (int k = 0; k < colours->base.components; ++k) {
      const double x = colours->get(v, k);
      if (!std::isfinite(x)) fail(where + ".attributes.COLOR_0", "colour " + std::to_string(v) + " is not finite");
      c[k] = float(std::clamp(x, 0.0, 1.0));
    }
    return c;
  };
  const auto uv = [&](size_t set, uint32_t v) {
    const glm::dvec2 t(uvs[set]->get(v, 0), uvs[set]->get(v, 1));
    if (!(std::abs(t.x) <= kMaxCoordinate && std::abs(t.y) <= kMaxCoordinate))
      fail(where + ".attributes." + uv_names[set], "texture coordinate " + std::to_string(v) + " is not finite or past +-1e9");
    return glm::vec2(t);
  };
  reserve_more(scene_.triangles, triangles);
  for (size_t t = 0; t < triangles; ++t) {
    if (t % 4096 == 0) throw_if_interrupted();
    std::array<uint32_t, 3> c;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      c = {corner(3 * t), corner(3 * t + 1), corner(3 * t + 2)};
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      c = t % 2 == 0 ? std::array<uint32_t, 3>{corner(t), corner(t + 1), corner(t + 2)}
                     : std::array<uint32_t, 3>{corner(t + 1), corner(t), corner(t + 2)};
    } else {
      c = {corner(t + 1), corner(t + 2), corner(0)};
    }
    if (mirrored) std::swap(c[1], c[2]);
    Triangle tri;
    tri.material = mat;
    for (size_t k = 0; k < 3; ++k) {
      tri.v[k] = position(c[k]);
      if (normals) tri.normals[k] = normal(c[k]);
      if (uvs[0]) tri.uv[k] = uv(0, c[k]);
      if (uvs[1]) tri.uv1[k] = uv(1, c[k]);
      if (colours) tri.colours[k] = colour(c[k]);
    }
    tri.smooth = normals.has_value() && std::all_of(tri.normals.begin(), tri.normals.end(), [](const glm::vec3& n) { return n != glm::vec3(0.0f); });
    // A triangle with a zero tangent at a corner, or not smooth, takes MikkTSpace's instead.
    if (tangents && tri.smooth) {
      for (size_t k = 0; k < 3; ++k) tri.tangents[k] = tangent(c[k]);
      if (!std::all_of(tri.tangents.begin(), tri.tangents.end(), [](const glm::vec4& t_k) { return t_k.w != 0.0f; })) tri.tangents = {};
    }
    scene_.triangles.push_back(tri);
  }
}

uint32_t GltfReader::material(int index, const std::string& where) {
  if (const auto found = materials_.find(index); found != materials_.end()) return found->second;
  Material m;
  m.type = MaterialType::metallic_roughness;  // glTF's own, with its defaults (Material's too): metallic 1, roughness 1
  if (index < 0) {  // glTF's default material: white, metallic, fully rough, single-sided
    m.name = file_.filename().string() + ": default material";
    m.albedo = glm::vec3(1.0f);
    m.double_sided = false;
  } else {
    if (size_t(index) >= model_.materials.size())
      fail(where, "materials[" + std::to_string(index) + "] does not exist (the file has " + std::to_string(model_.materials.size()) + ")");
    const tinygltf::Material& g = model_.materials[size_t(index)];
    const std::string name = element("materials", size_t(index));
    m.name = file_.filename().string() + ": " + (g.name.empty() ? name : printable(g.name));
    const auto colour = [&](const std::vector<double>& values, size_t size, const std::string& key, double max) {
      if (values.size() != size) fail(name + "." + key, "expected " + std::to_string(size) + " numbers, got " + std::to_string(values.size()));
      for (size_t c = 0; c < 3; ++c)
        if (!(values[c] >= 0.0 && values[c] <= max))
          fail(name + "." + key, max == 1.0 ? "a value outside [0, 1]" : "a value that is negative or not a finite 32-bit float");
      return glm::vec3(float(values[0]), float(values[1]), float(values[2]));
    };
    const tinygltf::PbrMetallicRoughness& pbr = g.pbrMetallicRoughness;
    m.albedo = colour(pbr.baseColorFactor, 4, "pbrMetallicRoughness.baseColorFactor", 1.0);
    m.double_sided = g.doubleSided;
    const auto factor = [&](double value, const std::string& key) {
      if (!(value >= 0.0 && value <= 1.0)) fail(name + "." + key, "expected a number from 0 to 1, got " + brief(nlohmann::json(value)));
      return float(value);
    };
    m.metallic = factor(pbr.metallicFactor, "pbrMetallicRoughness.metallicFactor");
    m.roughness = factor(pbr.roughnessFactor, "pbrMetallicRoughness.roughnessFactor");
    if (const auto ior = g.extensions.find("KHR_materials_ior"); ior != g.extensions.end()) {
      const tinygltf::Value& v = ior->second.Get("ior");
      const double value = v.IsNumber() ? v.GetNumberAsDouble() : v.Type() == tinygltf::NULL_TYPE ? 1.5 : std::nan("");
      // 1 and more, or exactly 0 (the extension's schema): F0 = ((ior - 1) / (ior + 1))^2 is then 1.
      if (!(value == 0.0 || (value >= 1.0 && value <= double(kMaxIor))))
        fail(name + ".extensions.KHR_materials_ior.ior", "expected 0 or an index of refraction from 1 to 100");
      m.ior = float(value);
    }
    m.emission = colour(g.emissiveFactor, 3, "emissiveFactor", FLT_MAX);
    if (const auto strength = g.extensions.find("KHR_materials_emissive_strength"); strength != g.extensions.end()) {
      const tinygltf::Value& v = strength->second.Get("emissiveStrength");
      const double s = v.IsNumber() ? v.GetNumberAsDouble() : 1.0;
      if (!(s >= 0.0 && s <= 1e6)) fail(name + ".extensions.KHR_materials_emissive_strength", "emissiveStrength outside [0, 1e6]");
      const glm::dvec3 emission = glm::dvec3(m.emission) * s;
      if (!(std::max({emission.r, emission.g, emission.b}) <= double(FLT_MAX)))
        fail(name + ".extensions.KHR_materials_emissive_strength",
             "emissiveFactor times emissiveStrength passes the largest 32-bit float (3.4e38)");
      m.emission = glm::vec3(emission);
    }
    // The texture coordinate sets its textures read: the first two distinct ones, in the order the
    // textures are read here, become the triangles' uv and uv1 (TextureRef::texcoord 0 and 1); a
    // texture that asks for a third is named in a warning and reads the first.
    std::vector<int> sets;
    const auto set_of = [&](const tinygltf::TextureInfo& info, const char* which) -> uint32_t {
      const int set = texcoord_of(info);
      if (set < 0) fail(name + "." + which, "texCoord " + std::to_string(set) + " (a set's number is at least 0)");
      for (size_t i = 0; i < sets.size(); ++i)
        if (sets[i] == set) return uint32_t(i);
      if (sets.size() < 2) {
        sets.push_back(set);
        return uint32_t(sets.size() - 1);
      }
      warn_once("texcoord sets", name, std::string("the ") + which + " reads TEXCOORD_" + std::to_string(set) +
                                           "; vkray reads two sets for a material's textures (here TEXCOORD_" + std::to_string(sets[0]) +
                                           " and TEXCOORD_" + std::to_string(sets[1]) + "), and it reads TEXCOORD_" + std::to_string(sets[0]));
      return 0;
    };
    if (pbr.baseColorTexture.index >= 0) {
      m.albedo_texture = texture(pbr.baseColorTexture, name + ".pbrMetallicRoughness.baseColorTexture", true);
      m.albedo_texture.texcoord = set_of(pbr.baseColorTexture, "baseColorTexture");
    }
    if (g.emissiveTexture.index >= 0 && m.emission != glm::vec3(0.0f)) {
      m.emission_texture = texture(g.emissiveTexture, name + ".emissiveTexture", true);
      m.emission_texture.texcoord = set_of(g.emissiveTexture, "emissiveTexture");
    }
    if (pbr.metallicRoughnessTexture.index >= 0) {  // data, not colour: linear
      m.metallic_roughness_texture = texture(pbr.metallicRoughnessTexture, name + ".pbrMetallicRoughness.metallicRoughnessTexture", false);
      m.metallic_roughness_texture.texcoord = set_of(pbr.metallicRoughnessTexture, "metallicRoughnessTexture");
    }
    if (g.normalTexture.index >= 0) {  // data, not colour: linear
      tinygltf::TextureInfo info;
      info.index = g.normalTexture.index;
      info.texCoord = g.normalTexture.texCoord;
      info.extensions = g.normalTexture.extensions;
      m.normal_texture = texture(info, name + ".normalTexture", false);
      if (!(std::abs(g.normalTexture.scale) <= 1e6))
        fail(name + ".normalTexture.scale", "expected a number of at most 1e6 in magnitude, got " + brief(nlohmann::json(g.normalTexture.scale)));
      m.normal_scale = float(g.normalTexture.scale);
      m.normal_texture.texcoord = set_of(info, "normalTexture");
    }
    if (const auto ext = g.extensions.find("KHR_materials_transmission"); ext != g.extensions.end()) {
      // Thin-walled, as the extension is without KHR_materials_volume (which vkray does not read): the
      // factor times the red of a linear texture. (gltf_schema.cpp has checked the types.)
      const std::string at = "extensions.KHR_materials_transmission";
      const tinygltf::Value& f = ext->second.Get("transmissionFactor");
      m.transmission = factor(f.IsNumber() ? f.GetNumberAsDouble() : 0.0, at + ".transmissionFactor");
      const tinygltf::Value& t = ext->second.Get("transmissionTexture");
      if (t.IsObject() && m.transmission > 0.0f) {
        tinygltf::TextureInfo info;
        info.index = t.Get("index").GetNumberAsInt();
        if (t.Has("texCoord")) info.texCoord = t.Get("texCoord").GetNumberAsInt();
        if (t.Has("extensions"))
          for (const std::string& key : t.Get("extensions").Keys()) info.extensions[key] = t.Get("extensions").Get(key);
        m.transmission_texture = texture(info, name + "." + at + ".transmissionTexture", false);
        m.transmission_texture.texcoord = set_of(info, "transmissionTexture");
      }
    }
    texcoord_sets_[index] = sets;
    if (g.occlusionTexture.index >= 0) warn_once("occlusionTexture", name, "occlusion textures are not rendered (light transport computes occlusion)");
    // Alpha: the base colour's, factor times texture (the texture's alpha, or 1 where it has none).
    // (gltf_schema.cpp has checked the mode's name.)
    m.alpha_mode = g.alphaMode == "MASK" ? AlphaMode::mask : g.alphaMode == "BLEND" ? AlphaMode::blend : AlphaMode::opaque;
    if (!(g.alphaCutoff >= 0.0 && g.alphaCutoff <= double(FLT_MAX)))
      fail(name + ".alphaCutoff", "expected a number of at least 0, got " + brief(nlohmann::json(g.alphaCutoff)));
    m.alpha_cutoff = float(g.alphaCutoff);
    if (!(pbr.baseColorFactor[3] >= 0.0 && pbr.baseColorFactor[3] <= 1.0))
      fail(name + ".pbrMetallicRoughness.baseColorFactor", "an alpha outside [0, 1]");
    m.opacity = float(pbr.baseColorFactor[3]);
    if (m.alpha_mode != AlphaMode::opaque) m.opacity_texture = m.albedo_texture;
    if (g.extensions.count("KHR_materials_unlit")) {
      // KHR_materials_unlit: the surface shows its base colour (factor times texture) and scatters
      // nothing; its other properties are for lit materials and are not used. Its base colour becomes
      // its emission, seen from its front as every emission is, and lighting the rest like any other.
      Material unlit;
      unlit.name = m.name;
      unlit.type = MaterialType::diffuse;
      unlit.albedo = glm::vec3(0.0f);
      unlit.emission = m.albedo;
      unlit.emission_texture = m.albedo_texture;
      unlit.double_sided = m.double_sided;
      unlit.alpha_mode = m.alpha_mode;
      unlit.opacity = m.opacity;
      unlit.alpha_cutoff = m.alpha_cutoff;
      unlit.opacity_texture = m.opacity_texture;
      unlit.vertex_colours_emit = true;
      unlit.emits_both_sides = m.double_sided;  // its base colour shows from both sides
      // Its one texture's set is the only one its triangles need.
      unlit.emission_texture.texcoord = unlit.opacity_texture.texcoord = 0;
      texcoord_sets_[index] = m.albedo_texture.present() ? std::vector<int>{texcoord_of(pbr.baseColorTexture)} : std::vector<int>{};
      m = std::move(unlit);
    }
  }
  const auto at = uint32_t(scene_.materials.size());
  scene_.materials.push_back(std::move(m));
  materials_[index] = at;
  return at;
}

TextureRef GltfReader::texture(const tinygltf::TextureInfo& info, const std::string& where, bool srgb) {
  if (size_t(info.index) >= model_.textures.size())
    fail(where, "textures[" + std::to_string(info.index) + "] does not exist (the file has " + std::to_string(model_.textures.size()) + ")");
  const tinygltf::Texture& t = model_.textures[size_t(info.index)];
  const std::string name = element("textures", size_t(info.index));
  TextureRef ref;
  if (t.source < 0) {
    warn_once("no source", name, "a texture with no PNG or JPEG source (another extension's format?) is not rendered");
    return ref;
  }
  ref.texture = image_texture(t.source, name + ".source", srgb);
  if (const auto ext = info.extensions.find("KHR_texture_transform"); ext != info.extensions.end()) {
    // The extension's u' = T R S (u, v, 1), rotating by `rotation` counter-clockwise in the picture
    // (whose v runs down): u' = sx u cos + sy v sin + ox, v' = sy v cos - sx u sin + oy. Its GLSL
    // listing reads this way when its mat3 arguments are taken row by row, as its sample model
    // (TextureTransformTest) and the implementations it names do.
    const std::string at = where + ".extensions.KHR_texture_transform";
    const auto number = [&](const tinygltf::Value& v, const std::string& key) {
      const double x = v.IsNumber() ? v.GetNumberAsDouble() : std::nan("");
      if (!(std::abs(x) <= 1e6)) fail(at + "." + key, "expected a number of at most 1e6 in magnitude");
      return x;
    };
    const auto pair = [&](const char* key, double fallback) {
      const tinygltf::Value& v = ext->second.Get(key);
      if (!v.IsArray() && v.Type() != tinygltf::NULL_TYPE) fail(at + "." + key, "expected two numbers");
      if (!v.IsArray()) return glm::dvec2(fallback);
      if (v.ArrayLen() != 2) fail(at + "." + key, "expected two numbers, got " + std::to_string(v.ArrayLen()));
      return glm::dvec2(number(v.Get(0), std::string(key) + "[0]"), number(v.Get(1), std::string(key) + "[1]"));
    };
    const glm::dvec2 offset = pair("offset", 0.0), scale = pair("scale", 1.0);
    const tinygltf::Value& r = ext->second.Get("rotation");
    const double rotation = r.Type() == tinygltf::NULL_TYPE ? 0.0 : number(r, "rotation");
    const tinygltf::Value& set = ext->second.Get("texCoord");
    if (set.Type() != tinygltf::NULL_TYPE && !(set.IsInt() && set.GetNumberAsInt() >= 0))
      fail(at + ".texCoord", "expected a whole number of at least 0");
    const double c = std::cos(rotation), s = std::sin(rotation);
    ref.to_u = glm::vec3(float(c * scale.x), float(s * scale.y), float(offset.x));
    ref.to_v = glm::vec3(float(-s * scale.x), float(c * scale.y), float(offset.y));
  }
  if (t.sampler >= 0) {
    if (size_t(t.sampler) >= model_.samplers.size())
      fail(name + ".sampler", "samplers[" + std::to_string(t.sampler) + "] does not exist (the file has " + std::to_string(model_.samplers.size()) + ")");
    const tinygltf::Sampler& s = model_.samplers[size_t(t.sampler)];
    const auto wrap = [&](int mode, const char* key) {
      switch (mode) {
        case TINYGLTF_TEXTURE_WRAP_REPEAT: return TextureWrap::repeat;
        case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return TextureWrap::clamp_to_edge;
        case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return TextureWrap::mirrored_repeat;
      }
      fail(element("samplers", size_t(t.sampler)) + "." + key, "unknown wrap mode " + std::to_string(mode));
    };
    ref.wrap_s = wrap(s.wrapS, "wrapS");
    ref.wrap_t = wrap(s.wrapT, "wrapT");
    // Magnification decides: vkray has no mipmaps, so minification filters as magnification does.
    if (s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST) ref.filter = TextureFilter::nearest;
  }
  return ref;
}

int32_t GltfReader::image_texture(int image, const std::string& where, bool srgb) {
  if (const auto found = image_textures_.find({image, srgb}); found != image_textures_.end()) return found->second;
  if (size_t(image) >= model_.images.size())
    fail(where, "images[" + std::to_string(image) + "] does not exist (the file has " + std::to_string(model_.images.size()) + ")");
  const tinygltf::Image& img = model_.images[size_t(image)];
  // Where its bytes are: a buffer view, a file (tinygltf keeps the URI of a file and reads none), or
  // a data: URI that tinygltf decoded. The same view or file named by several images is decoded once.
  // A uri tinygltf left as it is: a file, or a data: URI of a type tinygltf does not decode.
  const bool by_uri = img.bufferView < 0 && img.image.empty();
  if (by_uri && img.uri.empty()) fail(element("images", size_t(image)), "no picture (neither a uri nor a bufferView with data)");
  const UriTarget target = by_uri ? resolve_uri(img.uri, file_, element("images", size_t(image)) + ".uri") : UriTarget{};
  const std::string source = img.bufferView >= 0 ? "view " + std::to_string(img.bufferView)
                           : by_uri && !target.data() ? "file " + target.file.string() : "";
  if (const auto found = sources_.find({source, srgb}); !source.empty() && found != sources_.end())
    return image_textures_[{image, srgb}] = found->second;
  std::string name = file_.string() + ": " + element("images", size_t(image));
  std::string_view bytes(reinterpret_cast<const char*>(img.image.data()), img.image.size());
  std::string external;
  if (by_uri) {
    name += " (" + printable(img.uri, 200) + ")";
    if (target.data()) {
      external = decode_base64(target.base64);
    } else {
      if (!limits_.read_files) fail(element("images", size_t(image)), "external files are not read here: " + printable(img.uri, 200));
      InputFile input = read_input_file(target.file, kMaxPictureFileBytes);
      if (!input.error.empty()) throw SceneError(name + ": " + (input.error == "not found" ? "picture file not found" : input.error));
      scene_.files.push_back(target.file);
      external = std::move(input.text);
    }
    bytes = external;
  }
  // Its size from its header, against what the scene's textures may take together, before decoding.
  const PictureSize size = picture_size(bytes, name);
  const uint64_t texels = uint64_t(size.width) * size.height;
  if (texels > limits_.max_texels - std::min(limits_.max_texels, texels_))
    throw LimitError(name + ": a " + std::to_string(size.width) + " x " + std::to_string(size.height) +
                     " picture would bring the scene's textures past " + std::to_string(limits_.max_texels >> 20) +
                     "M texels, vkray's limit (docs/limits.md)");
  texels_ += texels;
  auto texture = std::make_shared<const Texture>(make_texture(decode_picture(bytes, name), name, srgb));
  const auto index = int32_t(scene_.textures.size());
  scene_.textures.push_back(std::move(texture));
  image_textures_[{image, srgb}] = index;
  if (!source.empty()) sources_[{source, srgb}] = index;
  return index;
}

void GltfReader::add_camera(size_t node, const dmat4& world) {
  const tinygltf::Node& n = model_.nodes[node];
  const std::string where = element("nodes", node) + ".camera";
  if (size_t(n.camera) >= model_.cameras.size())
    fail(where, "cameras[" + std::to_string(n.camera) + "] does not exist (the file has " + std::to_string(model_.cameras.size()) + ")");
  if (camera_found_) return;  // the first one is the one
  const tinygltf::Camera& c = model_.cameras[size_t(n.camera)];
  const std::string name = element("cameras", size_t(n.camera));
  if (c.type != "perspective") {
    warn_once("orthographic", name, "an orthographic camera is not rendered; vkray frames the scene with its own camera");
    return;
  }
  camera_found_ = true;
  const double yfov = c.perspective.yfov;
  if (!(yfov > 1e-6 && yfov < 3.14159)) fail(name + ".perspective.yfov", "expected radians in (0, pi)");
  // A camera looks down its local -z, with +y up (glTF 3.10.1).
  const dvec3 position(world * glm::dvec4(0, 0, 0, 1));
  const dvec3 forward(world * glm::dvec4(0, 0, -1, 0)), up(world * glm::dvec4(0, 1, 0, 0));
  const double f = glm::length(forward);
  if (!(f > 0 && std::isfinite(f)) || !(glm::length(glm::cross(forward / f, up)) > 1e-6 * glm::length(up)) ||
      !(glm::length(position) < double(kMaxCoordinate))) {
    warn_once("degenerate camera", element("nodes", node), "the camera's transform is degenerate; vkray frames the scene with its own camera");
    camera_found_ = false;
    return;
  }
  Camera camera;
  camera.position = glm::vec3(position);
  camera.forward = glm::vec3(forward / f);
  camera.up = glm::vec3(glm::normalize(up));
  camera.focal_length = float(0.5 / std::tan(yfov / 2));
  scene_.camera = camera;
  const double aspect = c.perspective.aspectRatio;
  scene_.aspect_ratio = aspect > 0 && aspect < 1e4 ? float(aspect) : 0.0f;
}

void GltfReader::add_light(size_t node, const dmat4& world) {
  const tinygltf::Value& ext = model_.nodes[node].extensions.at("KHR_lights_punctual");
  const std::string where = element("nodes", node) + ".extensions.KHR_lights_punctual.light";
  if (!ext.IsObject() || !ext.Has("light") || !ext.Get("light").IsInt()) fail(where, "expected the index of a light");
  const int index = ext.Get("light").GetNumberAsInt();
  if (index < 0 || size_t(index) >= model_.lights.size())
    fail(where, "lights[" + std::to_string(index) + "] does not exist (the file has " + std::to_string(model_.lights.size()) + ")");
  const tinygltf::Light& l = model_.lights[size_t(index)];
  const std::string name = "KHR_lights_punctual." + element("lights", size_t(index));
  Light light;
  if (l.type == "spot") {
    light.type = Light::Type::spot;
  } else if (l.type == "directional") {
    light.type = Light::Type::directional;
  } else if (l.type != "point") {
    fail(name + ".type", "unknown light type \"" + printable(l.type) + "\" (expected \"point\", \"spot\" or \"directional\")");
  }
  glm::vec3 colour(1.0f);
  if (!l.color.empty()) {
    if (l.color.size() != 3) fail(name + ".color", "expected 3 numbers");
    for (size_t c = 0; c < 3; ++c) {
      if (!(l.color[c] >= 0.0 && l.color[c] <= 1e6)) fail(name + ".color", "a value outside [0, 1e6]");
      colour[int(c)] = float(l.color[c]);
    }
  }
  if (!(l.intensity >= 0.0 && l.intensity <= 1e12)) fail(name + ".intensity", "expected a number from 0 to 1e12");
  if (l.range > 0 && light.type != Light::Type::directional)
    warn_once("light range", name, "a light's range is not rendered: its light reaches everywhere");
  // glTF's intensity is in candela (lm/sr) for point and spot lights and in lux (lm/m^2) for
  // directional ones; vkray's are W/sr and W/m^2, and the value is taken as it is.
  light.intensity = colour * float(l.intensity);
  if (light.type != Light::Type::directional) {
    const dvec3 position(world * glm::dvec4(0, 0, 0, 1));
    if (!(glm::length(position) < double(kMaxCoordinate))) fail(element("nodes", node), "the light lies past +-1e9");
    light.position = glm::vec3(position);
  }
  if (light.type != Light::Type::point) {
    // It shines along the node's -z.
    const dvec3 direction = glm::dmat3(world) * dvec3(0, 0, -1);
    if (!(glm::length(direction) > 0.0) || !std::isfinite(glm::length(direction)))
      fail(element("nodes", node), "the node's transform leaves the light no direction");
    light.direction = glm::vec3(glm::normalize(direction));
  }
  if (light.type == Light::Type::spot) {
    // The specification: 0 <= innerConeAngle < outerConeAngle <= pi / 2.
    const double inner = l.spot.innerConeAngle, outer = l.spot.outerConeAngle;
    if (!(outer > 0.0 && outer <= glm::half_pi<double>() + 1e-6))
      fail(name + ".spot.outerConeAngle", "expected radians in (0, pi/2]");
    if (!(inner >= 0.0 && inner < outer)) fail(name + ".spot.innerConeAngle", "expected radians from 0 to below outerConeAngle");
    light.falloff = Light::Falloff::gltf;
    light.cutoff_angle = float(std::min(outer, glm::half_pi<double>()));
    light.beam_width = float(inner);
  }
  scene_.lights.push_back(light);
}

GltfScene GltfReader::read(std::string_view bytes) {
  const bool binary = bytes.size() >= 4 && bytes.substr(0, 4) == "glTF";
  // The JSON is checked by vkray's own reader first (syntax with line and column, nesting depth,
  // duplicate keys), so that what reaches tinygltf is well-formed and shallow.
  nlohmann::json doc;
  bool has_binary_chunk = false;
  if (binary) {
    has_binary_chunk = check_glb(bytes);
    uint32_t json_length;
    std::memcpy(&json_length, bytes.data() + 12, 4);
    doc = parse_json_document(bytes.substr(20, json_length), file_);
  } else {
    doc = parse_json_document(bytes, file_);
  }
  if (!doc.is_object()) fail("", "the JSON is not an object");
  check_gltf_schema(doc, file_);
  check_buffer_views(doc);
  check_required_extensions(doc);
  GltfFiles files(doc, file_, limits_.read_files, binary, has_binary_chunk);
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(keep_encoded, nullptr);
  loader.SetFsCallbacks(files.callbacks());
  std::string err, warn;
  const std::string base_dir = file_.parent_path().string();
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  const auto size = static_cast<unsigned int>(bytes.size());
  doc = nlohmann::json();  // its copy of the file is not needed while tinygltf makes its own
  bool ok = false;
  try {
    ok = binary ? loader.LoadBinaryFromMemory(&model_, &err, &warn, data, size, base_dir)
                : loader.LoadASCIIFromString(&model_, &err, &warn, bytes.data(), size, base_dir);
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const Error&) {  // from a file callback: Ctrl-C, or host memory running out
    throw;
  } catch (const std::exception& e) {  // tinygltf's own slips (std::out_of_range from .at()): the file's fault
    fail("", std::string("tinygltf could not read the file: ") + e.what());
  }
  if (!files.error().empty()) fail("", files.error());  // a buffer vkray resolved could not be read
  if (!ok) {
    std::string message = err.empty() ? "tinygltf could not read the file" : err;
    std::replace(message.begin(), message.end(), '\n', ' ');
    fail("", printable(message, 400));
  }
  scene_.files = files.read();
  warn_used_extensions();
  if (!model_.animations.empty())
    warn_once("animations", "animations", std::to_string(model_.animations.size()) +
                                              " animations are not played: the file is shown at rest (its nodes' transforms, its default morph weights)");
  walk_nodes();
  place_meshes();
  return std::move(scene_);
}

}  // namespace

GltfScene parse_gltf(std::string_view bytes, const std::filesystem::path& file, const GltfLimits& limits) {
  if (bytes.size() > kMaxGltfFileBytes) throw LimitError(file.string() + ": larger than vkray's limit for glTF files (2 GiB)");
  return GltfReader(file, limits).read(bytes);
}

GltfScene load_gltf(const std::filesystem::path& file, const GltfLimits& limits) {
  const InputFile input = read_input_file(file, kMaxGltfFileBytes);
  if (!input.error.empty()) throw SceneError(file.string() + ": " + (input.error == "not found" ? "glTF file not found" : input.error));
  return parse_gltf(input.text, file, limits);
}

}  // namespace vkray
