// Scene files: the contract's keys, their defaults, transforms, and every error a user can make.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <glm/gtc/constants.hpp>

#include "base/errors.h"
#include "base/json_document.h"
#include "load/scene_loader.h"
#include "scene/scene.h"

namespace vkray {
namespace {

constexpr const char* kCamera = R"("camera": {"position": [0, 0, 0], "direction": [0, 0, 1], "focal_length": 1})";

std::string with_camera(const std::string& rest) { return std::string("{") + kCamera + (rest.empty() ? "" : ", ") + rest + "}"; }

// Parsing `json` throws a SceneError whose message starts with "test.json" and contains `where`.
// The scene's material of that name (the file's materials come in the JSON reader's order).
Material material_named(const Scene& scene, const std::string& name) {
  for (const Material& m : scene.materials)
    if (m.name == name) return m;
  ADD_FAILURE() << "no material " << name;
  return Material{};
}

void expect_error(const std::string& json, const std::string& where, const std::string& what = "") {
  try {
    parse_scene(json, "test.json");
    ADD_FAILURE() << "no error for: " << json;
  } catch (const SceneError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("test.json", 0), 0u) << message;
    EXPECT_NE(message.find(where), std::string::npos) << "expected \"" << where << "\" in: " << message;
    EXPECT_NE(message.find(what), std::string::npos) << "expected \"" << what << "\" in: " << message;
  }
}

TEST(SceneTest, CornellBoxLoads) {
  const Scene scene = load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "cornell.json");
  EXPECT_EQ(scene.name, "cornell");
  EXPECT_EQ(scene.triangles.size(), 30u);
  EXPECT_EQ(scene.materials.size(), 7u);
  ASSERT_EQ(scene.lights.size(), 1u);
  EXPECT_NEAR(scene.lights[0].intensity.r, 14.0f / (4.0f * glm::pi<float>()), 1e-6f);
  EXPECT_EQ(scene.camera.forward, glm::vec3(0, 0, 1));
  EXPECT_EQ(scene.camera.focal_length, 1.0f);
  EXPECT_TRUE(scene.warnings.empty());
  // The lab's scaling: raw (555, 0, 0) -> (-1, 1, -1). Every room vertex lands on the [-1, 1] cube.
  for (const Triangle& t : scene.triangles)
    for (const glm::vec3& v : t.v)
      for (int c = 0; c < 3; ++c) EXPECT_LE(std::abs(v[c]), 1.0f + 1e-6f);
}

TEST(SceneTest, DefaultsWhenKeysAreLeftOut) {
  const Scene scene = parse_scene(with_camera(""), "test.json");
  EXPECT_EQ(scene.image.width, 512u);
  EXPECT_EQ(scene.image.height, 512u);
  EXPECT_EQ(scene.image.samples_per_pixel, 1u);
  EXPECT_EQ(scene.background, glm::vec3(0));
  EXPECT_EQ(scene.ambient, glm::vec3(0));
  EXPECT_EQ(scene.camera.up, glm::vec3(0, 1, 0));
  EXPECT_TRUE(scene.triangles.empty());
}

TEST(SceneTest, CameraLookAtAndFieldOfView) {
  const Scene scene = parse_scene(
      R"({"camera": {"position": [1, 2, 3], "look_at": [1, 2, 7], "up": [0, 1, 0], "vertical_fov": 90}})", "t.json");
  EXPECT_EQ(scene.camera.forward, glm::vec3(0, 0, 1));
  EXPECT_NEAR(scene.camera.focal_length, 0.5f, 1e-6f);  // (H/2) / tan(45 deg) = H/2
}

TEST(SceneTest, PowerIsConvertedToIntensity) {
  const Scene scene = parse_scene(
      with_camera(R"("lights": [{"type": "point", "position": [0, 0, 0], "power": [4, 8, 0]}])"), "t.json");
  EXPECT_NEAR(scene.lights[0].intensity.r, 1.0f / glm::pi<float>(), 1e-6f);
  EXPECT_NEAR(scene.lights[0].intensity.g, 2.0f / glm::pi<float>(), 1e-6f);
}

