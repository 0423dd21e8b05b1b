// Environment maps (Scene::environment, Mitsuba's envmap): the file and its checks, the map's
// orientation, the physics of a constant map on both renderers under both integrators, and parity
// catching a density without its sin(theta) and a map sampled half a turn from where it is read.
#include <cmath>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#include "base/errors.h"
#include "cpu/environment.h"
#include "image/exr.h"
#include "load/environment_file.h"
#include "load/scene_loader.h"
#include "support/error_of.h"
#include "support/parity_run.h"
#include "support/temp_dir.h"

namespace vkray::test {
namespace {

// A map of `width` x width/2 texels, each `radiance`, written as a 32-bit EXR.
std::filesystem::path write_map(const TempDir& dir, const std::string& name, uint32_t width, glm::vec3 radiance) {
  Image map(width, width / 2);
  for (glm::vec3& p : map.pixels) p = radiance;
  OutputContent content;
  content.full_float = true;
  write_exr(dir / name, map, nullptr, content);
  return dir / name;
}

TEST(EnvironmentFileTest, ARadianceFileAndAnExrOfItAreTheSameMap) {
  const std::filesystem::path hdr = std::filesystem::path(VKRAY_CHECK_DIR) / "environment" / "sky.hdr";
  const auto from_hdr = read_environment_map(hdr, 1.0f);
  EXPECT_EQ(from_hdr->width, 128u);
  EXPECT_EQ(from_hdr->height, 64u);
  TempDir dir;
  OutputContent content;
  content.full_float = true;
  write_exr(dir / "sky.exr", *from_hdr, nullptr, content);
  const auto from_exr = read_environment_map(dir / "sky.exr", 2.0f);
  ASSERT_EQ(from_exr->pixels.size(), from_hdr->pixels.size());
  for (size_t i = 0; i < from_exr->pixels.size(); ++i) ASSERT_EQ(from_exr->pixels[i], 2.0f * from_hdr->pixels[i]) << i;
}

TEST(EnvironmentFileTest, AMapThatIsNotTwoToOneOrHasABadTexelIsRefusedNamingIt) {
  TempDir dir;
  Image square(8, 8);
  OutputContent content;
  content.full_float = true;
  write_exr(dir / "square.exr", square, nullptr, content);
  std::string message = error_of([&] { read_environment_map(dir / "square.exr", 1.0f); });
  EXPECT_NE(message.find("square.exr: an equirectangular map is twice as wide as it is high; this one is 8 x 8"), std::string::npos)
      << message;
  for (const auto& [value, what] : {std::pair<float, std::string>{-1.0f, "is -1 in its G channel"},
                                    {std::nanf(""), "is nan in its G channel"}}) {
    Image map(8, 4);
    map.at(5, 2).g = value;
    write_exr(dir / "bad.exr", map, nullptr, content);
    message = error_of([&] { read_environment_map(dir / "bad.exr", 1.0f); });
    EXPECT_NE(message.find("bad.exr: texel (5, 2) (column, row from the top) " + what), std::string::npos) << message;
  }
  // Finite in the file, past the largest float once scaled.
  Image bright(8, 4);
  bright.at(1, 1) = glm::vec3(3e38f);
  write_exr(dir / "bright.exr", bright, nullptr, content);
  message = error_of([&] { read_environment_map(dir / "bright.exr", 10.0f); });
  EXPECT_NE(message.find("texel (1, 1)"), std::string::npos) << message;
  EXPECT_NE(message.find("at the scale 10"), std::string::npos) << message;
  message = error_of([&] { read_environment_map(dir / "missing.hdr", 1.0f); });
  EXPECT_NE(message.find("missing.hdr: not found"), std::string::npos) << message;
  message = error_of([&] { read_environment_map(dir / "sky.png", 1.0f); });
  EXPECT_NE(message.find("a Radiance .hdr or an OpenEXR .exr file"), std::string::npos) << message;
}

TEST(EnvironmentFileTest, ARadianceFileCutShortOrWithAnEmptyRunIsRefused) {
  // stb_image would decode the first without its missing pixels, and never finish the second.
  TempDir dir;
  const std::filesystem::path sky = std::filesystem::path(VKRAY_CHECK_DIR) / "environment" / "sky.hdr";
  std::ifstream in(sky, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  std::ofstream(dir / "cut.hdr", std::ios::binary) << bytes.substr(0, bytes.size() - 100);
  std::string message = error_of([&] { read_environment_map(dir / "cut.hdr", 1.0f); });
  EXPECT_NE(message.find("cut.hdr: unreadable Radiance pixels (the file ends before its last pixel)"), std::string::npos) << message;
  std::string rle = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 8\n";
  rle += std::string("\x02\x02\x00\x08", 4) + std::string(1, '\0');
  std::ofstream(dir / "empty-run.hdr", std::ios::binary) << rle;
  message = error_of([&] { read_environment_map(dir / "empty-run.hdr", 1.0f); });
  EXPECT_NE(message.find("empty-run.hdr: unreadable Radiance pixels (scanline 0 has a run of length 0)"), std::string::npos) << message;
  std::ofstream(dir / "mid-run.hdr", std::ios::binary) << rle.substr(0, rle.size() - 1) + "\x05\x01";
  message = error_of([&] { read_environment_map(dir / "mid-run.hdr", 1.0f); });
  EXPECT_NE(message.find("mid-run.hdr: unreadable Radiance pixels (the file ends within scanline 0)"), std::string::npos) << message;
}

std::string scene_with_environment(const std::string& environment) {
  return R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "vertical_fov": 40}, "environment": )" + environment + "}";
}

