#include "scene/scene.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include <glm/gtc/constants.hpp>

#include "base/errors.h"
#include "base/input_file.h"
#include "base/interrupt.h"
#include "gltf/gltf.h"
#include "mesh/load.h"
#include "mesh/mesh.h"
#include "mesh/mtl.h"
#include "mesh/normals.h"
#include "scene/json_document.h"
#include "scene/transform.h"

namespace vkray {
namespace {

using json = nlohmann::json;

// The longest focal length, in image heights (a field of view of 5.7e-5 degrees). The camera ray's
// direction (F * H, x, y) is normalized: F * H (at most 1.6e10) squared stays far inside a float.
constexpr float kMaxFocalLength = 1e6f;

// The largest index of refraction: past every real material (diamond is 2.4), so that a typo shows.
constexpr float kMaxIor = 100.0f;

// Moves each textured triangle's texture coordinates by a whole number of periods toward [0, 2)
// along each axis its textures repeat (an even number, so that a mirrored repeat reads the same):
// exact in float, and the texture reads the same, but both renderers then interpolate small
// numbers, so that a floor tiled 5000 times is not sampled half a texel apart by float and double.
void recentre_texture_coordinates(Scene& scene) {
  for (Triangle& t : scene.triangles) {
    const Material& m = scene.materials[t.material];
    if (!m.textured()) continue;
    const auto repeats = [&](bool s) {
      for (const TextureRef* ref : {&m.albedo_texture, &m.emission_texture})
        if (ref->present() && (s ? ref->wrap_s : ref->wrap_t) == TextureWrap::clamp_to_edge) return false;
      return true;
    };
    for (int axis = 0; axis < 2; ++axis) {
      if (!repeats(axis == 0)) continue;
      const float lowest = std::min({t.uv[0][axis], t.uv[1][axis], t.uv[2][axis]});
      const float shift = 2.0f * std::floor(lowest / 2.0f);
      for (glm::vec2& uv : t.uv) uv[axis] -= shift;
    }
  }
}


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
  // Adds a glTF file's triangles, materials, textures and point lights, placed by `transform`, as the
  // object being parsed. `where` is the scene's key that names the file; null when the glTF file is
  // the scene itself (its messages then name it alone). Returns its camera and aspect ratio.
  std::pair<std::optional<Camera>, float> add_gltf(const Value* where, const std::filesystem::path& file, const glm::mat4& transform);