TEST(SceneTest, TransformOrderIsTranslateRotateZYXScale) {
  // Point (1, 0, 0): scale 2 -> (2, 0, 0); Rx(90) keeps it; Ry(0); Rz(90) -> (0, 2, 0); translate -> (10, 2, 0).
  const Scene scene = parse_scene(with_camera(R"(
    "materials": {"m": {"albedo": [1, 1, 1]}},
    "objects": [{"type": "triangles", "material": "m", "positions": [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
                 "indices": [[0, 1, 2]], "transform": {"translate": [10, 0, 0], "rotate": [90, 0, 90], "scale": 2}}])"),
                                  "t.json");
  const glm::vec3 p = scene.triangles[0].v[0];
  EXPECT_NEAR(p.x, 10.0f, 1e-5f);
  EXPECT_NEAR(p.y, 2.0f, 1e-5f);
  EXPECT_NEAR(p.z, 0.0f, 1e-5f);
  // (0, 1, 0): scale -> (0, 2, 0); Rx(90) -> (0, 0, 2); Rz(90) keeps it; translate -> (10, 0, 2).
  const glm::vec3 q = scene.triangles[0].v[1];
  EXPECT_NEAR(q.x, 10.0f, 1e-5f);
  EXPECT_NEAR(q.y, 0.0f, 1e-5f);
  EXPECT_NEAR(q.z, 2.0f, 1e-5f);
}

TEST(SceneTest, SphereTakesUniformScaleAndMatrix) {
  const Scene scene = parse_scene(with_camera(R"(
    "materials": {"m": {"albedo": [1, 1, 1]}},
    "objects": [{"type": "sphere", "center": [1, 0, 0], "radius": 0.5, "material": "m",
                 "transform": {"translate": [0, 0, 5], "rotate": [0, 0, 90], "scale": 3}},
                {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m",
                 "transform": {"matrix": [0, -2, 0, 1,  2, 0, 0, 2,  0, 0, 2, 3,  0, 0, 0, 1]}}])"),
                                  "t.json");
  ASSERT_EQ(scene.spheres.size(), 2u);
  EXPECT_NEAR(scene.spheres[0].center.x, 0.0f, 1e-5f);
  EXPECT_NEAR(scene.spheres[0].center.y, 3.0f, 1e-5f);
  EXPECT_NEAR(scene.spheres[0].center.z, 5.0f, 1e-5f);
  EXPECT_NEAR(scene.spheres[0].radius, 1.5f, 1e-6f);
  EXPECT_EQ(scene.spheres[1].center, glm::vec3(1, 2, 3));
  EXPECT_NEAR(scene.spheres[1].radius, 2.0f, 1e-6f);
}

TEST(SceneTest, NoLightsAndNoAmbientWarns) {
  const Scene scene = parse_scene(with_camera(R"("materials": {"m": {"albedo": [1, 1, 1]}},
    "objects": [{"type": "triangles", "material": "m", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "indices": [[0, 1, 2]]}])"),
                                  "t.json");
  ASSERT_EQ(scene.warnings.size(), 1u);
  EXPECT_NE(scene.warnings[0].find("no lights, no emission and no ambient"), std::string::npos) << scene.warnings[0];
}

// ---- The rendering equation's keys (integrator, materials, emission, the lens, the seed) ----------------
TEST(SceneTest, IntegratorMaterialsLensAndSeed) {
  const Scene scene = parse_scene(R"({
    "camera": {"position": [0, 0, 0], "look_at": [0, 0, 4], "focal_length": 1, "aperture_radius": 0.1},
    "integrator": {"type": "path", "max_depth": 6, "rr_depth": 3},
    "seed": 4000000000,
    "materials": {"d": {"albedo": [0.5, 0.5, 0.5], "emission": [1, 2, 3]}, "m": {"type": "mirror", "reflectance": [0.9, 0.8, 0.7]},
                  "g": {"type": "glass", "ior": 1.33}, "g2": {"type": "glass"}},
    "objects": [{"type": "sphere", "center": [0, 0, 5], "radius": 1, "material": "g", "flip_normals": true},
                {"type": "triangles", "material": "d", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "indices": [[0, 1, 2]], "flip_normals": true}]})",
                                  "t.json");
  EXPECT_EQ(scene.integrator.type, Integrator::Type::path);
  EXPECT_EQ(scene.integrator.max_depth, 6);
  EXPECT_EQ(scene.integrator.rr_depth, 3u);
  EXPECT_EQ(scene.image.seed, 4000000000u);
  EXPECT_FLOAT_EQ(scene.camera.aperture_radius, 0.1f);
  EXPECT_FLOAT_EQ(scene.camera.focus_distance, 4.0f);  // the distance to look_at
  ASSERT_EQ(scene.materials.size(), 4u);
  const auto material = [&](const char* name) { return material_named(scene, name); };
  EXPECT_EQ(material("d").type, MaterialType::diffuse);
  EXPECT_EQ(material("d").emission, glm::vec3(1, 2, 3));
  EXPECT_TRUE(material("d").emissive());
  EXPECT_FALSE(material("m").emissive());
  EXPECT_EQ(material("m").type, MaterialType::mirror);
  EXPECT_EQ(material("m").albedo, glm::vec3(0.9f, 0.8f, 0.7f));
  EXPECT_EQ(material("g").type, MaterialType::glass);
  EXPECT_FLOAT_EQ(material("g").ior, 1.33f);
  EXPECT_FLOAT_EQ(material("g2").ior, 1.5f);  // the default: Mitsuba's dielectric
  EXPECT_TRUE(scene.spheres[0].inward);
  EXPECT_EQ(scene.triangles[0].v[1], glm::vec3(0, 1, 0));  // wound the other way
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings[0];
}