TEST(EnvironmentFileTest, TheSceneKeysAreCheckedAsEveryKeyIs) {
  TempDir dir;
  write_map(dir, "sky.exr", 8, glm::vec3(1.0f));
  const std::filesystem::path file = dir / "scene.json";
  const auto error = [&](const std::string& json) { return error_of([&] { parse_scene(json, file); }); };
  EXPECT_NE(error(scene_with_environment(R"({"file": "sky.exr", "transform": {"scale": 2}})")).find("/environment/transform: an environment's transform is a rotation"),
            std::string::npos);
  EXPECT_NE(error(scene_with_environment(R"({"file": "sky.exr", "transform": {"translate": [0, 1, 0]}})")).find("/environment/transform"),
            std::string::npos);
  EXPECT_NE(error(scene_with_environment(R"({"file": "sky.exr", "scale": -1})")).find("/environment/scale: expected a number >= 0"),
            std::string::npos);
  EXPECT_NE(error(scene_with_environment(R"({"file": "none.hdr"})")).find("/environment/file: " + (dir / "none.hdr").string() + ": not found"),
            std::string::npos);
  EXPECT_NE(error(scene_with_environment(R"({"scale": 1})")).find("/environment: missing required key \"file\""), std::string::npos);
  const std::string both = R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "vertical_fov": 40}, "background": [1, 1, 1],
                              "environment": {"file": "sky.exr"}})";
  EXPECT_NE(error(both).find("give either \"background\" or \"environment\""), std::string::npos);
  // A map given in its place (--environment) replaces the file's own, which is then not read.
  const Scene replaced = parse_scene(scene_with_environment(R"({"file": "none.hdr"})"), file, nullptr, dir / "sky.exr");
  ASSERT_TRUE(replaced.environment);
  EXPECT_EQ(replaced.environment->file, dir / "sky.exr");
  // A quarter turn about y is a rotation: taken, with the file relative to the scene's folder.
  const Scene turned = parse_scene(scene_with_environment(R"({"file": "sky.exr", "transform": {"rotate": [0, 90, 0]}})"), file);
  ASSERT_TRUE(turned.environment);
  EXPECT_EQ(turned.environment->file, dir / "sky.exr");
  EXPECT_NEAR(glm::distance(turned.environment->to_world * glm::vec3(0, 0, 1), glm::vec3(1, 0, 0)), 0.0f, 1e-6f);
}

TEST(EnvironmentFileTest, AGltfFileLitByAMapGetsNoLightAtTheCamera) {
  TempDir dir;
  const std::filesystem::path map = write_map(dir, "sky.exr", 8, glm::vec3(1.0f));
  const std::filesystem::path box = std::filesystem::path(VKRAY_SCENE_DIR) / "gltf" / "BoxTextured" / "glTF-Binary" / "BoxTextured.glb";
  EXPECT_EQ(load_scene(box).lights.size(), 1u);
  const Scene lit = load_scene(box, nullptr, map);
  EXPECT_TRUE(lit.lights.empty());
  ASSERT_TRUE(lit.environment);
  EXPECT_EQ(lit.referenced_files.back(), map);
}

