// The scene file's parser: a JSON document (base/json_document.h) to a Scene, every value checked
// and every message naming the file and the key as a JSON pointer. scene_parser.cpp reads the
// file's own sections; scene_placement.cpp places what the files it names bring (meshes, material
// libraries, textures, glTF files). Used inside load/ alone: scene_loader.cpp is its caller.
#pragma once

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/errors.h"
#include "base/json_document.h"
#include "gltf/gltf.h"
#include "load/mesh_cache.h"
#include "mesh/mesh.h"
#include "mesh/mtl.h"
#include "scene/scene.h"

namespace vkray::scene_file {

using json = nlohmann::json;

// A JSON value together with its JSON-pointer path, so every message can say where it is.
struct Value {
  const json& j;
  std::string path;  // "" is the document root

  Value operator[](const std::string& key) const { return {j.at(key), path + "/" + printable(key)}; }
  Value operator[](size_t i) const { return {j.at(i), path + "/" + std::to_string(i)}; }
  bool has(const std::string& key) const { return j.contains(key); }
};

class SceneParser {
 public:
  SceneParser(const std::filesystem::path& file, Scene& scene, MeshCache& meshes) : file_(file), scene_(scene), meshes_(meshes) {}

  void parse(const json& root);
  // An environment map that replaces the file's environment and background (load_scene's
  // `environment`): the file's own map is then not read.
  void replace_environment_with(const std::filesystem::path& map) { environment_override_ = map; }
  // Adds a glTF file's triangles, materials, textures and point lights, placed by `transform`, as the
  // object being parsed. `where` is the scene's key that names the file; null when the glTF file is
  // the scene itself (its messages then name it alone). Returns its camera and aspect ratio.
  std::pair<std::optional<Camera>, float> add_gltf(const Value* where, const std::filesystem::path& file, const glm::mat4& transform);

 private:
  [[noreturn]] void fail(const Value& v, const std::string& what) const {
    throw SceneError(file_.string() + ": " + (v.path.empty() ? "top level" : v.path) + ": " + what);
  }
  // Each warning once: an object placed many times ("instances") would say the same for each placement.
  void warn(const Value& v, const std::string& what) {
    std::string message = printable_middle(file_.string() + ": " + (v.path.empty() ? "top level" : v.path) + ": " + what, 500);
    if (warned_.insert(message).second) scene_.warnings.push_back(std::move(message));
  }

  // ---- typed readers -----------------------------------------------------------------------------
  void expect_object(const Value& v) const {
    if (!v.j.is_object()) fail(v, std::string("expected an object, got ") + v.j.type_name());
  }
  void expect_array(const Value& v) const {
    if (!v.j.is_array()) fail(v, std::string("expected an array, got ") + v.j.type_name());
  }
  Value require(const Value& obj, const std::string& key) const {
    if (!obj.has(key)) fail(obj, "missing required key \"" + key + "\"");
    return obj[key];
  }
  // Warns about keys the contract does not define (most often a typo).
  void check_keys(const Value& obj, std::initializer_list<const char*> known, std::initializer_list<const char*> also_known = {}) {
    for (const auto& item : obj.j.items()) {
      const std::string& key = item.key();
      const auto is_key = [&](const char* k) { return key == k; };
      if (std::none_of(known.begin(), known.end(), is_key) && std::none_of(also_known.begin(), also_known.end(), is_key))
        warn(obj[key], "unknown key (ignored)");
    }
  }
  // Exactly one of two alternative keys; returns true when the first is present.
  bool one_of(const Value& obj, const char* a, const char* b) const {
    const bool has_a = obj.has(a), has_b = obj.has(b);
    if (has_a && has_b) fail(obj, std::string("give either \"") + a + "\" or \"" + b + "\", not both");
    if (!has_a && !has_b) fail(obj, std::string("missing required key \"") + a + "\" (or \"" + b + "\")");
    return has_a;
  }

  float number(const Value& v) const {
    if (!v.j.is_number()) fail(v, std::string("expected a number, got ") + v.j.type_name());
    const double d = v.j.get<double>();
    if (!std::isfinite(d) || std::abs(d) > FLT_MAX) fail(v, "number is out of range for a 32-bit float");
    return static_cast<float>(d);
  }
  float positive(const Value& v) const {
    const float f = number(v);
    if (!(f > 0.0f)) fail(v, "expected a number > 0, got " + brief(v.j));
    return f;
  }
  uint32_t count(const Value& v, uint32_t max) const {
    if (!v.j.is_number_integer() || v.j.get<int64_t>() < 1 || v.j.get<int64_t>() > max)
      fail(v, "expected an integer from 1 to " + std::to_string(max) + ", got " + brief(v.j));
    return static_cast<uint32_t>(v.j.get<int64_t>());
  }
  glm::vec3 three_numbers(const Value& v) const {
    if (!v.j.is_array() || v.j.size() != 3) fail(v, "expected an array of 3 numbers, got " + brief(v.j));
    return {number(v[0]), number(v[1]), number(v[2])};
  }
  glm::vec3 color(const Value& v) const {  // non-negative RGB
    const glm::vec3 c = three_numbers(v);
    if (c.r < 0.0f || c.g < 0.0f || c.b < 0.0f) fail(v, "expected non-negative values, got " + brief(v.j));
    return c;
  }
  std::string string(const Value& v) const {
    if (!v.j.is_string()) fail(v, std::string("expected a string, got ") + v.j.type_name());
    return v.j.get<std::string>();
  }