TEST(SceneTest, RoughConductorsTakeMitsubasNamesAndDefaults) {
  const Scene scene = parse_scene(with_camera(R"("materials": {
      "plain": {"type": "roughconductor"},
      "gold": {"type": "roughconductor", "alpha": 0.3, "eta": [0.14, 0.37, 1.44], "k": [3.98, 2.38, 1.6]},
      "brushed": {"type": "roughconductor", "alpha_u": 0.05, "alpha_v": 0.5, "specular_reflectance": [0.9, 0.8, 0.7]}})"),
                                  "t.json");
  ASSERT_EQ(scene.materials.size(), 3u);
  const Material plain = material_named(scene, "plain"), gold = material_named(scene, "gold"),
                 brushed = material_named(scene, "brushed");
  EXPECT_EQ(plain.type, MaterialType::roughconductor);
  EXPECT_EQ(plain.alpha, glm::vec2(0.1f));                   // Mitsuba's default roughness
  EXPECT_EQ(plain.albedo, glm::vec3(1.0f));                  // specular_reflectance
  EXPECT_EQ(plain.eta, glm::vec3(0.0f));                     // material "none": the Fresnel term is 1
  EXPECT_EQ(plain.k, glm::vec3(1.0f));
  EXPECT_TRUE(plain.has(VKRAY_BSDF_GLOSSY));
  EXPECT_FALSE(plain.has(VKRAY_BSDF_DELTA));
  EXPECT_EQ(gold.alpha, glm::vec2(0.3f));
  EXPECT_EQ(gold.eta, glm::vec3(0.14f, 0.37f, 1.44f));
  EXPECT_EQ(gold.k, glm::vec3(3.98f, 2.38f, 1.6f));
  EXPECT_EQ(brushed.alpha, glm::vec2(0.05f, 0.5f));
  EXPECT_EQ(brushed.albedo, glm::vec3(0.9f, 0.8f, 0.7f));
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings[0];
  // The unknown type's message names every type there is.
  expect_error(with_camera(R"("materials": {"m": {"type": "metal"}})"), "/materials/m/type",
               "(expected \"diffuse\", \"mirror\", \"glass\", \"roughconductor\", \"roughdielectric\" or \"metallic_roughness\")");
  expect_error(with_camera(R"("materials": {"m": {"type": "roughconductor", "alpha": 1.5}})"), "/materials/m/alpha", "from 0.0001 to 1");
  expect_error(with_camera(R"("materials": {"m": {"type": "roughconductor", "alpha_v": 0.2}})"), "/materials/m", "together");
  expect_error(with_camera(R"("materials": {"m": {"type": "roughconductor", "k": [1, -1, 1]}})"), "/materials/m/k", "non-negative");
}

TEST(SceneTest, RoughDielectricsTakeMitsubasNames) {
  const Scene scene = parse_scene(with_camera(R"("materials": {
      "plain": {"type": "roughdielectric"},
      "water": {"type": "roughdielectric", "alpha": 0.3, "int_ior": 1.33},
      "brushed": {"type": "roughdielectric", "alpha_u": 0.05, "alpha_v": 0.5}})"),
                                  "t.json");
  const Material plain = material_named(scene, "plain"), water = material_named(scene, "water"),
                 brushed = material_named(scene, "brushed");
  EXPECT_EQ(plain.type, MaterialType::roughdielectric);
  EXPECT_EQ(plain.alpha, glm::vec2(0.1f));
  EXPECT_EQ(plain.ior, 1.5f);  // vkray's glass default (Mitsuba's is bk7's 1.5046)
  EXPECT_EQ(plain.albedo, glm::vec3(1.0f));
  EXPECT_TRUE(plain.has(VKRAY_BSDF_TRANSMISSION) && plain.has(VKRAY_BSDF_GLOSSY) && plain.has(VKRAY_BSDF_CLEAR));
  EXPECT_EQ(water.alpha, glm::vec2(0.3f));
  EXPECT_EQ(water.ior, 1.33f);
  EXPECT_EQ(brushed.alpha, glm::vec2(0.05f, 0.5f));
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings[0];
  expect_error(with_camera(R"("materials": {"m": {"type": "roughdielectric", "int_ior": 101}})"), "/materials/m/int_ior", "up to 100");
}

TEST(SceneTest, TheGltfMaterialTakesGltfsNamesAndDefaults) {
  const Scene scene = parse_scene(with_camera(R"("materials": {
      "plain": {"type": "metallic_roughness"},
      "paint": {"type": "metallic_roughness", "base_color": [0.8, 0.1, 0.1], "metallic": 0, "roughness": 0.4, "ior": 1.45}})"),
                                  "t.json");
  const Material plain = material_named(scene, "plain"), paint = material_named(scene, "paint");
  EXPECT_EQ(plain.type, MaterialType::metallic_roughness);
  EXPECT_EQ(plain.albedo, glm::vec3(1.0f));  // glTF's defaults: a white, fully rough metal
  EXPECT_EQ(plain.metallic, 1.0f);
  EXPECT_EQ(plain.roughness, 1.0f);
  EXPECT_EQ(plain.ior, 1.5f);
  EXPECT_TRUE(plain.has(VKRAY_BSDF_DIFFUSE) && plain.has(VKRAY_BSDF_GLOSSY));
  EXPECT_EQ(paint.albedo, glm::vec3(0.8f, 0.1f, 0.1f));
  EXPECT_EQ(paint.metallic, 0.0f);
  EXPECT_EQ(paint.roughness, 0.4f);
  EXPECT_EQ(paint.ior, 1.45f);
  expect_error(with_camera(R"("materials": {"m": {"type": "metallic_roughness", "metallic": 1.5}})"), "/materials/m/metallic", "from 0 to 1");
  expect_error(with_camera(R"("materials": {"m": {"type": "metallic_roughness", "roughness": -0.1}})"), "/materials/m/roughness", "from 0 to 1");
  expect_error(with_camera(R"("materials": {"m": {"type": "metallic_roughness", "ior": 0.5}})"), "/materials/m/ior", "from 1 to 100");
}