TEST(EnvironmentOrientationTest, DirectionsFallWhereMitsubasEnvmapPutsThem) {
  // A map whose texels are their own numbers: +y is the top row, +x a quarter of the way along
  // (u = atan2(x, -z) / 2 pi), -z the first column, +z the middle one; turned by to_world.
  Image map(8, 4);
  for (uint32_t i = 0; i < 32; ++i) map.pixels[i] = glm::vec3(float(i + 1));
  Environment environment;
  environment.radiance = std::make_shared<const Image>(map);
  const auto texel = [&](const cpu::EnvironmentLight& light, glm::dvec3 d) { return int(light.lookup(glm::normalize(d)).radiance.x) - 1; };
  const cpu::EnvironmentLight plain(environment);
  EXPECT_EQ(texel(plain, {0, 1, 0}) / 8, 0);
  EXPECT_EQ(texel(plain, {0, -1, 0}) / 8, 3);
  EXPECT_EQ(texel(plain, {1, 0.1, 0}), 8 + 2);
  EXPECT_EQ(texel(plain, {0.01, 0.1, -1}), 8 + 0);
  EXPECT_EQ(texel(plain, {-0.01, -0.1, 1}), 16 + 4);
  EXPECT_EQ(texel(plain, {0.01, -0.1, 1}), 16 + 3);
  EXPECT_EQ(texel(plain, {-1, -0.1, 0}), 16 + 6);
  // Turned a quarter about y (+z to +x): what lay toward +x now lies toward -z.
  environment.to_world = glm::mat3(glm::vec3(0, 0, -1), glm::vec3(0, 1, 0), glm::vec3(1, 0, 0));
  const cpu::EnvironmentLight turned(environment);
  EXPECT_EQ(texel(turned, {0.01, 0.1, -1}), 8 + 2);
  // Sampling returns the direction's own texel and density.
  for (const double u : {0.1, 0.37, 0.62, 0.93}) {
    const cpu::EnvironmentLight::Sample s = turned.sample(u, 1 - u);
    const cpu::EnvironmentLight::Lookup l = turned.lookup(s.dir);
    EXPECT_EQ(s.radiance, l.radiance);
    EXPECT_NEAR(s.pdf, l.pdf, 1e-9 * l.pdf);
  }
}

// ---- Physics: a constant map -------------------------------------------------------------------
class EnvironmentPhysicsTest : public GpuTest, public ::testing::WithParamInterface<bool> {
 protected:
  std::string integrator() const { return GetParam() ? R"({"type": "path"})" : R"({"type": "direct"})"; }
  // The image means of both renderers, each channel.
  void expect_means(const Scene& scene, const ImageSettings& image, glm::dvec3 expected, double relative) {
    for (const bool cpu : {false, true}) {
      const glm::dvec3 m = image_mean(render(scene, image, {}, cpu));
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(m[c], expected[c], relative * expected[c]) << (cpu ? "CPU" : "GPU") << ", channel " << c;
    }
  }
  TempDir dir_;
};

TEST_P(EnvironmentPhysicsTest, ADiffuseSphereInAConstantMapShowsAlbedoTimesItsRadiance) {
  // Every point of a convex diffuse sphere sees the map over its whole hemisphere and nothing of the
  // sphere: L = albedo B, under both integrators. The camera sees only the sphere.
  const std::filesystem::path map = write_map(dir_, "grey.exr", 64, glm::vec3(0.5f, 1.0f, 2.0f));
  const Scene scene = parse_scene(R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "vertical_fov": 12},
      "integrator": )" + integrator() + R"(, "environment": {"file": "grey.exr"},
      "materials": {"m": {"albedo": [0.8, 0.5, 0.25]}},
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]})",
                                  dir_ / "furnace.json");
  expect_means(scene, {16, 16, 256}, {0.4, 0.5, 0.5}, 0.01);
}