 private:
  [[noreturn]] void fail(const Value& v, const std::string& what) const {
    throw SceneError(file_.string() + ": " + (v.path.empty() ? "top level" : v.path) + ": " + what);
  }
  void warn(const Value& v, const std::string& what) {
    scene_.warnings.push_back(printable(file_.string() + ": " + (v.path.empty() ? "top level" : v.path) + ": " + what, 500));
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
  void check_keys(const Value& obj, std::initializer_list<const char*> known) {
    for (const auto& item : obj.j.items()) {
      const std::string& key = item.key();
      if (std::none_of(known.begin(), known.end(), [&](const char* k) { return key == k; }))
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
  glm::vec3 vec3(const Value& v) const {
    if (!v.j.is_array() || v.j.size() != 3) fail(v, "expected an array of 3 numbers, got " + brief(v.j));
    return {number(v[0]), number(v[1]), number(v[2])};
  }
  glm::vec3 color(const Value& v) const {  // non-negative RGB
    const glm::vec3 c = vec3(v);
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
  void parse_integrator(const Value& v);
  void parse_materials(const Value& v);
  // Fails unless the JSON value is an integer from `min` to `max`.
  int64_t integer(const Value& v, int64_t min, int64_t max) const;
  // "flip_normals": true turns an object's normals around (for emission and glass).
  bool flip_normals(const Value& v) const;
  void parse_light(const Value& v);
  void parse_object(const Value& v);
  glm::mat4 parse_transform(const Value& v);
  uint32_t material_ref(const Value& v) const;
  void parse_mesh(const Value& v, const glm::mat4& transform);
  // The texels of the scene's textures so far.
  uint64_t scene_texels() const {
    uint64_t texels = 0;
    for (const auto& t : scene_.textures) texels += uint64_t(t->width) * t->height;
    return texels;
  }
  // Adds a file the scene reads to Scene::referenced_files, once.
  void reference(const std::filesystem::path& file);
  // The index in Scene::textures of a texture file, read the first time it is named.
  int32_t texture_file(const Value& where, const std::filesystem::path& file, bool srgb);
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
  std::map<std::pair<std::filesystem::path, bool>, int32_t> texture_files_;  // (file, sRGB) -> Scene::textures
  struct LoadedGltf {
    GltfScene gltf;
    uint32_t material_offset = 0;  // where its materials start in Scene::materials
  };
  std::map<std::filesystem::path, LoadedGltf> gltf_files_;
  uint32_t object_ = 0;  // the index in "objects" of the object being parsed
};

void SceneParser::parse(const json& root_json) {
  const Value root{root_json, ""};
  expect_object(root);
  check_keys(root, {"description", "image", "camera", "integrator", "seed", "background", "ambient", "materials", "lights",
                    "objects"});
  if (root.has("description")) scene_.description = printable(string(root["description"]), 1000);
  if (root.has("image")) parse_image(root["image"]);
  if (root.has("seed")) scene_.image.seed = static_cast<uint32_t>(integer(root["seed"], 0, UINT32_MAX));
  parse_camera(require(root, "camera"));
  if (root.has("integrator")) parse_integrator(root["integrator"]);
  if (root.has("background")) scene_.background = color(root["background"]);
  if (root.has("ambient")) scene_.ambient = color(root["ambient"]);
  if (root.has("materials")) parse_materials(root["materials"]);
  if (root.has("lights")) {
    const Value lights = root["lights"];
    expect_array(lights);
    for (size_t i = 0; i < lights.j.size(); ++i) parse_light(lights[i]);
  }
  if (root.has("objects")) {
    const Value objects = root["objects"];
    expect_array(objects);
    for (size_t i = 0; i < objects.j.size(); ++i) {
      object_ = static_cast<uint32_t>(i);
      parse_object(objects[i]);
    }
  }
  const bool path = scene_.integrator.type == Integrator::Type::path;
  if (path && scene_.ambient != glm::vec3(0.0f))
    warn(root["ambient"], "the path integrator carries indirect light itself: ambient is the direct model's stand-in for it, "
                          "and is ignored");
  const bool emitters = std::any_of(scene_.materials.begin(), scene_.materials.end(), [](const Material& m) { return m.emissive(); });
  const bool lit = !scene_.lights.empty() || emitters || (path ? scene_.background : scene_.ambient) != glm::vec3(0.0f);
  if (!lit && !scene_.triangles.empty())
    warn(root, path ? "no lights, no emission and no background: every surface renders black"
                    : "no lights, no emission and no ambient: every surface renders black");
}

void SceneParser::parse_image(const Value& v) {
  expect_object(v);
  check_keys(v, {"width", "height", "samples_per_pixel"});
  if (v.has("width")) scene_.image.width = count(v["width"], kMaxImageSide);
  if (v.has("height")) scene_.image.height = count(v["height"], kMaxImageSide);
  if (v.has("samples_per_pixel"))
    scene_.image.samples_per_pixel = count(v["samples_per_pixel"], kMaxSamplesPerPixel);
}

void SceneParser::parse_camera(const Value& v) {
  expect_object(v);
  check_keys(v, {"position", "look_at", "direction", "up", "vertical_fov", "focal_length", "aperture_radius", "focus_distance"});
  Camera& cam = scene_.camera;
  cam.position = vec3(require(v, "position"));
  check_coordinates(v["position"], cam.position, "the camera");

  // A direction is judged in double, where any finite float vector has a finite, non-zero length
  // unless it is zero (in float, the square of 1e20 overflows and that of 1e-30 vanishes). Its
  // value stays the float computation wherever that is finite, as it always was.
  const auto unit = [](glm::vec3 d) {
    const float length = glm::length(d);
    return length > 0.0f && std::isfinite(length) ? d / length : glm::vec3(glm::normalize(glm::dvec3(d)));
  };
  const bool by_target = one_of(v, "look_at", "direction");
  const Value aim = by_target ? v["look_at"] : v["direction"];
  if (by_target) check_coordinates(aim, vec3(aim), "look_at");
  const glm::vec3 forward = by_target ? vec3(aim) - cam.position : vec3(aim);
  if (!(glm::length(glm::dvec3(forward)) > 0.0))
    fail(aim, by_target ? "look_at equals the camera position: no view direction" : "direction has zero length");
  cam.forward = unit(forward);

  if (v.has("up")) {
    const glm::vec3 up = vec3(v["up"]);
    if (!(glm::length(glm::dvec3(up)) > 0.0)) fail(v["up"], "up has zero length");
    // A float length that overflows or vanishes is normalized away; the renderers only need the
    // direction (scene/camera.h).
    cam.up = std::isfinite(glm::length(up)) && glm::length(up) > 0.0f ? up : unit(up);
    // Relative test: |f x up/|up|| = sin of the angle between them.
    if (glm::length(glm::cross(cam.forward, unit(cam.up))) < 1e-6f) fail(v["up"], "up is parallel to the view direction");
  } else if (glm::length(glm::cross(cam.forward, cam.up)) < 1e-6f) {
    fail(v, "the default up [0,1,0] is parallel to the view direction; give \"up\"");
  }

  if (one_of(v, "vertical_fov", "focal_length")) {
    const float fov = number(v["vertical_fov"]);
    if (!(fov > 0.0f && fov < 180.0f)) fail(v["vertical_fov"], "expected degrees in (0, 180), got " + brief(v["vertical_fov"].j));
    // F = (H/2) / tan(fov/2) pixels = focal_length * H.
    cam.focal_length = 0.5f / std::tan(glm::radians(fov) * 0.5f);
    if (!(cam.focal_length <= kMaxFocalLength))
      fail(v["vertical_fov"], "a field of view this narrow has a focal length past 1e6 image heights; "
                              "the smallest vkray renders is 6e-5 degrees");
  } else {
    cam.focal_length = positive(v["focal_length"]);
    if (!(cam.focal_length <= kMaxFocalLength))
      fail(v["focal_length"], "expected at most 1e6 (image heights), got " + brief(v["focal_length"].j));
  }

  // The thin lens. The focus distance defaults to the target's, when the camera has one.
  if (v.has("aperture_radius")) {
    cam.aperture_radius = number(v["aperture_radius"]);
    if (!(cam.aperture_radius >= 0.0f && cam.aperture_radius <= kMaxCoordinate))
      fail(v["aperture_radius"], "expected a radius from 0 to 1e9, got " + brief(v["aperture_radius"].j));
  }
  if (v.has("focus_distance")) {
    cam.focus_distance = positive(v["focus_distance"]);
    if (!(cam.focus_distance <= 2.0f * kMaxCoordinate))
      fail(v["focus_distance"], "expected a distance up to 2e9, got " + brief(v["focus_distance"].j));
  } else if (cam.aperture_radius > 0.0f) {
    if (!by_target) fail(v, "a camera with an aperture_radius needs a \"focus_distance\" (or a \"look_at\" to focus on)");
    cam.focus_distance = glm::length(vec3(aim) - cam.position);
  }
  if (v.has("focus_distance") && cam.aperture_radius == 0.0f)
    warn(v["focus_distance"], "a pinhole camera (aperture_radius 0) is sharp everywhere: focus_distance has no effect");
}

void SceneParser::parse_integrator(const Value& v) {
  expect_object(v);
  const std::string type = string(require(v, "type"));
  Integrator& integrator = scene_.integrator;
  if (type == "direct") {
    check_keys(v, {"type"});
    integrator.type = Integrator::Type::direct;
  } else if (type == "path") {
    check_keys(v, {"type", "max_depth", "rr_depth"});
    integrator.type = Integrator::Type::path;
    if (v.has("max_depth")) {
      integrator.max_depth = static_cast<int32_t>(integer(v["max_depth"], -1, kMaxPathDepth));
      if (integrator.max_depth == 0) fail(v["max_depth"], "max_depth 0 renders nothing: give -1 (no limit) or at least 1");
    }
    if (v.has("rr_depth")) integrator.rr_depth = static_cast<uint32_t>(integer(v["rr_depth"], 1, kMaxPathDepth));
  } else {
    fail(v["type"], "unknown integrator \"" + printable(type) + "\" (expected \"direct\" or \"path\")");
  }
}

int64_t SceneParser::integer(const Value& v, int64_t min, int64_t max) const {
  // JSON reads a non-negative integer as unsigned, which may pass int64_t's range.
  const bool in_range = v.j.is_number_unsigned() ? v.j.get<uint64_t>() <= uint64_t(max) && int64_t(v.j.get<uint64_t>()) >= min
                        : v.j.is_number_integer() ? v.j.get<int64_t>() >= min && v.j.get<int64_t>() <= max
                                                  : false;
  if (!in_range) fail(v, "expected an integer from " + std::to_string(min) + " to " + std::to_string(max) + ", got " + brief(v.j));
  return v.j.is_number_unsigned() ? int64_t(v.j.get<uint64_t>()) : v.j.get<int64_t>();
}

bool SceneParser::flip_normals(const Value& v) const {
  if (!v.has("flip_normals")) return false;
  if (!v["flip_normals"].j.is_boolean()) fail(v["flip_normals"], std::string("expected true or false, got ") + v["flip_normals"].j.type_name());
  return v["flip_normals"].j.get<bool>();
}

void SceneParser::parse_materials(const Value& v) {
  expect_object(v);
  for (const auto& [name, unused] : v.j.items()) {
    const Value m = v[name];
    expect_object(m);
    Material material;
    material.name = name;
    const std::string type = m.has("type") ? string(m["type"]) : "diffuse";
    // A colour in [0, 1]: more would reflect more light than arrives.
    const auto reflectance = [&](const Value& c) {
      const glm::vec3 rgb = color(c);
      if (rgb.r > 1.0f || rgb.g > 1.0f || rgb.b > 1.0f) warn(c, "a value above 1 reflects more light than arrives");
      return rgb;
    };
    if (type == "diffuse") {
      check_keys(m, {"type", "albedo", "emission"});
      material.albedo = reflectance(require(m, "albedo"));
    } else if (type == "mirror") {
      check_keys(m, {"type", "reflectance", "emission"});
      material.type = MaterialType::mirror;
      material.albedo = reflectance(require(m, "reflectance"));
    } else if (type == "glass") {
      check_keys(m, {"type", "ior", "emission"});
      material.type = MaterialType::glass;
      if (m.has("ior")) {
        material.ior = positive(m["ior"]);
        if (!(material.ior <= kMaxIor)) fail(m["ior"], "expected an index of refraction up to 100, got " + brief(m["ior"].j));
      }
    } else {
      fail(m["type"], "unknown material type \"" + printable(type) + "\" (expected \"diffuse\", \"mirror\" or \"glass\")");
    }
    if (m.has("emission")) material.emission = color(m["emission"]);
    material_index_[name] = static_cast<uint32_t>(scene_.materials.size());
    scene_.materials.push_back(material);
  }
}

uint32_t SceneParser::material_ref(const Value& v) const {
  const std::string name = string(v);
  const auto it = material_index_.find(name);
  if (it == material_index_.end()) fail(v, "undefined material \"" + printable(name) + "\"");
  return it->second;
}

void SceneParser::parse_light(const Value& v) {
  expect_object(v);
  check_keys(v, {"type", "position", "intensity", "power"});
  const Value type = require(v, "type");
  if (string(type) != "point") fail(type, "unknown light type " + brief(type.j) + " (expected \"point\")");
  PointLight light;
  light.position = vec3(require(v, "position"));
  check_coordinates(v["position"], light.position, "the light");
  if (one_of(v, "intensity", "power")) {
    light.intensity = color(v["intensity"]);
  } else {
    light.intensity = color(v["power"]) / (4.0f * glm::pi<float>());  // isotropic: I = P / 4pi
  }
  scene_.lights.push_back(light);
}

glm::mat4 SceneParser::parse_transform(const Value& v) {
  expect_object(v);
  check_keys(v, {"translate", "rotate", "scale", "matrix"});
  if (v.has("matrix")) {
    if (v.has("translate") || v.has("rotate") || v.has("scale"))
      fail(v, "give either \"matrix\" or translate/rotate/scale, not both");
    const Value m = v["matrix"];
    if (!m.j.is_array() || m.j.size() != 16) fail(m, "expected an array of 16 numbers (row-major 4x4)");
    float values[16];
    for (size_t i = 0; i < 16; ++i) values[i] = number(m[i]);
    if (values[12] != 0.0f || values[13] != 0.0f || values[14] != 0.0f || values[15] != 1.0f)
      fail(m, "the last row must be [0, 0, 0, 1] (an affine transform)");
    const glm::mat4 matrix = matrix_from_row_major(values);
    if (glm::determinant(glm::mat3(matrix)) == 0.0f) fail(m, "the matrix is singular");
    return matrix;
  }
  glm::vec3 translate(0.0f), rotate(0.0f), scale(1.0f);
  if (v.has("translate")) translate = vec3(v["translate"]);
  if (v.has("rotate")) rotate = vec3(v["rotate"]);
  if (v.has("scale")) {
    const Value s = v["scale"];
    scale = s.j.is_number() ? glm::vec3(number(s)) : vec3(s);
    if (scale.x == 0.0f || scale.y == 0.0f || scale.z == 0.0f) fail(s, "scale must be non-zero");
  }
  return compose_transform(translate, rotate, scale);
}

void SceneParser::parse_object(const Value& v) {
  throw_if_interrupted();
  expect_object(v);
  const Value type_value = require(v, "type");
  const std::string type = string(type_value);
  const glm::mat4 transform = v.has("transform") ? parse_transform(v["transform"]) : glm::mat4(1.0f);

  if (type == "sphere") {
    check_keys(v, {"type", "center", "radius", "material", "transform", "flip_normals"});
    Sphere sphere;
    sphere.inward = flip_normals(v);
    sphere.center = vec3(require(v, "center"));
    sphere.radius = positive(require(v, "radius"));
    sphere.material = material_ref(require(v, "material"));
    sphere.object = object_;
    if (v.has("transform")) {
      const auto s = uniform_scale_of(transform);
      if (!s) fail(v["transform"], "a sphere takes only a uniform scale (with rotation and translation)");
      sphere.center = transform_point(transform, sphere.center);
      sphere.radius *= *s;
    }
    if (!(sphere.radius > 0.0f)) fail(v, "the transform scales the sphere's radius to zero");
    check_coordinates(v, glm::abs(sphere.center) + sphere.radius, "the sphere's bounding box");
    check_primitive_count(v, 1);
    scene_.spheres.push_back(sphere);
  } else if (type == "triangles") {
    check_keys(v, {"type", "positions", "indices", "material", "transform", "flip_normals"});
    const Value positions = require(v, "positions");
    expect_array(positions);
    std::vector<glm::vec3> points;
    points.reserve(positions.j.size());
    for (size_t i = 0; i < positions.j.size(); ++i) points.push_back(transform_point(transform, vec3(positions[i])));
    const uint32_t material = material_ref(require(v, "material"));
    const bool flip = flip_normals(v);
    const Value indices = require(v, "indices");
    expect_array(indices);
    std::vector<Triangle> triangles;
    triangles.reserve(indices.j.size());
    for (size_t i = 0; i < indices.j.size(); ++i) {
      const Value tri = indices[i];
      if (!tri.j.is_array() || tri.j.size() != 3) fail(tri, "expected an array of 3 vertex indices, got " + brief(tri.j));
      Triangle t;
      t.material = material;
      t.object = object_;
      for (size_t k = 0; k < 3; ++k) {
        const Value idx = tri[k];
        if (!idx.j.is_number_integer() || idx.j.get<int64_t>() < 0 ||
            idx.j.get<int64_t>() >= static_cast<int64_t>(points.size()))
          fail(idx, "vertex index " + brief(idx.j) + " is out of range (the object has " +
                        std::to_string(points.size()) + " positions)");
        t.v[k] = points[idx.j.get<size_t>()];
      }
      if (flip) std::swap(t.v[1], t.v[2]);  // the other winding: the normal turned around
      triangles.push_back(t);
    }
    add_triangles(indices, triangles);
  } else if (type == "mesh") {
    check_keys(v, {"type", "file", "material", "transform", "smooth", "flip_normals"});
    parse_mesh(v, transform);
  } else if (type == "gltf") {
    check_keys(v, {"type", "file", "transform"});
    const Value file_value = require(v, "file");
    add_gltf(&file_value, (file_.parent_path() / string(file_value)).lexically_normal(), transform);
  } else {
    fail(type_value, "unknown object type \"" + printable(type) + "\" (expected \"sphere\", \"triangles\", \"mesh\" or \"gltf\")");
  }
}

std::pair<std::optional<Camera>, float> SceneParser::add_gltf(const Value* where, const std::filesystem::path& file,
                                                              const glm::mat4& transform) {
  // A file placed several times is read once: its materials and textures are the scene's once, and
  // its warnings said once.
  auto loaded = gltf_files_.find(file);
  if (loaded == gltf_files_.end()) {
    LoadedGltf entry;
    GltfLimits limits;
    limits.max_texels = kMaxSceneTexels - std::min(kMaxSceneTexels, scene_texels());
    try {
      entry.gltf = load_gltf(file, limits);
    } catch (const LimitError& e) {
      if (!where) throw;
      throw LimitError(file_.string() + ": " + where->path + ": " + e.what());
    } catch (const SceneError& e) {
      if (!where) throw;
      throw SceneError(file_.string() + ": " + where->path + ": " + e.what());
    }
    reference(file);
    for (const auto& f : entry.gltf.files) reference(f);
    for (const std::string& w : entry.gltf.warnings) {
      if (where) warn(*where, w);
      else scene_.warnings.push_back(w);
    }
    entry.material_offset = uint32_t(scene_.materials.size());
    const auto texture_offset = int32_t(scene_.textures.size());
    for (Material m : entry.gltf.materials) {
      for (TextureRef* ref : {&m.albedo_texture, &m.emission_texture})
        if (ref->present()) ref->texture += texture_offset;
      scene_.materials.push_back(std::move(m));
    }
    for (const auto& t : entry.gltf.textures) scene_.textures.push_back(t);
    loaded = gltf_files_.emplace(file, std::move(entry)).first;
  }
  const GltfScene& gltf = loaded->second.gltf;
  const uint32_t material_offset = loaded->second.material_offset;
  static const json kNothing;
  const Value root{kNothing, ""};  // where messages point when the file is the scene itself
  const Value& at = where ? *where : root;
  // The object's transform on top of the file's own: normals by the inverse transpose, and the
  // winding turned around where it mirrors.
  const glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(transform)));
  const bool mirrors = glm::determinant(glm::mat3(transform)) < 0.0f;
  const bool moved = transform != glm::mat4(1.0f);
  std::vector<Triangle> placed = gltf.triangles;
  for (Triangle& t : placed) {
    t.material += material_offset;
    t.object = object_;
    if (!moved) continue;
    for (size_t k = 0; k < 3; ++k) {
      t.v[k] = transform_point(transform, t.v[k]);
      if (t.smooth) t.normals[k] = glm::normalize(normal_matrix * t.normals[k]);
    }
    if (t.smooth && !std::all_of(t.normals.begin(), t.normals.end(), [](const glm::vec3& n) { return std::isfinite(n.x) && glm::length(n) > 0.5f; }))
      t.smooth = false;
    if (mirrors) {
      std::swap(t.v[1], t.v[2]);
      std::swap(t.normals[1], t.normals[2]);
      std::swap(t.uv[1], t.uv[2]);
    }
  }
  add_triangles(at, placed);
  for (PointLight light : gltf.lights) {
    light.position = transform_point(transform, light.position);
    check_coordinates(at, light.position, "a light of the glTF file");
    scene_.lights.push_back(light);
  }
  std::optional<Camera> camera = gltf.camera;
  if (camera && moved) {
    camera->position = transform_point(transform, camera->position);
    camera->forward = glm::normalize(glm::mat3(transform) * camera->forward);
    camera->up = glm::normalize(glm::mat3(transform) * camera->up);
  }
  return {camera, gltf.aspect_ratio};
}

void SceneParser::check_coordinates(const Value& where, const glm::vec3& p, const char* what) const {
  for (int c = 0; c < 3; ++c)
    if (!(std::abs(p[c]) <= kMaxCoordinate)) {
      char value[32];
      std::snprintf(value, sizeof value, "%g", double(p[c]));
      fail(where, std::string(what) + " has a coordinate of " + value +
                      "; vkray renders world-space coordinates within +-1e9 (README, \"Limits\")");
    }
}

void SceneParser::check_primitive_count(const Value& where, size_t adding) const {
  const size_t count = scene_.triangles.size() + scene_.spheres.size();
  if (adding > kMaxScenePrimitives - count)
    throw LimitError(file_.string() + ": " + where.path + ": the scene would have " + std::to_string(count + adding) +
                     " primitives; vkray renders at most " + std::to_string(kMaxScenePrimitives));
}

void SceneParser::add_triangles(const Value& where, std::vector<Triangle>& triangles) {
  const auto within_limit = [](const glm::vec3& p) { return glm::all(glm::lessThanEqual(glm::abs(p), glm::vec3(kMaxCoordinate))); };
  std::vector<bool> degenerate(triangles.size());
  size_t left_out = 0;
  for (size_t i = 0; i < triangles.size(); ++i) {
    if (i % 4096 == 0) throw_if_interrupted();  // a mesh of millions takes a while to place
    const Triangle& t = triangles[i];
    for (const glm::vec3& p : t.v)  // the message is made only for a triangle that fails
      if (!within_limit(p)) check_coordinates(where, p, ("triangle " + std::to_string(i) + " (after the transform)").c_str());
    degenerate[i] = glm::length(glm::cross(t.v[1] - t.v[0], t.v[2] - t.v[0])) == 0.0f;
    left_out += degenerate[i];
  }
  check_primitive_count(where, triangles.size() - left_out);
  const size_t needed = scene_.triangles.size() + triangles.size() - left_out;  // grown geometrically, as push_back would
  if (needed > scene_.triangles.capacity()) scene_.triangles.reserve(std::max(needed, 2 * scene_.triangles.capacity()));
  for (size_t i = 0; i < triangles.size(); ++i)
    if (!degenerate[i]) scene_.triangles.push_back(triangles[i]);
  if (left_out > 0) warn(where, std::to_string(left_out) + " degenerate (zero-area) triangles left out");
}

void SceneParser::reference(const std::filesystem::path& file) {
  if (referenced_.insert(file).second) scene_.referenced_files.push_back(file);
}

int32_t SceneParser::texture_file(const Value& where, const std::filesystem::path& file, bool srgb) {
  const auto key = std::make_pair(file, srgb);
  if (const auto found = texture_files_.find(key); found != texture_files_.end()) return found->second;
  reference(file);
  std::shared_ptr<const Texture> texture;
  try {
    texture = std::make_shared<const Texture>(load_texture(file, srgb));
  } catch (const LimitError& e) {
    throw LimitError(file_.string() + ": " + where.path + ": " + e.what());
  } catch (const SceneError& e) {
    throw SceneError(file_.string() + ": " + where.path + ": " + e.what());
  }
  const uint64_t texels = uint64_t(texture->width) * texture->height;
  if (texels > kMaxSceneTexels - std::min(kMaxSceneTexels, scene_texels()))
    throw LimitError(file_.string() + ": " + where.path + ": " + file.string() + ": it brings the scene's textures past " +
                     std::to_string(kMaxSceneTexels >> 20) + "M texels, vkray's limit (README, \"Limits\")");
  const auto index = int32_t(scene_.textures.size());
  scene_.textures.push_back(std::move(texture));
  texture_files_[key] = index;
  return index;
}

std::vector<uint32_t> SceneParser::mesh_materials(const Value& where, const std::filesystem::path& mesh_file, const Mesh& mesh) {
  // Every library the file names, read now; a later definition of a name replaces an earlier one.
  std::map<std::string, std::pair<MtlMaterial, std::filesystem::path>> defined;
  for (const std::string& library : mesh.material_libraries) {
    const std::filesystem::path file = (mesh_file.parent_path() / library).lexically_normal();
    reference(file);
    const InputFile input = read_input_file(file, kMaxSceneFileBytes);
    if (!input.error.empty())
      throw MeshError(file_.string() + ": " + where.path + ": " + mesh_file.filename().string() + ": mtllib " + printable(library) +
                      ": " + (input.error == "not found" ? "material library not found" : input.error));
    MtlLibrary parsed;
    try {
      parsed = parse_mtl(input.text, file);
    } catch (const MeshError& e) {
      throw MeshError(file_.string() + ": " + where.path + ": " + e.what());
    }
    for (const std::string& w : parsed.warnings) warn(where, w);
    for (MtlMaterial& m : parsed.materials) {
      const std::string name = m.name;
      defined[name] = {std::move(m), file};
    }
  }
  std::vector<uint32_t> index;  // mesh material -> scene material
  for (const std::string& name : mesh.material_names) {
    const auto found = defined.find(name);
    if (found == defined.end())
      throw MeshError(file_.string() + ": " + where.path + ": " + mesh_file.filename().string() + ": usemtl " + printable(name) +
                      ": no material library it names (mtllib) defines it");
    const MtlMaterial& mtl = found->second.first;
    const std::filesystem::path& library = found->second.second;
    Material material;
    material.name = mesh_file.filename().string() + ": " + name;
    material.albedo = mtl.diffuse;
    material.emission = mtl.emission;
    const auto map = [&](const MtlTexture& t) {
      TextureRef ref;
      ref.texture = texture_file(where, (library.parent_path() / t.file).lexically_normal(), true);
      ref.wrap_s = ref.wrap_t = t.wrap;
      return ref;
    };
    if (!mtl.diffuse_map.file.empty()) material.albedo_texture = map(mtl.diffuse_map);
    if (!mtl.emission_map.file.empty()) material.emission_texture = map(mtl.emission_map);
    index.push_back(uint32_t(scene_.materials.size()));
    scene_.materials.push_back(std::move(material));
  }
  return index;
}

void SceneParser::parse_mesh(const Value& v, const glm::mat4& transform) {
  const Value file_value = require(v, "file");
  const std::filesystem::path file = (file_.parent_path() / string(file_value)).lexically_normal();
  bool smooth = false;
  if (v.has("smooth")) {
    if (!v["smooth"].j.is_boolean()) fail(v["smooth"], std::string("expected true or false, got ") + v["smooth"].j.type_name());
    smooth = v["smooth"].j.get<bool>();
  }
  std::shared_ptr<const Mesh> loaded;
  try {
    loaded = meshes_.get(file);
  } catch (const MeshError& e) {
    throw MeshError(file_.string() + ": " + file_value.path + ": " + e.what());
  }
  if (referenced_.insert(file).second) {
    scene_.referenced_files.push_back(file);
    if (loaded->polygons_split > 0)
      warn(file_value, file.filename().string() + ": " + std::to_string(loaded->polygons_split) +
                           " faces with more than 3 vertices split into triangles");
  }
  const Mesh& mesh = *loaded;

  // The scene's material for every face, or the ones the file's faces name (an OBJ file's usemtl).
  std::vector<uint32_t> file_materials;
  uint32_t material = 0;
  if (v.has("material")) {
    material = material_ref(v["material"]);
  } else if (!mesh.material_names.empty()) {
    file_materials = mesh_materials(file_value, file, mesh);
    const bool unnamed = std::find(mesh.triangle_materials.begin(), mesh.triangle_materials.end(), Mesh::kNoMaterial) !=
                         mesh.triangle_materials.end();
    if (unnamed) {  // faces before the first usemtl
      Material grey;
      grey.name = file.filename().string() + ": (no usemtl)";
      grey.albedo = glm::vec3(0.8f);
      material = uint32_t(scene_.materials.size());
      scene_.materials.push_back(grey);
    }
  } else {
    fail(v, "missing required key \"material\" (" + file.filename().string() + " names no materials of its own)");
  }

  std::vector<glm::vec3> points(mesh.positions.size());
  for (size_t i = 0; i < points.size(); ++i) points[i] = transform_point(transform, mesh.positions[i]);
  std::vector<Triangle> triangles(mesh.triangles.size());
  for (size_t i = 0; i < triangles.size(); ++i) {
    const uint32_t named = file_materials.empty() ? Mesh::kNoMaterial : mesh.triangle_materials[i];
    triangles[i].material = named == Mesh::kNoMaterial ? material : file_materials[named];
    triangles[i].object = object_;
    for (int k = 0; k < 3; ++k) triangles[i].v[size_t(k)] = points[mesh.triangles[i][size_t(k)]];
    if (!mesh.corner_uvs.empty()) triangles[i].uv = mesh.corner_uvs[i];
  }
  if (mesh.corner_uvs.empty() &&
      std::any_of(triangles.begin(), triangles.end(), [&](const Triangle& t) { return scene_.materials[t.material].textured(); }))
    warn(file_value, file.filename().string() + ": a textured material on faces without texture coordinates (vt): "
                                                "every point takes the texture's value at (0, 0)");
  if (smooth) {
    if (!mesh.corner_normals.empty()) {
      // Normals transform by the inverse transpose.
      const glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(transform)));
      for (size_t i = 0; i < triangles.size(); ++i)
        for (size_t k = 0; k < 3; ++k) triangles[i].normals[k] = glm::normalize(normal_matrix * mesh.corner_normals[i][k]);
    } else {
      std::vector<std::array<glm::vec3, 3>> corners(triangles.size());
      for (size_t i = 0; i < triangles.size(); ++i) corners[i] = triangles[i].v;
      const auto normals = area_weighted_normals(corners);
      for (size_t i = 0; i < triangles.size(); ++i) triangles[i].normals = normals[i];
    }
    for (Triangle& t : triangles) {
      t.smooth = true;
      // A zero normal (a vertex only on degenerate faces, or a zero normal in the file) cannot be
      // interpolated meaningfully: shade that triangle flat.
      for (const glm::vec3& n : t.normals)
        if (!std::isfinite(n.x) || glm::length(n) < 0.5f) t.smooth = false;
    }
  }
  if (flip_normals(v))
    for (Triangle& t : triangles) {  // the other winding, and the vertex normals turned with it
      std::swap(t.v[1], t.v[2]);
      std::swap(t.normals[1], t.normals[2]);
      std::swap(t.uv[1], t.uv[2]);
      for (glm::vec3& n : t.normals) n = -n;
    }
  add_triangles(file_value, triangles);
}

}  // namespace