TEST(SceneTest, TheDirectModelIsTheDefault) {
  const Scene scene = parse_scene(with_camera(""), "t.json");
  EXPECT_EQ(scene.integrator.type, Integrator::Type::direct);
  EXPECT_EQ(scene.integrator.max_depth, -1);
  EXPECT_EQ(scene.integrator.rr_depth, 5u);
  EXPECT_EQ(scene.image.seed, 0u);
  EXPECT_EQ(scene.camera.aperture_radius, 0.0f);
}

TEST(SceneTest, AmbientIsIgnoredUnderPathsWithAWarning) {
  const Scene scene = parse_scene(with_camera(R"("integrator": {"type": "path"}, "ambient": [0.1, 0.1, 0.1], "background": [1, 1, 1])"), "t.json");
  ASSERT_EQ(scene.warnings.size(), 1u);
  EXPECT_NE(scene.warnings[0].find("/ambient"), std::string::npos) << scene.warnings[0];
  EXPECT_NE(scene.warnings[0].find("ignored"), std::string::npos) << scene.warnings[0];
}

TEST(SceneTest, IntegratorMaterialAndLensErrors) {
  expect_error(with_camera(R"("integrator": {"type": "bidirectional"})"), "/integrator/type", "unknown integrator");
  expect_error(with_camera(R"("integrator": {})"), "/integrator", "missing required key \"type\"");
  expect_error(with_camera(R"("integrator": {"type": "path", "max_depth": 0})"), "/integrator/max_depth", "renders nothing");
  expect_error(with_camera(R"("integrator": {"type": "path", "max_depth": -2})"), "/integrator/max_depth", "from -1 to 1024");
  expect_error(with_camera(R"("integrator": {"type": "path", "max_depth": 2.5})"), "/integrator/max_depth", "integer");
  expect_error(with_camera(R"("integrator": {"type": "path", "rr_depth": 0})"), "/integrator/rr_depth", "from 1 to 1024");
  expect_error(with_camera(R"("seed": -1)"), "/seed", "from 0 to 4294967295");
  expect_error(with_camera(R"("seed": 4294967296)"), "/seed", "from 0 to 4294967295");
  expect_error(with_camera(R"("materials": {"g": {"type": "glass", "ior": 0}})"), "/materials/g/ior", "> 0");
  expect_error(with_camera(R"("materials": {"g": {"type": "glass", "ior": -1.5}})"), "/materials/g/ior", "> 0");
  expect_error(with_camera(R"("materials": {"g": {"type": "glass", "ior": 1e300}})"), "/materials/g/ior", "out of range");
  expect_error(with_camera(R"("materials": {"m": {"type": "mirror"}})"), "/materials/m", "\"reflectance\"");
  expect_error(with_camera(R"("materials": {"m": {"type": "metal", "albedo": [1, 1, 1]}})"), "/materials/m/type", "unknown material type");
  expect_error(with_camera(R"("materials": {"e": {"albedo": [1, 1, 1], "emission": [1, -1, 1]}})"), "/materials/e/emission", "non-negative");
  expect_error(with_camera(R"("materials": {"e": {"albedo": [1, 1, 1], "emission": [1, 1e39, 1]}})"), "/materials/e/emission", "out of range");
  expect_error(with_camera(R"("objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "x", "flip_normals": 1}])"),
               "/objects/0/flip_normals", "true or false");
  expect_error(R"({"camera": {"position": [0, 0, 0], "direction": [0, 0, 1], "focal_length": 1, "aperture_radius": 0.1}})", "/camera",
               "\"focus_distance\"");
  expect_error(R"({"camera": {"position": [0, 0, 0], "direction": [0, 0, 1], "focal_length": 1, "aperture_radius": -0.1}})",
               "/camera/aperture_radius", "from 0 to 1e9");
  expect_error(R"({"camera": {"position": [0, 0, 0], "direction": [0, 0, 1], "focal_length": 1, "focus_distance": 0}})",
               "/camera/focus_distance", "> 0");
}

