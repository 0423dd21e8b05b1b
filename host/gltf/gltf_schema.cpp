#include "gltf/gltf_schema.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "base/errors.h"
#include "base/input_file.h"
#include "base/json_document.h"

namespace vkray {
namespace {

class SchemaCheck {
 public:
  using json = nlohmann::json;
  SchemaCheck(const json& doc, const std::filesystem::path& file) : doc_(doc), file_(file) {}
  void run() const;

 private:
  // The largest byte offset, length or count: a buffer holds at most what vkray reads of a file.
  static constexpr uint64_t kMaxBytes = kMaxGltfFileBytes;
  static constexpr uint64_t kMaxInt = INT32_MAX;  // what tinygltf holds in an int (texCoord, sparse counts)

  [[noreturn]] void fail(const std::string& at, const std::string& what) const {
    throw SceneError(file_.string() + ": " + at + ": " + what);
  }
  void expect(bool ok, const json& value, const std::string& at, const std::string& expected) const {
    if (!ok) fail(at, "expected " + expected + ", got " + brief(value));
  }
  static std::string path(const std::string& at, const std::string& key) { return at.empty() ? key : at + "." + key; }
  // The value of `key` in `object`, or null when it is absent (refused when required).
  const json* find(const json& object, const std::string& at, const char* key, bool required = false) const;
  // The number of elements of a root array ("accessors"), 0 when the file has none.
  size_t count(const char* array) const {
    const auto it = doc_.find(array);
    return it == doc_.end() ? 0 : it->size();
  }

  // One key of each kind; absent keys pass unless required.
  void index(const json& value, const std::string& at, const std::string& array, size_t size) const;
  void index_key(const json& o, const std::string& at, const char* key, const char* array, bool required = false) const;
  void indices_key(const json& o, const std::string& at, const char* key, const char* array, bool required = false) const;
  void whole_key(const json& o, const std::string& at, const char* key, uint64_t min, uint64_t max, bool required = false,
                 const char* unit = "") const;
  void enum_key(const json& o, const std::string& at, const char* key, std::initializer_list<int> values, bool required = false) const;
  void enum_key(const json& o, const std::string& at, const char* key, std::initializer_list<const char*> values,
                bool required = false) const;
  void number_key(const json& o, const std::string& at, const char* key, bool required = false) const;
  void numbers_key(const json& o, const std::string& at, const char* key, size_t min_size, size_t max_size) const;
  void string_key(const json& o, const std::string& at, const char* key, bool required = false) const;
  void bool_key(const json& o, const std::string& at, const char* key) const;
  const json* object_key(const json& o, const std::string& at, const char* key, bool required = false) const;
  // `name`, `extensions` (an object of objects) and `extras`, which every object may have.
  void common(const json& o, const std::string& at) const;
  // Each element of an array of objects at `key` of `o`, checked by `check(element, its place)`.
  template <typename Check>
  void each(const json& o, const std::string& at, const char* key, Check check, bool required = false) const;

  void asset(const json& a, const std::string& at) const;
  void accessor(const json& a, const std::string& at) const;
  void animation(const json& a, const std::string& at) const;
  void buffer(const json& b, const std::string& at) const;
  void buffer_view(const json& v, const std::string& at) const;
  void camera(const json& c, const std::string& at) const;
  void image(const json& i, const std::string& at) const;
  void material(const json& m, const std::string& at) const;
  void texture_info(const json& o, const std::string& at, const char* key, const char* extra_number = nullptr) const;
  void mesh(const json& m, const std::string& at) const;
  void node(const json& n, const std::string& at) const;
  void sampler(const json& s, const std::string& at) const;
  void scene(const json& s, const std::string& at) const;
  void skin(const json& s, const std::string& at) const;
  void texture(const json& t, const std::string& at) const;
  void light(const json& l, const std::string& at) const;