float Scene::extent() const {
  float e = 0.0f;
  auto grow = [&e](glm::vec3 p) { e = std::max({e, std::abs(p.x), std::abs(p.y), std::abs(p.z)}); };
  grow(camera.position);
  for (const auto& l : lights) grow(l.position);
  for (const auto& s : spheres) grow(glm::abs(s.center) + s.radius);
  for (const auto& t : triangles)
    for (const auto& p : t.v) grow(p);
  return e;
}

namespace {

// Bit for bit: -0 and 0 are different coordinates to the shader's packed buffers.
bool same_bits(const glm::vec3& a, const glm::vec3& b) { return std::memcmp(&a, &b, sizeof(glm::vec3)) == 0; }

bool same_bits(const Triangle& a, const Triangle& b) {
  for (size_t k = 0; k < 3; ++k)
    if (!same_bits(a.v[k], b.v[k]) || !same_bits(a.normals[k], b.normals[k]) ||
        std::memcmp(&a.uv[k], &b.uv[k], sizeof(glm::vec2)) != 0)
      return false;
  return a.material == b.material && a.object == b.object && a.smooth == b.smooth;
}

bool same_bits(const Sphere& a, const Sphere& b) {
  return same_bits(a.center, b.center) && std::memcmp(&a.radius, &b.radius, sizeof(float)) == 0 && a.material == b.material &&
         a.object == b.object && a.inward == b.inward;
}

}  // namespace