TEST_P(EnvironmentPhysicsTest, AConstantMapLightsAsTheSameBackgroundDoes) {
  // A floor and two spheres under a constant map of B and under "background": B: the same image (the
  // path integrator samples the background uniformly, the map by its texels' sin(theta)), and under
  // the direct model, lit by the map alone, the map's image equals the path's of two vertices.
  const std::filesystem::path map = write_map(dir_, "sky.exr", 64, glm::vec3(0.6f, 0.8f, 1.0f));
  const std::string rest = R"("camera": {"position": [0, 1.2, 4], "look_at": [0, 0.4, 0], "vertical_fov": 45},
      "materials": {"floor": {"albedo": [0.6, 0.6, 0.6]}, "red": {"albedo": [0.7, 0.2, 0.1]}},
      "objects": [{"type": "triangles", "material": "floor", "positions": [[-3, 0, -3], [3, 0, -3], [3, 0, 3], [-3, 0, 3]],
                   "indices": [[0, 2, 1], [0, 3, 2]]},
                  {"type": "sphere", "center": [-0.5, 0.5, 0], "radius": 0.5, "material": "red"},
                  {"type": "sphere", "center": [0.7, 0.35, 0.4], "radius": 0.35, "material": "floor"}])";
  const std::string integrator_json = GetParam() ? R"({"type": "path"})" : R"({"type": "path", "max_depth": 2})";
  const Scene by_map = parse_scene("{" + rest + R"(, "integrator": )" + (GetParam() ? integrator_json : R"({"type": "direct"})") +
                                       R"(, "environment": {"file": "sky.exr"}})",
                                   dir_ / "map.json");
  const Scene by_background =
      parse_scene("{" + rest + R"(, "integrator": )" + integrator_json + R"(, "background": [0.6, 0.8, 1.0]})", dir_ / "background.json");
  const glm::dvec3 expected = image_mean(render(by_background, {24, 18, 1024}, {}, true));
  expect_means(by_map, {24, 18, 256}, expected, 0.01);
}

TEST_P(EnvironmentPhysicsTest, BsdfSamplingAloneFindsTheSameLight) {
  // The furnace again, the map found by BSDF sampling alone (RenderOptions::sample_environment): the
  // same albedo B on both renderers; the direct model, which samples no BSDF at a diffuse surface,
  // refuses it.
  write_map(dir_, "grey.exr", 64, glm::vec3(0.5f, 1.0f, 2.0f));
  const Scene scene = parse_scene(R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "vertical_fov": 12},
      "integrator": )" + integrator() + R"(, "environment": {"file": "grey.exr"},
      "materials": {"m": {"albedo": [0.8, 0.5, 0.25]}},
      "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]})",
                                  dir_ / "furnace.json");
  RenderOptions options;
  options.sample_environment = false;
  if (!GetParam()) {
    const std::string message = error_of([&] { render(scene, {8, 8, 1}, options); });
    EXPECT_NE(message.find("environment_sampling: \"bsdf\" is for the path integrator"), std::string::npos) << message;
    return;
  }
  for (const bool cpu : {false, true}) {
    const glm::dvec3 m = image_mean(render(scene, {16, 16, 256}, options, cpu));
    const glm::dvec3 expected(0.4, 0.5, 0.5);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(m[c], expected[c], 0.01 * expected[c]) << (cpu ? "CPU" : "GPU") << ", channel " << c;
  }
}

INSTANTIATE_TEST_SUITE_P(Integrators, EnvironmentPhysicsTest, ::testing::Bool(), [](const auto& p) { return p.param ? "Path" : "Direct"; });

// ---- Parity catches a wrong density and a turned map ---------------------------------------------
class DensityWithoutItsJacobian : public BrokenShaderParityTest {
 protected:
  DensityWithoutItsJacobian()
      : BrokenShaderParityTest("environment.glsl", "return EnvironmentSample(dir, texel.rgb, sin_theta > 0.0 ? texel.w / (2.0 * PI * PI * sin_theta) : 0.0);",
                               "return EnvironmentSample(dir, texel.rgb, sin_theta > 0.0 ? texel.w / (2.0 * PI * PI) : 0.0);") {}
};
TEST_F(DensityWithoutItsJacobian, FailsParity) {
  expect_caught_on_check("environment-direct");
  expect_caught_on_check("environment-path");
}

class MapSampledHalfATurnAway : public BrokenShaderParityTest {
 protected:
  MapSampledHalfATurnAway()
      : BrokenShaderParityTest("environment.glsl", "float theta = v * PI, phi = u * (2.0 * PI);", "float theta = v * PI, phi = u * (2.0 * PI) + PI;") {}
};
TEST_F(MapSampledHalfATurnAway, FailsParity) {
  expect_caught_on_check("environment-direct");
  expect_caught_on_check("environment-path");
}

}  // namespace
}  // namespace vkray::test