// Values a 32-bit float holds but the GPU's float math could not carry: refused by the loader, so
// that both renderers refuse them alike.
TEST(SceneTest, ValuesPastWhatTheGpuCarriesAreRefused) {
  // A lens wider than f/0.5: its radius past the distance it focuses at.
  expect_error(R"({"camera": {"position": [0, 0, 0], "direction": [0, 0, 1], "focal_length": 1, "aperture_radius": 2.5,
                   "focus_distance": 2}})", "/camera/aperture_radius", "past the focus distance");
  expect_error(R"({"camera": {"position": [0, 0, 0], "look_at": [0, 0, 3], "focal_length": 1, "aperture_radius": 1e9}})",
               "/camera/aperture_radius", "at most the distance it focuses at");
  EXPECT_NO_THROW(parse_scene(R"({"camera": {"position": [0, 0, 0], "look_at": [0, 0, 3], "focal_length": 1,
                                  "aperture_radius": 3}})", "test.json"));
  // Paths carry a reflectance above 1 without end; the direct model takes it with a warning.
  expect_error(with_camera(R"("integrator": {"type": "path"}, "materials": {"w": {"albedo": [0.5, 1.5, 0.5]}})"),
               "/materials/w/albedo", "at most 1");
  expect_error(with_camera(R"("integrator": {"type": "path"}, "materials": {"m": {"type": "mirror", "reflectance": [2, 2, 2]}})"),
               "/materials/m/reflectance", "at most 1");
  const Scene direct = parse_scene(with_camera(R"("materials": {"w": {"albedo": [0.5, 1.5, 0.5]}})"), "test.json");
  ASSERT_FALSE(direct.warnings.empty());
  EXPECT_NE(direct.warnings.front().find("reflects more light than arrives"), std::string::npos);
  // An area light whose sampling density (its share of the lights' power over its area) passes the
  // largest float: a tiny light that is the only one. Beside a light of ordinary size it is picked
  // rarely and its density is small.
  expect_error(with_camera(R"("materials": {"d": {"albedo": [1, 1, 1]}, "e": {"albedo": [1, 1, 1], "emission": [1, 1, 1]}},
                              "objects": [{"type": "sphere", "center": [0, 0, 5], "radius": 1, "material": "d"},
                                          {"type": "sphere", "center": [0, 0, 5], "radius": 1e-21, "material": "e"}])"),
               "/objects/1", "past the largest 32-bit float");
  EXPECT_NO_THROW(parse_scene(with_camera(R"("materials": {"e": {"albedo": [1, 1, 1], "emission": [1, 1, 1]},
                                                           "f": {"albedo": [1, 1, 1], "emission": [1, 1, 1]}},
                                             "objects": [{"type": "sphere", "center": [0, 0, 5], "radius": 1, "material": "e"},
                                                         {"type": "sphere", "center": [0, 0, 5], "radius": 1e-21, "material": "f"}])"),
                              "test.json"));
  // A scene so small that the squared distances the shader divides by are below the smallest
  // normal float; the smallest it takes renders (checks/scale-1e-9.json).
  expect_error(R"({"camera": {"position": [0, 0, -4e-22], "direction": [0, 0, 1], "focal_length": 1},
                  "materials": {"m": {"albedo": [1, 1, 1]}},
                  "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1e-22, "material": "m"}]})",
               "the scene reaches only 4e-22 from the origin", "at least 1e-9");
  EXPECT_NO_THROW(parse_scene(R"({"camera": {"position": [0, 0, 0], "direction": [0, 0, 1], "focal_length": 1}})", "test.json"));
  // Radiance no one scale of floats holds: the brightest more than 1e30 times the dimmest.
  expect_error(with_camera(R"("background": [3e38, 3e38, 3e38],
                              "lights": [{"type": "point", "position": [0, 1, 0], "intensity": [1, 0, 0]}])"),
               "/lights/0/intensity, 1, is more than 1e30 times dimmer", "(/background, 3e+38)");
  expect_error(with_camera(R"("background": [1e-39, 0, 0], "materials": {"hot": {"albedo": [1, 1, 1], "emission": [0, 2e-9, 0]}})"),
               "/background, 1e-39, is more than 1e30 times dimmer", "(material \"hot\"'s emission, 2e-09)");
  EXPECT_NO_THROW(parse_scene(with_camera(R"("background": [3e29, 3e29, 3e29],
                                             "lights": [{"type": "point", "position": [0, 1, 0], "intensity": [1, 0, 0]}])"), "test.json"));
  EXPECT_NO_THROW(parse_scene(with_camera(R"("materials": {"e": {"albedo": [1, 1, 1], "emission": [1e-25, 1e-25, 1e-25]}},
                                             "objects": [{"type": "sphere", "center": [0, 0, 5], "radius": 1e-8, "material": "e"}])"),
                              "test.json"));
}

TEST(SceneTest, CommentsAreAllowed) {
  EXPECT_NO_THROW(parse_scene("{ // a comment\n" + std::string(kCamera) + " /* another */ }", "t.json"));
}

TEST(SceneTest, UnknownKeysWarnWithTheirPath) {
  const Scene scene = parse_scene(with_camera(R"("lihgts": [], "image": {"widht": 3})"), "t.json");
  ASSERT_EQ(scene.warnings.size(), 2u);
  EXPECT_NE(scene.warnings[0].find("t.json: /lihgts: unknown key"), std::string::npos) << scene.warnings[0];
  EXPECT_NE(scene.warnings[1].find("/image/widht"), std::string::npos) << scene.warnings[1];
}

TEST(SceneTest, DegenerateTrianglesAreDroppedWithAWarning) {
  const Scene scene = parse_scene(with_camera(R"(
    "materials": {"m": {"albedo": [1, 1, 1]}},
    "objects": [{"type": "triangles", "material": "m", "positions": [[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]],
                 "indices": [[0, 1, 2], [0, 1, 3]]}])"),
                                  "t.json");
  EXPECT_EQ(scene.triangles.size(), 1u);
  ASSERT_FALSE(scene.warnings.empty());
  EXPECT_NE(scene.warnings[0].find("/objects/0/indices: 1 degenerate"), std::string::npos) << scene.warnings[0];
}

TEST(SceneTest, SyntaxErrorsNameLineAndColumn) {
  expect_error("{\n  \"camera\": {\n    \"position\": [0, 0, 0],\n  }\n}", "test.json:4:3:", "syntax error");
  expect_error("", "test.json:1:1:");
  expect_error("{\"camera\": {\"position\": [0, 0", "test.json:1:");
}

TEST(SceneTest, FileErrors) {
  EXPECT_THROW(load_scene("/nonexistent/scene.json"), SceneError);
  EXPECT_THROW(load_scene(VKRAY_SCENE_DIR), SceneError);  // a directory
}

TEST(SceneTest, StructureErrors) {
  expect_error("[]", "top level", "expected an object");
  expect_error("{}", "top level", "missing required key \"camera\"");
  expect_error(R"({"camera": []})", "/camera", "expected an object, got array");
  expect_error(with_camera(R"("objects": {})"), "/objects", "expected an array");
  expect_error(with_camera(R"("lights": [3])"), "/lights/0", "expected an object");
  expect_error(with_camera(R"("materials": [])"), "/materials", "expected an object");
}

TEST(SceneTest, CameraErrors) {
  expect_error(R"({"camera": {"direction": [0, 0, 1], "focal_length": 1}})", "/camera", "\"position\"");
  expect_error(R"({"camera": {"position": [0, 0, 0], "focal_length": 1}})", "/camera", "\"look_at\" (or \"direction\")");
  expect_error(R"({"camera": {"position": [0, 0, 0], "look_at": [0, 0, 1], "direction": [0, 0, 1], "focal_length": 1}})",
               "/camera", "not both");
  expect_error(R"({"camera": {"position": [0, 0, 0], "direction": [0, 0, 0], "focal_length": 1}})", "/camera/direction",
               "zero length");
  expect_error(R"({"camera": {"position": [1, 1, 1], "look_at": [1, 1, 1], "focal_length": 1}})", "/camera/look_at",
               "equals the camera position");
  expect_error(R"({"camera": {"position": [0, 0, 0], "direction": [0, 0, 1], "up": [0, 0, -2], "focal_length": 1}})",
               "/camera/up", "parallel");
  expect_error(R"({"camera": {"position": [0, 0, 0], "direction": [0, 1, 0], "focal_length": 1}})", "/camera",
               "default up");
  expect_error(R"({"camera": {"position": [0, 0, 0], "direction": [0, 0, 1], "up": [0, 0, 0], "focal_length": 1}})",
               "/camera/up", "zero length");
  expect_error(R"({"camera": {"position": [0, 0, 0], "direction": [0, 0, 1]}})", "/camera", "vertical_fov");
  expect_error(R"({"camera": {"position": [0, 0, 0], "direction": [0, 0, 1], "vertical_fov": 180}})",
               "/camera/vertical_fov", "(0, 180)");
  expect_error(R"({"camera": {"position": [0, 0, 0], "direction": [0, 0, 1], "focal_length": 0}})",
               "/camera/focal_length", "> 0");
  expect_error(R"({"camera": {"position": [0, 0], "direction": [0, 0, 1], "focal_length": 1}})", "/camera/position",
               "3 numbers");
  expect_error(R"({"camera": {"position": [0, "0", 0], "direction": [0, 0, 1], "focal_length": 1}})",
               "/camera/position/1", "expected a number, got string");
  expect_error(R"({"camera": {"position": [0, 1e39, 0], "direction": [0, 0, 1], "focal_length": 1}})",
               "/camera/position/1", "out of range");
}

TEST(SceneTest, ImageErrors) {
  expect_error(with_camera(R"("image": {"width": 0})"), "/image/width", "1 to 16384");
  expect_error(with_camera(R"("image": {"height": 100000})"), "/image/height", "1 to 16384");
  expect_error(with_camera(R"("image": {"width": 12.5})"), "/image/width");
  expect_error(with_camera(R"("image": {"samples_per_pixel": 0})"), "/image/samples_per_pixel");
  expect_error(with_camera(R"("image": {"samples_per_pixel": 1000000000})"), "/image/samples_per_pixel");
}

TEST(SceneTest, MaterialAndColourErrors) {
  expect_error(with_camera(R"("materials": {"m": {}})"), "/materials/m", "\"albedo\"");
  expect_error(with_camera(R"("materials": {"m": {"albedo": [1, -0.5, 1]}})"), "/materials/m/albedo", "non-negative");
  expect_error(with_camera(R"("ambient": [1, 1])"), "/ambient", "3 numbers");
  expect_error(with_camera(R"("background": "black")"), "/background");
}

TEST(SceneTest, LightErrors) {
  expect_error(with_camera(R"("lights": [{"type": "area", "position": [0, 0, 0], "intensity": [1, 1, 1]}])"),
               "/lights/0/type", "unknown light type");
  expect_error(with_camera(R"("lights": [{"type": "spot", "position": [0, 0, 0], "intensity": [1, 1, 1]}])"),
               "/lights/0", "missing required key \"look_at\" (or \"direction\")");
  expect_error(with_camera(R"("lights": [{"type": "spot", "position": [0, 0, 0], "direction": [0, 0, 1], "intensity": [1, 1, 1],
                                          "cutoff_angle": 0}])"),
               "/lights/0/cutoff_angle", "expected degrees in (0, 180]");
  expect_error(with_camera(R"("lights": [{"type": "spot", "position": [0, 0, 0], "direction": [0, 0, 1], "intensity": [1, 1, 1],
                                          "beam_width": -1}])"),
               "/lights/0/beam_width", "expected degrees from 0 to the cutoff_angle (20)");
  expect_error(with_camera(R"("lights": [{"type": "directional", "direction": [0, 0, 1]}])"), "/lights/0", "\"irradiance\"");
  expect_error(with_camera(R"("lights": [{"position": [0, 0, 0], "intensity": [1, 1, 1]}])"), "/lights/0", "\"type\"");
  expect_error(with_camera(R"("lights": [{"type": "point", "position": [0, 0, 0]}])"), "/lights/0", "\"intensity\"");
  expect_error(with_camera(R"("lights": [{"type": "point", "position": [0, 0, 0], "intensity": [1, 1, 1], "power": [1, 1, 1]}])"),
               "/lights/0", "not both");
  expect_error(with_camera(R"("lights": [{"type": "point", "position": [0, 0, 0], "intensity": [1, -1, 1]}])"),
               "/lights/0/intensity", "non-negative");
}