  const json& doc_;
  const std::filesystem::path& file_;
};

const nlohmann::json* SchemaCheck::find(const json& object, const std::string& at, const char* key, bool required) const {
  const auto it = object.find(key);
  if (it != object.end()) return &*it;
  if (required) fail(at.empty() ? "top level" : at, std::string("missing required key \"") + key + "\"");
  return nullptr;
}

void SchemaCheck::index(const json& value, const std::string& at, const std::string& array, size_t size) const {
  expect(value.is_number_integer(), value, at, "an index into " + array);
  if (value.is_number_unsigned() && value.get<uint64_t>() < size) return;
  const std::string number = value.is_number_unsigned() ? std::to_string(value.get<uint64_t>()) : std::to_string(value.get<int64_t>());
  fail(at, array + "[" + number + "] does not exist (the file has " + std::to_string(size) + ")");
}

void SchemaCheck::index_key(const json& o, const std::string& at, const char* key, const char* array, bool required) const {
  if (const json* v = find(o, at, key, required)) index(*v, path(at, key), array, count(array));
}

void SchemaCheck::indices_key(const json& o, const std::string& at, const char* key, const char* array, bool required) const {
  const json* v = find(o, at, key, required);
  if (!v) return;
  expect(v->is_array(), *v, path(at, key), "an array of indices into " + std::string(array));
  for (size_t i = 0; i < v->size(); ++i) index((*v)[i], path(at, key) + "[" + std::to_string(i) + "]", array, count(array));
}

void SchemaCheck::whole_key(const json& o, const std::string& at, const char* key, uint64_t min, uint64_t max, bool required,
                            const char* unit) const {
  const json* v = find(o, at, key, required);
  if (!v) return;
  const bool ok = v->is_number_unsigned() && v->get<uint64_t>() >= min && v->get<uint64_t>() <= max;
  expect(ok, *v, path(at, key),
         std::string("a whole number") + unit + ", at least " + std::to_string(min) + " and at most " + std::to_string(max));
}

void SchemaCheck::enum_key(const json& o, const std::string& at, const char* key, std::initializer_list<int> values, bool required) const {
  const json* v = find(o, at, key, required);
  if (!v) return;
  std::string list;
  for (const int value : values) {
    if (v->is_number_integer() && v->get<int64_t>() == value) return;
    list += (list.empty() ? "" : ", ") + std::to_string(value);
  }
  fail(path(at, key), "expected one of " + list + ", got " + brief(*v));
}

void SchemaCheck::enum_key(const json& o, const std::string& at, const char* key, std::initializer_list<const char*> values,
                           bool required) const {
  const json* v = find(o, at, key, required);
  if (!v) return;
  std::string list;
  for (const char* value : values) {
    if (v->is_string() && v->get_ref<const std::string&>() == value) return;
    list += (list.empty() ? "\"" : ", \"") + std::string(value) + "\"";
  }
  fail(path(at, key), "expected one of " + list + ", got " + brief(*v));
}

void SchemaCheck::number_key(const json& o, const std::string& at, const char* key, bool required) const {
  if (const json* v = find(o, at, key, required)) expect(v->is_number(), *v, path(at, key), "a number");
}

void SchemaCheck::numbers_key(const json& o, const std::string& at, const char* key, size_t min_size, size_t max_size) const {
  const json* v = find(o, at, key);
  if (!v) return;
  const std::string size = min_size == max_size ? std::to_string(min_size)
                         : max_size == SIZE_MAX ? "at least " + std::to_string(min_size)
                                                : std::to_string(min_size) + " to " + std::to_string(max_size);
  expect(v->is_array() && v->size() >= min_size && v->size() <= max_size && std::all_of(v->begin(), v->end(), [](const json& x) { return x.is_number(); }),
         *v, path(at, key), "an array of " + size + " numbers");
}

void SchemaCheck::string_key(const json& o, const std::string& at, const char* key, bool required) const {
  if (const json* v = find(o, at, key, required)) expect(v->is_string(), *v, path(at, key), "a string");
}

void SchemaCheck::bool_key(const json& o, const std::string& at, const char* key) const {
  if (const json* v = find(o, at, key)) expect(v->is_boolean(), *v, path(at, key), "true or false");
}

const nlohmann::json* SchemaCheck::object_key(const json& o, const std::string& at, const char* key, bool required) const {
  const json* v = find(o, at, key, required);
  if (v) expect(v->is_object(), *v, path(at, key), "an object");
  return v;
}

void SchemaCheck::common(const json& o, const std::string& at) const {
  string_key(o, at, "name");
  if (const json* extensions = object_key(o, at, "extensions"))
    for (const auto& [name, value] : extensions->items()) expect(value.is_object(), value, path(at, "extensions." + name), "an object");
}

template <typename Check>
void SchemaCheck::each(const json& o, const std::string& at, const char* key, Check check, bool required) const {
  const json* v = find(o, at, key, required);
  if (!v) return;
  const std::string where = path(at, key);
  expect(v->is_array(), *v, where, "an array of objects");
  for (size_t i = 0; i < v->size(); ++i) {
    const std::string element_at = where + "[" + std::to_string(i) + "]";
    expect((*v)[i].is_object(), (*v)[i], element_at, "an object");
    common((*v)[i], element_at);
    check((*v)[i], element_at);
  }
}

void SchemaCheck::asset(const json& a, const std::string& at) const {
  string_key(a, at, "version", true);
  string_key(a, at, "minVersion");
  string_key(a, at, "generator");
  string_key(a, at, "copyright");
  // "2.0", "2.1", ...: a later minor version adds only what a 2.0 reader may ignore, unless minVersion asks for it.
  const std::string& version = a["version"].get_ref<const std::string&>();
  if (version.rfind("2.", 0) != 0) fail(path(at, "version"), "glTF " + printable(version) + "; vkray reads glTF 2.0");
  if (a.contains("minVersion") && a["minVersion"] != "2.0")
    fail(path(at, "minVersion"), "the file needs a reader of glTF " + printable(a["minVersion"].get<std::string>()) + "; vkray reads glTF 2.0");
}

void SchemaCheck::accessor(const json& a, const std::string& at) const {
  index_key(a, at, "bufferView", "bufferViews");
  whole_key(a, at, "byteOffset", 0, kMaxBytes, false, " of bytes");
  enum_key(a, at, "componentType", {5120, 5121, 5122, 5123, 5125, 5126}, true);
  bool_key(a, at, "normalized");
  whole_key(a, at, "count", 1, kMaxBytes, true);
  enum_key(a, at, "type", {"SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4"}, true);
  numbers_key(a, at, "max", 1, 16);
  numbers_key(a, at, "min", 1, 16);
  if (const json* sparse = object_key(a, at, "sparse")) {
    const std::string s = path(at, "sparse");
    common(*sparse, s);
    whole_key(*sparse, s, "count", 1, kMaxInt, true);
    const json& ind = *object_key(*sparse, s, "indices", true);
    common(ind, path(s, "indices"));
    index_key(ind, path(s, "indices"), "bufferView", "bufferViews", true);
    whole_key(ind, path(s, "indices"), "byteOffset", 0, kMaxInt, false, " of bytes");
    enum_key(ind, path(s, "indices"), "componentType", {5121, 5123, 5125}, true);
    const json& values = *object_key(*sparse, s, "values", true);
    common(values, path(s, "values"));
    index_key(values, path(s, "values"), "bufferView", "bufferViews", true);
    whole_key(values, path(s, "values"), "byteOffset", 0, kMaxInt, false, " of bytes");
  }
}

void SchemaCheck::animation(const json& a, const std::string& at) const {
  const size_t samplers = a.contains("samplers") && a["samplers"].is_array() ? a["samplers"].size() : 0;
  each(a, at, "channels", [&](const json& c, const std::string& c_at) {
    if (const json* s = find(c, c_at, "sampler", true)) index(*s, path(c_at, "sampler"), path(at, "samplers"), samplers);
    const json& target = *object_key(c, c_at, "target", true);
    common(target, path(c_at, "target"));
    index_key(target, path(c_at, "target"), "node", "nodes");
    enum_key(target, path(c_at, "target"), "path", {"translation", "rotation", "scale", "weights"}, true);
  }, true);
  each(a, at, "samplers", [&](const json& s, const std::string& s_at) {
    index_key(s, s_at, "input", "accessors", true);
    enum_key(s, s_at, "interpolation", {"LINEAR", "STEP", "CUBICSPLINE"});
    index_key(s, s_at, "output", "accessors", true);
  }, true);
}

void SchemaCheck::buffer(const json& b, const std::string& at) const {
  string_key(b, at, "uri");
  whole_key(b, at, "byteLength", 1, kMaxBytes, true, " of bytes");
}

void SchemaCheck::buffer_view(const json& v, const std::string& at) const {
  index_key(v, at, "buffer", "buffers", true);
  whole_key(v, at, "byteOffset", 0, kMaxBytes, false, " of bytes");
  whole_key(v, at, "byteLength", 1, kMaxBytes, true, " of bytes");
  if (const json* stride = find(v, at, "byteStride"))
    expect(stride->is_number_unsigned() && *stride >= 4 && *stride <= 252 && stride->get<uint64_t>() % 4 == 0, *stride,
           path(at, "byteStride"), "a multiple of 4 from 4 to 252");
  enum_key(v, at, "target", {34962, 34963});
}

void SchemaCheck::camera(const json& c, const std::string& at) const {
  enum_key(c, at, "type", {"perspective", "orthographic"}, true);
  const bool perspective = c["type"] == "perspective";
  // The object the type names is required; the other one is not read.
  if (const json* p = object_key(c, at, "perspective", perspective)) {
    common(*p, path(at, "perspective"));
    for (const char* key : {"yfov", "znear"}) number_key(*p, path(at, "perspective"), key, true);
    for (const char* key : {"aspectRatio", "zfar"}) number_key(*p, path(at, "perspective"), key);
  }
  if (const json* o = object_key(c, at, "orthographic", !perspective)) {
    common(*o, path(at, "orthographic"));
    for (const char* key : {"xmag", "ymag", "zfar", "znear"}) number_key(*o, path(at, "orthographic"), key, true);
  }
}

void SchemaCheck::image(const json& i, const std::string& at) const {
  string_key(i, at, "uri");
  string_key(i, at, "mimeType");
  index_key(i, at, "bufferView", "bufferViews");
  if (i.contains("uri") == i.contains("bufferView"))
    fail(at, i.contains("uri") ? "give a uri or a bufferView, not both" : "no picture: give a uri or a bufferView");
}

void SchemaCheck::texture_info(const json& o, const std::string& at, const char* key, const char* extra_number) const {
  const json* info = object_key(o, at, key);
  if (!info) return;
  const std::string where = path(at, key);
  common(*info, where);
  index_key(*info, where, "index", "textures", true);
  whole_key(*info, where, "texCoord", 0, kMaxInt);
  if (extra_number) number_key(*info, where, extra_number);
  // The reader takes a whole number past 32 bits round to another (tinygltf's int): such values are
  // refused here, before it, as every number of the extension is bounded by 1e6 anyway.
  if (info->contains("extensions") && (*info)["extensions"].contains("KHR_texture_transform")) {
    const json& t = (*info)["extensions"]["KHR_texture_transform"];
    const std::string t_at = path(where, "extensions.KHR_texture_transform");
    numbers_key(t, t_at, "offset", 2, 2);
    numbers_key(t, t_at, "scale", 2, 2);
    number_key(t, t_at, "rotation");
    whole_key(t, t_at, "texCoord", 0, kMaxInt);
    for (const char* name : {"offset", "scale", "rotation"})
      if (const json* v = find(t, t_at, name))
        for (const json& x : v->is_array() ? *v : json::array({*v}))
          expect(std::abs(x.get<double>()) <= 1e6, x, path(t_at, name), "a number of at most 1e6 in magnitude");
  }
}

void SchemaCheck::material(const json& m, const std::string& at) const {
  if (const json* pbr = object_key(m, at, "pbrMetallicRoughness")) {
    const std::string where = path(at, "pbrMetallicRoughness");
    common(*pbr, where);
    numbers_key(*pbr, where, "baseColorFactor", 4, 4);
    texture_info(*pbr, where, "baseColorTexture");
    number_key(*pbr, where, "metallicFactor");
    number_key(*pbr, where, "roughnessFactor");
    texture_info(*pbr, where, "metallicRoughnessTexture");
  }
  texture_info(m, at, "normalTexture", "scale");
  texture_info(m, at, "occlusionTexture", "strength");
  texture_info(m, at, "emissiveTexture");
  numbers_key(m, at, "emissiveFactor", 3, 3);
  enum_key(m, at, "alphaMode", {"OPAQUE", "MASK", "BLEND"});
  number_key(m, at, "alphaCutoff");
  bool_key(m, at, "doubleSided");
  if (m.contains("extensions") && m["extensions"].contains("KHR_materials_emissive_strength"))
    number_key(m["extensions"]["KHR_materials_emissive_strength"], path(at, "extensions.KHR_materials_emissive_strength"), "emissiveStrength");
  if (m.contains("extensions") && m["extensions"].contains("KHR_materials_ior")) {
    const json& e = m["extensions"]["KHR_materials_ior"];
    const std::string e_at = path(at, "extensions.KHR_materials_ior");
    number_key(e, e_at, "ior");
    if (const json* v = find(e, e_at, "ior")) expect(std::abs(v->get<double>()) <= 1e6, *v, path(e_at, "ior"), "an index of refraction");
  }
  if (m.contains("extensions") && m["extensions"].contains("KHR_materials_transmission")) {
    const json& e = m["extensions"]["KHR_materials_transmission"];
    const std::string e_at = path(at, "extensions.KHR_materials_transmission");
    number_key(e, e_at, "transmissionFactor");
    texture_info(e, e_at, "transmissionTexture");
  }
}

void SchemaCheck::mesh(const json& m, const std::string& at) const {
  // An attributes object: each value the index of an accessor.
  const auto attributes = [&](const json& a, const std::string& where) {
    expect(a.is_object(), a, where, "an object of accessor indices");
    for (const auto& [name, value] : a.items()) index(value, path(where, name), "accessors", count("accessors"));
  };
  each(m, at, "primitives", [&](const json& p, const std::string& p_at) {
    attributes(*find(p, p_at, "attributes", true), path(p_at, "attributes"));
    index_key(p, p_at, "indices", "accessors");
    index_key(p, p_at, "material", "materials");
    enum_key(p, p_at, "mode", {0, 1, 2, 3, 4, 5, 6});
    if (const json* targets = find(p, p_at, "targets")) {
      expect(targets->is_array(), *targets, path(p_at, "targets"), "an array of objects");
      for (size_t t = 0; t < targets->size(); ++t) attributes((*targets)[t], path(p_at, "targets") + "[" + std::to_string(t) + "]");
    }
  }, true);
  numbers_key(m, at, "weights", 1, SIZE_MAX);
}

void SchemaCheck::node(const json& n, const std::string& at) const {
  index_key(n, at, "camera", "cameras");
  indices_key(n, at, "children", "nodes");
  index_key(n, at, "skin", "skins");
  index_key(n, at, "mesh", "meshes");
  numbers_key(n, at, "matrix", 16, 16);
  numbers_key(n, at, "rotation", 4, 4);
  numbers_key(n, at, "scale", 3, 3);
  numbers_key(n, at, "translation", 3, 3);
  numbers_key(n, at, "weights", 1, SIZE_MAX);
  // tinygltf, as vkray, would take the matrix and ignore the others.
  if (n.contains("matrix") && (n.contains("translation") || n.contains("rotation") || n.contains("scale")))
    fail(at, "a matrix and translation, rotation or scale together: give one or the other");
  if (n.contains("extensions") && n["extensions"].contains("KHR_lights_punctual")) {
    const json& ext = n["extensions"]["KHR_lights_punctual"];
    const json* lights = doc_.contains("extensions") ? &doc_["extensions"] : nullptr;
    lights = lights && lights->contains("KHR_lights_punctual") ? &(*lights)["KHR_lights_punctual"] : nullptr;
    const size_t size = lights && lights->contains("lights") ? (*lights)["lights"].size() : 0;
    index(*find(ext, path(at, "extensions.KHR_lights_punctual"), "light", true), path(at, "extensions.KHR_lights_punctual.light"),
          "KHR_lights_punctual.lights", size);
  }
}

void SchemaCheck::sampler(const json& s, const std::string& at) const {
  enum_key(s, at, "magFilter", {9728, 9729});
  enum_key(s, at, "minFilter", {9728, 9729, 9984, 9985, 9986, 9987});
  enum_key(s, at, "wrapS", {33071, 33648, 10497});
  enum_key(s, at, "wrapT", {33071, 33648, 10497});
}

void SchemaCheck::scene(const json& s, const std::string& at) const { indices_key(s, at, "nodes", "nodes"); }

void SchemaCheck::skin(const json& s, const std::string& at) const {
  index_key(s, at, "inverseBindMatrices", "accessors");
  index_key(s, at, "skeleton", "nodes");
  indices_key(s, at, "joints", "nodes", true);
}

void SchemaCheck::texture(const json& t, const std::string& at) const {
  index_key(t, at, "sampler", "samplers");
  index_key(t, at, "source", "images");
}

void SchemaCheck::light(const json& l, const std::string& at) const {
  enum_key(l, at, "type", {"directional", "point", "spot"}, true);
  numbers_key(l, at, "color", 3, 3);
  number_key(l, at, "intensity");
  number_key(l, at, "range");
  if (const json* spot = object_key(l, at, "spot", l["type"] == "spot")) {
    common(*spot, path(at, "spot"));
    number_key(*spot, path(at, "spot"), "innerConeAngle");
    number_key(*spot, path(at, "spot"), "outerConeAngle");
  }
}

void SchemaCheck::run() const {
  // The root's arrays first, so that an index can be checked against the array it names.
  for (const char* array : {"accessors", "animations", "buffers", "bufferViews", "cameras", "images", "materials", "meshes", "nodes",
                            "samplers", "scenes", "skins", "textures"})
    if (const json* v = find(doc_, "", array)) expect(v->is_array(), *v, array, "an array of objects");
  for (const char* list : {"extensionsUsed", "extensionsRequired"})
    if (const json* v = find(doc_, "", list))
      expect(v->is_array() && std::all_of(v->begin(), v->end(), [](const json& x) { return x.is_string(); }), *v, list, "an array of names");
  common(doc_, "");
  asset(*object_key(doc_, "", "asset", true), "asset");
  index_key(doc_, "", "scene", "scenes");
  if (doc_.contains("extensions") && doc_["extensions"].contains("KHR_lights_punctual"))  // before the nodes that name them
    each(doc_["extensions"]["KHR_lights_punctual"], "extensions.KHR_lights_punctual", "lights",
         [&](const json& v, const std::string& at) { light(v, at); });
  each(doc_, "", "accessors", [&](const json& v, const std::string& at) { accessor(v, at); });
  each(doc_, "", "animations", [&](const json& v, const std::string& at) { animation(v, at); });
  each(doc_, "", "buffers", [&](const json& v, const std::string& at) { buffer(v, at); });
  each(doc_, "", "bufferViews", [&](const json& v, const std::string& at) { buffer_view(v, at); });
  each(doc_, "", "cameras", [&](const json& v, const std::string& at) { camera(v, at); });
  each(doc_, "", "images", [&](const json& v, const std::string& at) { image(v, at); });
  each(doc_, "", "materials", [&](const json& v, const std::string& at) { material(v, at); });
  each(doc_, "", "meshes", [&](const json& v, const std::string& at) { mesh(v, at); });
  each(doc_, "", "nodes", [&](const json& v, const std::string& at) { node(v, at); });
  each(doc_, "", "samplers", [&](const json& v, const std::string& at) { sampler(v, at); });
  each(doc_, "", "scenes", [&](const json& v, const std::string& at) { scene(v, at); });
  each(doc_, "", "skins", [&](const json& v, const std::string& at) { skin(v, at); });
  each(doc_, "", "textures", [&](const json& v, const std::string& at) { texture(v, at); });
}

}  // namespace

void check_gltf_schema(const nlohmann::json& doc, const std::filesystem::path& file) { SchemaCheck(doc, file).run(); }

}  // namespace vkray