  // ---- sections ----------------------------------------------------------------------------------
  void parse_image(const Value& v);
  void parse_camera(const Value& v);
  void parse_environment(const Value& v);
  std::filesystem::path environment_override_;
  void parse_integrator(const Value& v);
  void parse_materials(const Value& v);
  glm::vec3 reflectance(const Value& v);  // a colour in [0, 1] (above 1: refused for paths, a warning otherwise)
  float index_of_refraction(const Value& v) const;
  glm::vec3 bounded_color(const Value& v, float max, const char* expected) const;  // each channel in [0, max]
  glm::vec2 roughness(const Value& material) const;
  float unit_interval(const Value& v) const;  // a number in [0, 1]
  static std::string material_type_list();  // "\"diffuse\", \"mirror\", ... or \"...\""
  // Fails unless the JSON value is an integer from `min` to `max`.
  int64_t integer(const Value& v, int64_t min, int64_t max) const;
  // "flip_normals": true turns an object's normals around (for emission and glass).
  bool flip_normals(const Value& v) const;
  void parse_light(const Value& v);
  void parse_object(const Value& v);
  // Where an object goes: its "transform", or once for each of its "instances" (each instance's
  // transform, then the object's).
  std::vector<glm::mat4> placements(const Value& v, const glm::mat4& transform);
  glm::mat4 parse_transform(const Value& v);
  uint32_t material_ref(const Value& v) const;
  // A mesh object's triangles, placed by `transform`.
  std::vector<Triangle> mesh_triangles(const Value& v, const glm::mat4& transform);
  // Stores `triangles` once as a mesh (Scene::meshes) and places it by each of `placements`
  // (Scene::instances, of the current object). `where`: the "instances" array, whose elements are the
  // placements when `each_named` (an error then names the one at fault), else what they come from.
  void add_instances(const Value& where, std::vector<Triangle>& triangles, const std::vector<glm::mat4>& placements,
                     bool each_named = true);
  // Adds a texture to Scene::textures, counting its texels in scene_texels_.
  void add_texture(std::shared_ptr<const Texture> texture) {
    scene_texels_ += uint64_t(texture->width) * texture->height;
    scene_.textures.push_back(std::move(texture));
  }
  // Adds a file the scene reads to Scene::referenced_files, once.
  void reference(const std::filesystem::path& file);
  // The index in Scene::textures of a texture file, read the first time it is named.
  // A material's alpha keys (any type): alpha_mode, opacity, opacity_texture, alpha_cutoff.
  void parse_alpha(const Value& m, Material& material);
  int32_t texture_file(const Value& where, const std::filesystem::path& file, TextureUse use);
  // A file a string of the scene file names, relative to the scene file's folder.
  std::filesystem::path file_of(const Value& name) const;
  // The scene materials made from the .mtl materials a mesh's faces name, in Mesh::material_names order.
  std::vector<uint32_t> mesh_materials(const Value& where, const std::filesystem::path& mesh_file, const Mesh& mesh);
  // Appends triangles, leaving out zero-area ones (they have no normal and are never hit).
  void add_triangles(const Value& where, std::vector<Triangle>& triangles);
  // Fails at `where` unless every coordinate of `p` lies within +-kMaxCoordinate (and so is finite).
  void check_coordinates(const Value& where, const glm::vec3& p, const char* what) const;
  // Fails at `where` when `adding` more primitives would pass kMaxScenePrimitives.
  void check_primitive_count(const Value& where, size_t adding) const;

  const std::filesystem::path& file_;
  Scene& scene_;
  std::map<std::string, uint32_t> material_index_;
  MeshCache& meshes_;  // each file loaded once, however often it is used
  std::set<std::filesystem::path> referenced_;  // the files in scene_.referenced_files
  std::set<std::string> warned_;                 // the warnings in scene_.warnings said by this parser
  std::map<std::pair<std::filesystem::path, TextureUse>, int32_t> texture_files_;  // (file, use) -> Scene::textures
  struct LoadedGltf {
    GltfScene gltf;
    uint32_t material_offset = 0;  // where its materials start in Scene::materials
  };
  // A glTF file, read the first time it is named: its materials and textures then added to the scene.
  LoadedGltf& gltf_file(const Value* where, const std::filesystem::path& file);
  // The meshes a glTF file places by instances, each placed by each of its instances after each of
  // `placements`.
  void add_gltf_meshes(const Value& where, const LoadedGltf& loaded, const std::vector<glm::mat4>& placements);
  // A glTF file's lights, placed by `transform`.
  void add_gltf_lights(const Value& where, const GltfScene& gltf, const glm::mat4& transform);
  // A glTF file placed by each of `placements`: its triangles stored once, as a mesh.
  // `file_value`: the object's "file"; `where`: its "instances".
  void add_gltf_instances(const Value& file_value, const Value& where, const std::filesystem::path& file,
                          const std::vector<glm::mat4>& placements);
  std::map<std::filesystem::path, LoadedGltf> gltf_files_;
  struct MeshFileMaterials {
    std::shared_ptr<const Mesh> mesh;  // the mesh they were made for
    std::vector<uint32_t> named;  // Mesh::material_names -> Scene::materials
    uint32_t unnamed = 0;         // the material of faces before the first usemtl
  };
  std::map<std::filesystem::path, MeshFileMaterials> mesh_file_materials_;  // made once for each mesh file
  std::map<std::filesystem::path, MtlLibrary> mtl_files_;  // each material library read once
  uint64_t scene_texels_ = 0;  // the texels of Scene::textures
  uint32_t object_ = 0;  // the index in "objects" of the object being parsed
};

}  // namespace vkray::scene_file