TEST(SceneTest, ObjectErrors) {
  const std::string m = R"("materials": {"m": {"albedo": [1, 1, 1]}}, )";
  expect_error(with_camera(m + R"("objects": [{"center": [0, 0, 0]}])"), "/objects/0", "\"type\"");
  expect_error(with_camera(m + R"("objects": [{"type": "cube"}])"), "/objects/0/type", "unknown object type");
  expect_error(with_camera(m + R"("objects": [{"type": "sphere", "center": [0, 0, 0], "radius": -1, "material": "m"}])"),
               "/objects/0/radius", "> 0");
  expect_error(with_camera(m + R"("objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 0, "material": "m"}])"),
               "/objects/0/radius", "> 0");
  expect_error(with_camera(m + R"("objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "x"}])"),
               "/objects/0/material", "undefined material \"x\"");
  expect_error(with_camera(m + R"("objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1}])"), "/objects/0",
               "\"material\"");
  expect_error(with_camera(m + R"("objects": [{"type": "triangles", "material": "m", "positions": [[0, 0, 0]], "indices": [[0, 0, 1]]}])"),
               "/objects/0/indices/0/2", "out of range");
  expect_error(with_camera(m + R"("objects": [{"type": "triangles", "material": "m", "positions": [[0, 0, 0]], "indices": [[0, -1, 0]]}])"),
               "/objects/0/indices/0/1", "out of range");
  expect_error(with_camera(m + R"("objects": [{"type": "triangles", "material": "m", "positions": [[0, 0, 0]], "indices": [[0, 0]]}])"),
               "/objects/0/indices/0", "3 vertex indices");
  expect_error(with_camera(m + R"("objects": [{"type": "triangles", "material": "m", "positions": [[0, 0]], "indices": []}])"),
               "/objects/0/positions/0", "3 numbers");
  expect_error(with_camera(m + R"("objects": [{"type": "triangles", "material": "m", "indices": []}])"), "/objects/0",
               "\"positions\"");
}

