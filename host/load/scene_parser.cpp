#include "load/scene_parser.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <glm/gtc/constants.hpp>

#include "base/checked.h"
#include "base/interrupt.h"
#include "scene/camera.h"
#include "load/environment_file.h"
#include "scene/transform.h"

namespace vkray::scene_file {
namespace {

// The longest focal length, in image heights (a field of view of 5.7e-5 degrees). The camera ray's
// direction (F * H, x, y) is normalized: F * H (at most 1.6e10) squared stays far inside a float.
constexpr float kMaxFocalLength = 1e6f;

// The smoothest GGX surface (shared/materials.h says why); smoother than that is a mirror.
constexpr float kMinAlpha = VKRAY_MIN_GGX_ALPHA;

}  // namespace

void SceneParser::parse(const json& root_json) {
  const Value root{root_json, ""};
  expect_object(root);
  check_keys(root, {"description", "image", "camera", "integrator", "seed", "background", "environment", "ambient", "materials",
                    "lights", "objects"});
  if (root.has("description")) scene_.description = printable(string(root["description"]), 1000);
  if (root.has("image")) parse_image(root["image"]);
  if (root.has("seed")) scene_.image.seed = static_cast<uint32_t>(integer(root["seed"], 0, UINT32_MAX));
  parse_camera(require(root, "camera"));
  if (root.has("integrator")) parse_integrator(root["integrator"]);
  if (root.has("background")) scene_.background = color(root["background"]);
  if (root.has("environment") && environment_override_.empty()) {
    if (root.has("background")) fail(root, "give either \"background\" or \"environment\", not both: the map replaces the background");
    parse_environment(root["environment"]);
  }
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
  const bool lit = !scene_.lights.empty() || emitters || scene_.environment || !environment_override_.empty() ||
                   (path ? scene_.background : scene_.ambient) != glm::vec3(0.0f);
  if (!lit && (!scene_.triangles.empty() || !scene_.instances.empty()))
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
  cam.position = three_numbers(require(v, "position"));
  check_coordinates(v["position"], cam.position, "the camera");

  // A direction is judged in double, where any finite float vector has a finite, non-zero length
  // unless it is zero; its value is unit_direction's (scene/camera.h).
  const auto unit = [](glm::vec3 d) { return unit_direction(d); };
  const bool by_target = one_of(v, "look_at", "direction");
  const Value aim = by_target ? v["look_at"] : v["direction"];
  if (by_target) check_coordinates(aim, three_numbers(aim), "look_at");
  const glm::vec3 forward = by_target ? three_numbers(aim) - cam.position : three_numbers(aim);
  if (!(glm::length(glm::dvec3(forward)) > 0.0))
    fail(aim, by_target ? "look_at equals the camera position: no view direction" : "direction has zero length");
  cam.forward = unit(forward);

  if (v.has("up")) {
    const glm::vec3 up = three_numbers(v["up"]);
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
    cam.focus_distance = glm::length(three_numbers(aim) - cam.position);
  }
  // A lens in air is at most f/0.5 (a numerical aperture of 1), so its radius is at most its focal
  // length, which is at most the distance it focuses at. Past that, rays leave the lens far from the
  // scene they light, where 32-bit floats place them too coarsely for the scene's epsilon.
  if (cam.aperture_radius > cam.focus_distance) {
    std::ostringstream focus;
    focus << cam.focus_distance;
    fail(v["aperture_radius"], "an aperture radius of " + brief(v["aperture_radius"].j) + " is past the focus distance (" +
                                   focus.str() +
                                   "): a thin lens's aperture radius is at most the distance it focuses at (f/0.5, the "
                                   "widest a lens in air can be)");
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

// The keys every material takes, whatever its type: emission, a normal map and alpha (read below).
constexpr std::initializer_list<const char*> kAnyMaterialKeys = {"emission", "normal_texture", "normal_scale", "alpha_mode",
                                                                 "opacity", "opacity_texture", "alpha_cutoff"};

void SceneParser::parse_materials(const Value& v) {
  expect_object(v);
  for (const auto& [name, unused] : v.j.items()) {
    const Value m = v[name];
    expect_object(m);
    Material material;
    material.name = name;
    const std::string type = m.has("type") ? string(m["type"]) : "diffuse";
    const std::optional<MaterialType> known = material_type_named(type);
    if (!known) fail(m["type"], "unknown material type \"" + printable(type) + "\" (expected " + material_type_list() + ")");
    material.type = *known;
    switch (material.type) {
      case MaterialType::diffuse:
        check_keys(m, {"type", "albedo"}, kAnyMaterialKeys);
        material.albedo = reflectance(require(m, "albedo"));
        break;
      case MaterialType::mirror:
        check_keys(m, {"type", "reflectance"}, kAnyMaterialKeys);
        material.albedo = reflectance(require(m, "reflectance"));
        break;
      case MaterialType::glass:
        check_keys(m, {"type", "ior"}, kAnyMaterialKeys);
        if (m.has("ior")) material.ior = index_of_refraction(m["ior"]);
        break;
      case MaterialType::roughconductor:
        check_keys(m, {"type", "alpha", "alpha_u", "alpha_v", "specular_reflectance", "eta", "k"}, kAnyMaterialKeys);
        material.alpha = roughness(m);
        material.albedo = m.has("specular_reflectance") ? reflectance(m["specular_reflectance"]) : glm::vec3(1.0f);
        if (m.has("eta")) material.eta = bounded_color(m["eta"], kMaxIor, "indices of refraction up to 100");
        if (m.has("k")) material.k = bounded_color(m["k"], kMaxIor, "absorption coefficients up to 100");
        for (int c = 0; c < 3; ++c)
          if (material.eta[c] == 0.0f && material.k[c] == 0.0f)
            fail(m.has("k") ? m["k"] : m["eta"], "eta and k are both 0 in one channel, which is no conductor (without "
                                                 "either, eta 0 and k 1 reflect everything)");
        break;
      case MaterialType::roughdielectric:
        check_keys(m, {"type", "alpha", "alpha_u", "alpha_v", "int_ior"}, kAnyMaterialKeys);
        material.alpha = roughness(m);
        material.albedo = glm::vec3(1.0f);  // clear: Mitsuba's specular reflectance and transmittance, 1
        if (m.has("int_ior")) material.ior = index_of_refraction(m["int_ior"]);
        break;
      case MaterialType::metallic_roughness:  // glTF 2.0's, with its names and defaults
        check_keys(m, {"type", "base_color", "metallic", "roughness", "ior", "transmission", "base_color_texture",
                       "metallic_roughness_texture", "transmission_texture"},
                   kAnyMaterialKeys);
        material.albedo = m.has("base_color") ? reflectance(m["base_color"]) : glm::vec3(1.0f);
        // Pictures beside the scene file, read where a mesh gives texture coordinates: the base colour
        // as sRGB; metallic (blue) and roughness (green) as linear data, as glTF's textures are.
        if (m.has("base_color_texture")) material.albedo_texture.texture = texture_file(m["base_color_texture"], file_of(m["base_color_texture"]), TextureUse::colour);
        if (m.has("metallic_roughness_texture"))
          material.metallic_roughness_texture.texture = texture_file(m["metallic_roughness_texture"], file_of(m["metallic_roughness_texture"]), TextureUse::data);
        if (m.has("metallic")) material.metallic = unit_interval(m["metallic"]);
        if (m.has("roughness")) material.roughness = unit_interval(m["roughness"]);
        // KHR_materials_transmission (thin-walled): the factor (glTF's default 0), times the red of a
        // linear texture.
        if (m.has("transmission")) material.transmission = unit_interval(m["transmission"]);
        if (m.has("transmission_texture")) {
          if (!(material.transmission > 0.0f))
            fail(m["transmission_texture"], "a transmission_texture multiplies \"transmission\", which is 0: give it too");
          material.transmission_texture.texture =
              texture_file(m["transmission_texture"], file_of(m["transmission_texture"]), TextureUse::data);
        }
        if (m.has("ior")) {
          material.ior = index_of_refraction(m["ior"]);
          if (material.ior < 1.0f) fail(m["ior"], "expected an index of refraction from 1 to 100 (KHR_materials_ior), got " + brief(m["ior"].j));
        }
        break;
    }
    if (m.has("emission")) material.emission = color(m["emission"]);
    // A tangent-space normal map (linear data, as glTF's normalTexture) on any material, read where a
    // mesh gives texture coordinates; normal_scale multiplies its red and green.
    if (m.has("normal_texture")) material.normal_texture.texture = texture_file(m["normal_texture"], file_of(m["normal_texture"]), TextureUse::data);
    if (m.has("normal_scale")) {
      if (!m.has("normal_texture")) fail(m["normal_scale"], "normal_scale without a normal_texture");
      material.normal_scale = number(m["normal_scale"]);
      if (!(std::abs(material.normal_scale) <= 1e6f)) fail(m["normal_scale"], "expected a number of at most 1e6 in magnitude, got " + brief(m["normal_scale"].j));
    }
    parse_alpha(m, material);
    material_index_[name] = static_cast<uint32_t>(scene_.materials.size());
    scene_.materials.push_back(material);
  }
}

// How much of a surface is there, on any material (glTF's alpha, with glTF's modes): "opacity" (0 to 1)
// times the alpha of "opacity_texture" (a picture's grey where it has no alpha), by "alpha_mode":
// "blend" (the default where either is given: each ray meets the surface with probability its
// opacity, as Mitsuba's mask), "mask" (where the opacity reaches "alpha_cutoff", 0.5 by default), or
// "opaque".
void SceneParser::parse_alpha(const Value& m, Material& material) {
  const bool given = m.has("opacity") || m.has("opacity_texture");
  material.alpha_mode = given ? AlphaMode::blend : AlphaMode::opaque;
  if (m.has("alpha_mode")) {
    const std::string mode = string(m["alpha_mode"]);
    if (mode == "opaque") material.alpha_mode = AlphaMode::opaque;
    else if (mode == "mask") material.alpha_mode = AlphaMode::mask;
    else if (mode == "blend") material.alpha_mode = AlphaMode::blend;
    else fail(m["alpha_mode"], "unknown alpha_mode \"" + printable(mode) + "\" (expected \"opaque\", \"mask\" or \"blend\")");
    if (material.alpha_mode == AlphaMode::opaque && given)
      fail(m["alpha_mode"], "alpha_mode \"opaque\" renders no opacity: leave out \"opacity\" and \"opacity_texture\", or give \"mask\" or \"blend\"");
    if (material.alpha_mode != AlphaMode::opaque && !given)
      fail(m["alpha_mode"], "alpha_mode \"" + mode + "\" without \"opacity\" or \"opacity_texture\": the surface would be whole");
  }
  if (m.has("opacity")) material.opacity = unit_interval(m["opacity"]);
  if (m.has("opacity_texture"))
    material.opacity_texture.texture = texture_file(m["opacity_texture"], file_of(m["opacity_texture"]), TextureUse::opacity);
  if (m.has("alpha_cutoff")) {
    if (material.alpha_mode != AlphaMode::mask) fail(m["alpha_cutoff"], "alpha_cutoff applies to alpha_mode \"mask\" only");
    material.alpha_cutoff = unit_interval(m["alpha_cutoff"]);
  }
}

// A colour in [0, 1]: more would reflect more light than arrives. The direct model takes it with a
// warning (a light bounces at most a few times); paths would carry it without end, so that a closed
// room of such a surface has no finite radiance.
glm::vec3 SceneParser::reflectance(const Value& c) {
  const glm::vec3 rgb = color(c);
  if (rgb.r > 1.0f || rgb.g > 1.0f || rgb.b > 1.0f) {
    if (scene_.integrator.type == Integrator::Type::path)
      fail(c, "a value above 1 reflects more light than arrives, which the path integrator would carry without end "
              "(radiance past any bound): at most 1");
    warn(c, "a value above 1 reflects more light than arrives");
  }
  return rgb;
}

float SceneParser::index_of_refraction(const Value& v) const {
  const float ior = positive(v);
  if (!(ior <= kMaxIor)) fail(v, "expected an index of refraction up to 100, got " + brief(v.j));
  return ior;
}

glm::vec3 SceneParser::bounded_color(const Value& v, float max, const char* expected) const {
  const glm::vec3 c = color(v);
  if (!(c.r <= max && c.g <= max && c.b <= max)) fail(v, std::string("expected ") + expected + ", got " + brief(v.j));
  return c;
}

// "alpha", or "alpha_u" and "alpha_v" (Mitsuba's names), each from kMinAlpha to 1; 0.1 when none is given.
glm::vec2 SceneParser::roughness(const Value& m) const {
  const auto one = [&](const Value& a) {
    const float alpha = number(a);
    if (!(alpha >= kMinAlpha && alpha <= 1.0f))
      fail(a, "expected a roughness (GGX alpha) from 0.0001 to 1, got " + brief(a.j) +
                  " (for a perfectly smooth surface, use \"mirror\" or \"glass\")");
    return alpha;
  };
  if (m.has("alpha")) {
    if (m.has("alpha_u") || m.has("alpha_v")) fail(m, "give either \"alpha\" or \"alpha_u\" and \"alpha_v\", not both");
    return glm::vec2(one(m["alpha"]));
  }
  if (m.has("alpha_u") != m.has("alpha_v")) fail(m, "give \"alpha_u\" and \"alpha_v\" together");
  if (m.has("alpha_u")) return {one(m["alpha_u"]), one(m["alpha_v"])};
  return glm::vec2(0.1f);
}

float SceneParser::unit_interval(const Value& v) const {
  const float f = number(v);
  if (!(f >= 0.0f && f <= 1.0f)) fail(v, "expected a number from 0 to 1, got " + brief(v.j));
  return f;
}

std::string SceneParser::material_type_list() {
  std::string list;
  for (uint32_t t = 0; t < VKRAY_MATERIAL_TYPE_COUNT; ++t)
    list += std::string(t == 0 ? "" : t + 1 == VKRAY_MATERIAL_TYPE_COUNT ? " or " : ", ") + "\"" +
            std::string(material_type_name(MaterialType(t))) + "\"";
  return list;
}

uint32_t SceneParser::material_ref(const Value& v) const {
  const std::string name = string(v);
  const auto it = material_index_.find(name);
  if (it == material_index_.end()) fail(v, "undefined material \"" + printable(name) + "\"");
  return it->second;
}

void SceneParser::parse_light(const Value& v) {
  expect_object(v);
  const Value type = require(v, "type");
  const std::string kind = string(type);
  Light light;
  // A direction given by a target or by itself, as the camera's; judged in double (any finite float
  // vector has a finite length there unless it is zero).
  const auto aim = [&](const char* what) {
    const bool by_target = what == std::string("spot") ? one_of(v, "look_at", "direction") : false;
    const Value given = by_target ? v["look_at"] : require(v, "direction");
    if (by_target) check_coordinates(given, three_numbers(given), "look_at");
    const glm::dvec3 d = by_target ? glm::dvec3(three_numbers(given)) - glm::dvec3(light.position) : glm::dvec3(three_numbers(given));
    if (!(glm::length(d) > 0.0)) fail(given, by_target ? "look_at equals the light's position: no direction" : "direction has zero length");
    light.direction = glm::vec3(glm::normalize(d));
  };
  if (kind == "point") {
    check_keys(v, {"type", "position", "intensity", "power"});
    light.position = three_numbers(require(v, "position"));
    check_coordinates(v["position"], light.position, "the light");
    if (one_of(v, "intensity", "power")) {
      light.intensity = color(v["intensity"]);
    } else {
      light.intensity = color(v["power"]) / (4.0f * glm::pi<float>());  // isotropic: I = P / 4pi
    }
  } else if (kind == "spot") {
    // Mitsuba's `spot`: its intensity at the centre, a cutoff angle (20 degrees unless given) and a
    // beam width (three quarters of the cutoff unless given), in degrees.
    check_keys(v, {"type", "position", "look_at", "direction", "intensity", "cutoff_angle", "beam_width"});
    light.type = Light::Type::spot;
    light.position = three_numbers(require(v, "position"));
    check_coordinates(v["position"], light.position, "the light");
    aim("spot");
    light.intensity = color(require(v, "intensity"));
    float cutoff = 20.0f;
    if (v.has("cutoff_angle")) {
      cutoff = number(v["cutoff_angle"]);
      if (!(cutoff > 0.0f && cutoff <= 180.0f)) fail(v["cutoff_angle"], "expected degrees in (0, 180], got " + brief(v["cutoff_angle"].j));
    }
    float beam = 0.75f * cutoff;
    if (v.has("beam_width")) {
      beam = number(v["beam_width"]);
      if (!(beam >= 0.0f && beam <= cutoff))
        fail(v["beam_width"], "expected degrees from 0 to the cutoff_angle (" + (v.has("cutoff_angle") ? brief(v["cutoff_angle"].j) : std::string("20")) + "), got " + brief(v["beam_width"].j));
    }
    light.cutoff_angle = glm::radians(cutoff);
    light.beam_width = glm::radians(beam);
  } else if (kind == "directional") {
    // Mitsuba's `directional`: the irradiance on a surface facing it, arriving along `direction`.
    check_keys(v, {"type", "direction", "irradiance"});
    light.type = Light::Type::directional;
    aim("directional");
    light.intensity = color(require(v, "irradiance"));
  } else {
    fail(type, "unknown light type " + brief(type.j) + " (expected \"point\", \"spot\" or \"directional\")");
  }
  scene_.lights.push_back(light);
}

void SceneParser::parse_environment(const Value& v) {
  // Mitsuba's envmap: its file, a scale of its radiance, and its to_world, a rotation (a map infinitely far
  // away has no place to move to, nor a size).
  expect_object(v);
  check_keys(v, {"file", "scale", "transform"});
  Environment environment;
  environment.file = file_of(require(v, "file"));
  if (v.has("scale")) {
    environment.scale = number(v["scale"]);
    if (!(environment.scale >= 0.0f)) fail(v["scale"], "expected a number >= 0, got " + brief(v["scale"].j));
  }
  if (v.has("transform")) {
    const glm::mat4 m = parse_transform(v["transform"]);
    const glm::mat3 r(m);
    // Within float rounding of a rotation: orthonormal columns, determinant 1, no translation.
    const glm::dmat3 rtr = glm::transpose(glm::dmat3(r)) * glm::dmat3(r);
    double off = 0.0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) off = std::max(off, std::abs(rtr[i][j] - (i == j ? 1.0 : 0.0)));
    if (glm::vec3(m[3]) != glm::vec3(0.0f) || !(off < 1e-5) || !(glm::determinant(glm::dmat3(r)) > 0.0))
      fail(v["transform"], "an environment's transform is a rotation (\"rotate\", or a rotation \"matrix\"): no translation, "
                           "scale or mirroring");
    environment.to_world = r;
  }
  try {
    environment.radiance = read_environment_map(environment.file, environment.scale, &environment.brightest);
  } catch (const LimitError& e) {
    throw LimitError(file_.string() + ": " + v["file"].path + ": " + e.what());
  } catch (const SceneError& e) {
    throw SceneError(file_.string() + ": " + v["file"].path + ": " + e.what());
  }
  reference(environment.file);
  scene_.environment = std::move(environment);
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
  if (v.has("translate")) translate = three_numbers(v["translate"]);
  if (v.has("rotate")) rotate = three_numbers(v["rotate"]);
  if (v.has("scale")) {
    const Value s = v["scale"];
    scale = s.j.is_number() ? glm::vec3(number(s)) : three_numbers(s);
    if (scale.x == 0.0f || scale.y == 0.0f || scale.z == 0.0f) fail(s, "scale must be non-zero");
  }
  return compose_transform(translate, rotate, scale);
}

std::vector<glm::mat4> SceneParser::placements(const Value& v, const glm::mat4& transform) {
  if (!v.has("instances")) return {transform};
  // Each instance is a transform that places the object, then its own "transform" places that.
  const Value instances = v["instances"];
  expect_array(instances);
  if (instances.j.empty()) fail(instances, "expected at least one transform");
  std::vector<glm::mat4> out;
  out.reserve(instances.j.size());
  for (size_t i = 0; i < instances.j.size(); ++i) {
    if (i % 1024 == 0) throw_if_interrupted();
    out.push_back(transform * parse_transform(instances[i]));
  }
  return out;
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
    sphere.center = three_numbers(require(v, "center"));
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
    check_keys(v, {"type", "positions", "indices", "material", "transform", "instances", "flip_normals"});
    // Placed once: moved into place. Placed by "instances": stored once, in its own space.
    const std::vector<glm::mat4> where = placements(v, transform);
    const glm::mat4 placed = where.size() == 1 ? where[0] : glm::mat4(1.0f);
    const Value positions = require(v, "positions");
    expect_array(positions);
    std::vector<glm::vec3> points;
    points.reserve(positions.j.size());
    for (size_t i = 0; i < positions.j.size(); ++i) points.push_back(transform_point(placed, three_numbers(positions[i])));
    const uint32_t material = material_ref(require(v, "material"));
    const bool flip = flip_normals(v), mirrors = glm::determinant(glm::mat3(placed)) < 0.0f;
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
      if (flip != mirrors) std::swap(t.v[1], t.v[2]);  // the other winding: the normal turned around (a mirror turns it too)
      triangles.push_back(t);
    }
    if (where.size() == 1)
      add_triangles(indices, triangles);
    else
      add_instances(v["instances"], triangles, where);
  } else if (type == "mesh") {
    check_keys(v, {"type", "file", "material", "transform", "instances", "smooth", "flip_normals"});
    const std::vector<glm::mat4> where = placements(v, transform);
    // Placed once: its triangles moved into place. Placed by "instances": stored once, in its own space.
    std::vector<Triangle> triangles = mesh_triangles(v, where.size() == 1 ? where[0] : glm::mat4(1.0f));
    if (where.size() == 1)
      add_triangles(require(v, "file"), triangles);
    else
      add_instances(v["instances"], triangles, where);
  } else if (type == "gltf") {
    check_keys(v, {"type", "file", "transform", "instances"});
    const Value file_value = require(v, "file");
    const std::vector<glm::mat4> where = placements(v, transform);
    if (where.size() == 1)
      add_gltf(&file_value, file_of(file_value), where[0]);
    else
      add_gltf_instances(file_value, v["instances"], file_of(file_value), where);
  } else {
    fail(type_value, "unknown object type \"" + printable(type) + "\" (expected \"sphere\", \"triangles\", \"mesh\" or \"gltf\")");
  }
}


}  // namespace vkray::scene_file