bool same_geometry(const Scene& a, const Scene& b) {
  // Materials are compared by index (a primitive's flags hold it), not by value.
  const auto same = [](const auto& x, const auto& y) { return same_bits(x, y); };
  const auto same_texture = [](const std::shared_ptr<const Texture>& x, const std::shared_ptr<const Texture>& y) {
    return x == y || (x->width == y->width && x->height == y->height && x->texels == y->texels);
  };
  // The texture coordinates are on the device when some material has a texture.
  const auto textured = [](const Scene& s) {
    return std::any_of(s.materials.begin(), s.materials.end(), [](const Material& m) { return m.textured(); });
  };
  return a.materials.size() == b.materials.size() && textured(a) == textured(b) &&
         std::equal(a.textures.begin(), a.textures.end(), b.textures.begin(), b.textures.end(), same_texture) &&
         std::equal(a.triangles.begin(), a.triangles.end(), b.triangles.begin(), b.triangles.end(), same) &&
         std::equal(a.spheres.begin(), a.spheres.end(), b.spheres.begin(), b.spheres.end(), same);
}

struct MeshCache::Entry {
  uintmax_t size = 0;
  std::filesystem::file_time_type modified;
  std::shared_ptr<const Mesh> mesh;
};

MeshCache::MeshCache() = default;
MeshCache::~MeshCache() = default;