TEST(SceneTest, TransformErrors) {
  const std::string m = R"("materials": {"m": {"albedo": [1, 1, 1]}}, )";
  const std::string sphere = R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m", "transform": )";
  expect_error(with_camera(m + R"("objects": [)" + sphere + R"({"scale": [1, 2, 1]}}])"), "/objects/0/transform",
               "uniform scale");
  expect_error(with_camera(m + R"("objects": [)" + sphere + R"({"matrix": [1, 0, 0, 0,  0, 2, 0, 0,  0, 0, 1, 0,  0, 0, 0, 1]}}])"),
               "/objects/0/transform", "uniform scale");
  expect_error(with_camera(m + R"("objects": [)" + sphere + R"({"scale": 0}}])"), "/objects/0/transform/scale", "non-zero");
  expect_error(with_camera(m + R"("objects": [)" + sphere + R"({"matrix": [1, 0, 0]}}])"), "/objects/0/transform/matrix",
               "16 numbers");
  expect_error(with_camera(m + R"("objects": [)" + sphere + R"({"matrix": [1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0,  0, 0, 1, 1]}}])"),
               "/objects/0/transform/matrix", "affine");
  expect_error(with_camera(m + R"("objects": [)" + sphere + R"({"matrix": [1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 0, 0,  0, 0, 0, 1]}}])"),
               "/objects/0/transform/matrix", "singular");
  expect_error(with_camera(m + R"("objects": [)" + sphere + R"({"matrix": [1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0,  0, 0, 0, 1], "translate": [1, 0, 0]}}])"),
               "/objects/0/transform", "not both");
  expect_error(with_camera(m + R"("objects": [)" + sphere + R"({"rotate": [0, 0]}}])"), "/objects/0/transform/rotate",
               "3 numbers");
}