std::shared_ptr<const Mesh> MeshCache::get(const std::filesystem::path& file) {
  std::error_code size_error, time_error;
  const uintmax_t size = std::filesystem::file_size(file, size_error);
  const auto modified = std::filesystem::last_write_time(file, time_error);
  const auto found = entries_.find(file);
  if (!size_error && !time_error && found != entries_.end() && found->second.size == size && found->second.modified == modified)
    return found->second.mesh;
  auto mesh = std::make_shared<const Mesh>(load_mesh(file));
  if (!size_error && !time_error) entries_[file] = Entry{size, modified, mesh};
  return mesh;
}

void MeshCache::keep_only(const std::vector<std::filesystem::path>& files) {
  std::erase_if(entries_, [&](const auto& entry) { return std::find(files.begin(), files.end(), entry.first) == files.end(); });
}

Scene parse_scene(std::string_view json_text, const std::filesystem::path& file, MeshCache* meshes) {
  const json root = parse_json_document(json_text, file);
  Scene scene;
  scene.file = file;
  scene.name = file.stem().string();
  MeshCache this_scene;
  SceneParser(file, scene, meshes ? *meshes : this_scene).parse(root);
  recentre_texture_coordinates(scene);
  return scene;
}

namespace {

// The camera vkray frames a glTF scene with when the file has none: a 45-degree vertical field of
// view from the front (glTF's +z) and a little above, so that the bounding sphere fills the height.
Camera framing_camera(const Scene& scene) {
  Camera camera;
  camera.focal_length = 0.5f / std::tan(glm::radians(45.0f) / 2);
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (const Triangle& t : scene.triangles)
    for (const glm::vec3& p : t.v) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
  if (scene.triangles.empty()) {
    camera.position = glm::vec3(0.0f, 0.0f, 1.0f);
    camera.forward = glm::vec3(0.0f, 0.0f, -1.0f);
    return camera;
  }
  const glm::dvec3 centre = (glm::dvec3(lo) + glm::dvec3(hi)) / 2.0;
  const double radius = std::max(glm::length(glm::dvec3(hi) - glm::dvec3(lo)) / 2.0, 1e-6);
  const double distance = radius / std::sin(glm::radians(45.0 / 2)) * 1.05;
  const glm::dvec3 direction = glm::normalize(glm::dvec3(0.0, 0.3, 1.0));
  camera.position = glm::vec3(centre + distance * direction);
  camera.forward = glm::vec3(-direction);
  return camera;
}

}  // namespace