// JSON as vkray reads it: nesting and duplicate keys are refused by their JSON pointer, and values
// are quoted briefly. A deep document overflowed the stack while its error message was built.
TEST(SceneTest, JsonNestingHasALimit) {
  const auto nested = [](size_t levels) { return std::string(levels, '[') + std::string(levels, ']'); };
  // "camera" and "position" take two levels: the array may nest 62 deep.
  EXPECT_NO_THROW(parse_scene(with_camera("\"x\": " + nested(kMaxJsonDepth - 1)), "test.json"));  // a warning only
  expect_error(with_camera("\"x\": " + nested(kMaxJsonDepth)), "test.json: /x/0/0", "nesting deeper than 64 levels");
  expect_error(nested(1'000'000), "test.json: /0/0/0", "nesting deeper than 64 levels");
  expect_error(std::string(1'000'000, '{'), "test.json:1:2:", "syntax error");
}

TEST(SceneTest, DuplicateKeysAreRefused) {
  expect_error(with_camera(R"("image": {"width": 8, "width": 9})"), "test.json: /image: ", "the key \"width\" is given twice");
  expect_error(with_camera(R"("objects": [1, [2, {"a": 1, "a": 2}]])"), "test.json: /objects/1/1: ", "\"a\" is given twice");
  expect_error(R"({"camera": {}, "camera": {}})", "test.json: top level: ", "the key \"camera\" is given twice");
  // The same key in different objects is fine.
  EXPECT_NO_THROW(parse_scene(with_camera(R"("materials": {"a": {"albedo": [1, 1, 1]}, "b": {"albedo": [1, 1, 1]}})"), "test.json"));
}

TEST(SceneTest, ValuesAreQuotedBriefly) {
  EXPECT_EQ(brief(nlohmann::json::parse("[1, 2, 3]")), "[1, 2, 3]");
  EXPECT_EQ(brief(nlohmann::json("\u001b[31m")), "\"\\u001b[31m\"");
  std::string long_array = "[1";
  for (int i = 0; i < 100000; ++i) long_array += ", 1";
  long_array += "]";
  EXPECT_LE(brief(nlohmann::json::parse("[" + std::string(100, '[') + std::string(100, ']') + "]")).size(), 63u);
  EXPECT_LE(brief(nlohmann::json::parse(long_array)).size(), 63u);
}

// Coordinates whose sums or products overflow a float, although each number is finite, are
// refused at the key that makes them (docs/limits.md), before any renderer sees them.
TEST(SceneTest, CoordinatesPastTheLimitAreRefused) {
  const std::string material = R"("materials": {"m": {"albedo": [1, 1, 1]}}, )";
  expect_error(with_camera(material + R"("objects": [{"type": "sphere", "center": [1e9, 0, 0], "radius": 1e3, "material": "m"}])"),
               "/objects/0", "the sphere's bounding box has a coordinate of 1e+09");
  EXPECT_NO_THROW(parse_scene(with_camera(material + R"("objects": [{"type": "sphere", "center": [5e8, 0, 0], "radius": 1, "material": "m"}])"), "t.json"));
  expect_error(with_camera(material + R"("objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m", "transform": {"scale": 2e9}}])"),
               "/objects/0", "has a coordinate of 2e+09");
  expect_error(with_camera(material + R"("objects": [{"type": "triangles", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "indices": [[0, 1, 2]], "material": "m", "transform": {"translate": [0, -3e38, 0], "scale": 3e38}}])"),
               "/objects/0/indices", "triangle 0 (after the transform) has a coordinate of");
  expect_error(with_camera(R"("lights": [{"type": "point", "position": [0, 0, 1e10], "intensity": [1, 1, 1]}])"),
               "/lights/0/position", "the light has a coordinate of 1e+10");
  // A tiny uniform scale is still a uniform scale; the radius it leaves must be positive.
  expect_error(with_camera(material + R"("objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1e-30, "material": "m", "transform": {"scale": 1e-30}}])"),
               "/objects/0", "scales the sphere's radius to zero");
}

TEST(SceneTest, FocalLengthsThatOverflowAreRefused) {
  const std::string camera = R"({"camera": {"position": [0, 0, 0], "direction": [0, 0, 1], )";
  expect_error(camera + R"("focal_length": 3e38}})", "/camera/focal_length", "expected at most 1e6");
  expect_error(camera + R"("vertical_fov": 1e-30}})", "/camera/vertical_fov", "field of view this narrow");
  EXPECT_NO_THROW(parse_scene(camera + R"("focal_length": 1e6}})", "t.json"));
  EXPECT_NO_THROW(parse_scene(camera + R"("vertical_fov": 1e-4}})", "t.json"));
}

}  // namespace
}  // namespace vkray