Scene load_gltf_scene(const std::filesystem::path& file, MeshCache* meshes) {
  Scene scene;
  scene.file = file;
  scene.name = file.stem().string();
  scene.description = "The glTF file " + file.filename().string();
  MeshCache this_scene;
  SceneParser parser(file, scene, meshes ? *meshes : this_scene);
  const auto [camera, aspect] = parser.add_gltf(nullptr, file, glm::mat4(1.0f));
  scene.camera = camera ? *camera : framing_camera(scene);
  if (!(glm::all(glm::lessThanEqual(glm::abs(scene.camera.position), glm::vec3(kMaxCoordinate)))))
    throw LimitError(file.string() + ": the camera vkray frames the model with would stand past +-1e9 (README, \"Limits\")");
  if (!camera) scene.warnings.push_back(file.string() + ": no perspective camera: vkray frames the scene from the front");
  if (aspect > 0.0f)
    scene.image.width = uint32_t(std::clamp(std::lround(double(scene.image.height) * aspect), 1l, long(kMaxImageSide)));
  // A file that brings no light is lit from the camera, so that it is seen at all (DECISIONS.md, 19):
  // a point light whose irradiance at the scene's centre, straight on, is 1.
  const bool emitters = std::any_of(scene.materials.begin(), scene.materials.end(), [](const Material& m) { return m.emissive(); });
  if (scene.lights.empty() && !emitters && !scene.triangles.empty()) {
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (const Triangle& t : scene.triangles)
      for (const glm::vec3& p : t.v) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
      }
    const float distance = std::max(glm::length((lo + hi) / 2.0f - scene.camera.position), 1e-6f);
    scene.lights.push_back(PointLight{scene.camera.position, glm::vec3(glm::pi<float>() * distance * distance)});
    scene.warnings.push_back(file.string() + ": the file brings no light: vkray adds a point light at the camera");
  }
  recentre_texture_coordinates(scene);
  return scene;
}

Scene load_scene(const std::filesystem::path& file, MeshCache* meshes) {
  if (file.empty()) throw SceneError("the scene file name is empty");
  if (is_gltf_path(file)) return load_gltf_scene(file, meshes);
  const InputFile input = read_input_file(file, kMaxSceneFileBytes);
  if (!input.error.empty()) throw SceneError(file.string() + ": " + input.error);
  return parse_scene(input.text, file, meshes);
}

}  // namespace vkray
