// Rendered pixels against values worked out by hand from the shading contract, for both renderers:
// the GPU path and the CPU reference must each get them right on their own.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <string>
#include <vector>

#include <algorithm>

#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include "base/errors.h"
#include "packing/inline_scene.h"
#include "session/session.h"
#include "support/gpu_fixture.h"
#include "support/temp_dir.h"
#include "load/scene_loader.h"

namespace vkray::test {
namespace {

constexpr double kPi = std::numbers::pi;

using RenderTest = GpuTest;

void expect_radiance(glm::vec3 actual, glm::dvec3 expected, const char* what) {
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(actual[c], expected[c], 1e-5 + 1e-4 * expected[c]) << what << ", channel " << c;
}

// ---- The Cornell box at 256x256: camera (0,0,-3) looking along +z, up (0,-1,0), F = 256 px, so pixel
// (i, j) looks along (x, -y, 256) with x = i + 0.5 - 128, y = 128 - (j + 0.5). One light of power
// 14 (I = 14/4pi) at (0,-0.5,-0.7), ambient 0.1. ----------------------------------------------------
enum class Renderer { gpu_bvh, gpu_inline, cpu };
const char* name(Renderer r) { return r == Renderer::cpu ? "cpu" : r == Renderer::gpu_inline ? "gpu_inline" : "gpu"; }
void PrintTo(Renderer r, std::ostream* os) { *os << name(r); }

class CornellTest : public RenderTest, public ::testing::WithParamInterface<Renderer> {
 protected:
  void SetUp() override {
    RenderTest::SetUp();
    scene_ = load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "cornell.json");
    RenderOptions options;
    options.inline_scene = GetParam() == Renderer::gpu_inline ? InlineScene::always : InlineScene::never;
    image_ = render(scene_, {256, 256, 1}, options, /*cpu=*/GetParam() == Renderer::cpu);
  }
  void TearDown() override { RenderTest::TearDown(); }
  Scene scene_;
  Image image_;
  const glm::dvec3 camera_{0, 0, -3}, light_{0, -0.5, -0.7};
  const double intensity_ = 14.0 / (4 * kPi), ambient_ = 0.1;
  // Where pixel (i, j)'s ray meets the plane coordinate[axis] = value.
  glm::dvec3 hit_plane(uint32_t i, uint32_t j, int axis, double value) const {
    const glm::dvec3 d(i + 0.5 - 128, -(128 - (j + 0.5)), 256);
    return camera_ + (value - camera_[axis]) / d[axis] * d;
  }
  glm::dvec3 lit(glm::dvec3 albedo, glm::dvec3 x, glm::dvec3 n) const {
    const glm::dvec3 to_light = light_ - x;
    const double r2 = glm::dot(to_light, to_light);
    return albedo * (ambient_ + intensity_ * glm::dot(n, to_light / std::sqrt(r2)) / (kPi * r2));
  }
};

TEST_P(CornellTest, BackWallInFrontOfTheLight) {
  // Pixel (127, 95) looks at the back wall (z = 1) at about (0.008, -0.508): straight ahead of the
  // light, which sees it over the top of the tall block (its top is at y = -0.19).
  const glm::dvec3 x = hit_plane(127, 95, 2, 1.0);
  expect_radiance(image_.at(127, 95), lit({0.75, 0.75, 0.75}, x, {0, 0, -1}), "back wall");
}

TEST_P(CornellTest, CeilingRightAboveTheLight) {
  // Pixel (127, 20) meets the ceiling (y = -1) at z = -0.65, 0.5 above the light: nearly normal incidence.
  const glm::dvec3 x = hit_plane(127, 20, 1, -1.0);
  expect_radiance(image_.at(127, 20), lit({0.15, 0.75, 0.75}, x, {0, 1, 0}), "ceiling");
}

TEST_P(CornellTest, LeftWallLit) {
  const glm::dvec3 x = hit_plane(20, 128, 0, -1.0);
  expect_radiance(image_.at(20, 128), lit({0.75, 0.15, 0.75}, x, {1, 0, 0}), "left wall");
}

TEST_P(CornellTest, FloorInTheTallBlocksShadowGetsAmbientOnly) {
  // Pixel (60, 200) meets the floor (y = 1) at (-0.931, 1, 0.531). The segment to the light is inside
  // the tall block's footprint at 40% of the way (x = -0.559, z = 0.039, y = 0.4, below its top): shadow.
  const glm::dvec3 x = hit_plane(60, 200, 1, 1.0);
  ASSERT_NEAR(x.x, -0.931, 1e-3);
  expect_radiance(image_.at(60, 200), glm::dvec3(0.15, 0.75, 0.15) * ambient_, "floor in shadow");
}

TEST_P(CornellTest, FloorInTheOpenIsLit) {
  // Pixel (128, 236): floor at (0.004, 1, -0.630), in front of both blocks.
  const glm::dvec3 x = hit_plane(128, 236, 1, 1.0);
  expect_radiance(image_.at(128, 236), lit({0.15, 0.75, 0.15}, x, {0, -1, 0}), "lit floor");
}

// ---- A sphere, built in the test -------------------------------------------------------------------
Scene one_sphere_scene() {
  return parse_scene(R"({
    "camera": {"position": [0, 0, 0], "direction": [0, 0, 1], "up": [0, 1, 0], "focal_length": 2},
    "background": [0.2, 0.3, 0.4], "ambient": [0.05, 0.05, 0.05],
    "materials": {"m": {"albedo": [0.8, 0.5, 0.2]}},
    "lights": [{"type": "point", "position": [0, 3, 0], "intensity": [20, 20, 20]}],
    "objects": [{"type": "sphere", "center": [0, 0, 4], "radius": 1, "material": "m"}]})", "sphere.json");
}

TEST_F(RenderTest, SphereShadingAndBackground) {
  const Scene scene = one_sphere_scene();
  for (const bool cpu : {false, true}) {
    SCOPED_TRACE(cpu ? "CPU reference" : "GPU");
    const Image image = render(scene, {64, 64, 1}, {}, cpu);
    expect_radiance(image.at(0, 0), {0.2, 0.3, 0.4}, "corner: background");

    // Pixel (31, 20): F = 128 px; right = f x up = (-1, 0, 0), up = (0, 1, 0).
    const glm::dvec3 d = glm::normalize(glm::dvec3(-(31 + 0.5 - 32), 32 - 20.5, 128));
    const glm::dvec3 oc = -glm::dvec3(0, 0, 4);
    const double b = glm::dot(d, oc), c = glm::dot(oc, oc) - 1;
    const double t = -b - std::sqrt(b * b - c);
    const glm::dvec3 x = t * d, n = x - glm::dvec3(0, 0, 4);
    const glm::dvec3 to_light = glm::dvec3(0, 3, 0) - x;
    const double r2 = glm::dot(to_light, to_light);
    const double cos_theta = glm::dot(n, to_light / std::sqrt(r2));
    ASSERT_GT(cos_theta, 0.1);
    expect_radiance(image.at(31, 20), glm::dvec3(0.8, 0.5, 0.2) * (0.05 + 20 * cos_theta / (kPi * r2)), "sphere top");
  }
}

TEST_F(RenderTest, OnePipelineServesScenesWithAndWithoutSpheres) {
  // A scene without spheres gets a pipeline variant without the sphere test (gpu::ShaderVariant);
  // compiled first, it must not serve the sphere scene after it.
  const Scene no_spheres = load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "cornell.json");
  const Scene spheres = one_sphere_scene();
  const Image before = render(no_spheres, {32, 32, 1});
  const Image sphere = render(spheres, {32, 32, 1});
  const Image sphere_reference = render(spheres, {32, 32, 1}, {}, /*cpu=*/true);
  expect_radiance(sphere.at(16, 16), glm::dvec3(sphere_reference.at(16, 16)), "sphere center");
  EXPECT_NE(sphere.at(16, 16), glm::vec3(0.2f, 0.3f, 0.4f)) << "the sphere is missing";
  const Image after = render(no_spheres, {32, 32, 1});
  EXPECT_EQ(before.pixels, after.pixels);
}

TEST_F(RenderTest, OnePipelineServesPathsWithAndWithoutPointLightsAndASky) {
  // Point lights, and a sky that paths sample as a light, are pipeline variants too: compiled for a
  // scene with neither, the pipeline must not serve one with both (the sphere would be lit by
  // neither).
  Scene lit = one_sphere_scene();
  lit.integrator.type = Integrator::Type::path;
  lit.ambient = glm::vec3(0.0f);
  Scene dark = lit;
  dark.lights.clear();
  dark.background = glm::vec3(0.0f);
  const Image before = render(dark, {32, 32, 4});
  const glm::dvec3 gpu = image_mean(render(lit, {32, 32, 4})), cpu = image_mean(render(lit, {32, 32, 4}, {}, /*cpu=*/true));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(gpu[c], cpu[c], 0.01 * cpu[c]) << "channel " << c;
  EXPECT_GT(cpu.r, 0.2);  // the sky and the light both reach it
  const Image after = render(dark, {32, 32, 4});
  EXPECT_EQ(before.pixels, after.pixels);
}

TEST_F(RenderTest, TilesCoverTheImageExactly) {
  const Scene scene = load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "cornell.json");
  const Image whole = render(scene, {100, 76, 2});
  RenderOptions options;
  options.tile_side = 16;  // 7 x 5 tiles, the last row and column partial
  const Image tiled = render(scene, {100, 76, 2}, options);
  ASSERT_EQ(whole.pixels.size(), tiled.pixels.size());
  for (size_t i = 0; i < whole.pixels.size(); ++i) ASSERT_EQ(whole.pixels[i], tiled.pixels[i]) << "pixel " << i;
  // Tiles smaller than a workgroup: 5 x 3 of them, 4 pixels a side.
  options.tile_side = 4;
  const Image small_whole = render(scene, {20, 12, 1});
  const Image small_tiled = render(scene, {20, 12, 1}, options);
  EXPECT_EQ(small_whole.pixels, small_tiled.pixels);
}

// Submissions sized by time (gpu/tiling.h): at 256 spp the first one is 64x64 pixels' worth (the
// cost model), a band of 32 rows of this 128x96 image, and the sizer takes the rest in bands of its
// choosing, through both output slots. Whatever it chose, the image is the one traced in one square.
TEST_F(RenderTest, SubmissionsSizedByTimeGiveTheImageOfOneSubmission) {
  const auto scene = std::make_shared<const Scene>(load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "cornell.json"));
  const DeviceScene on_device = session().upload(scene);
  RenderOptions options;
  options.width = 128;
  options.height = 96;
  options.samples_per_pixel = 256;
  options.inline_scene = InlineScene::never;
  std::vector<uint32_t> progress;
  options.progress = [&](const char* unit, uint32_t done, uint32_t total) {
    EXPECT_STREQ(unit, "pixels");
    EXPECT_EQ(total, 128u * 96u);
    progress.push_back(done);
  };
  const RenderResult sized = session().render(on_device, options);
  EXPECT_GE(sized.stats.tiles, 2u);
  ASSERT_EQ(progress.size(), sized.stats.tiles);
  EXPECT_TRUE(std::is_sorted(progress.begin(), progress.end()));
  EXPECT_EQ(progress.back(), 128u * 96u);
  options.progress = nullptr;
  options.tile_side = 128;  // one square: the whole image
  const RenderResult one = session().render(on_device, options);
  EXPECT_EQ(one.stats.tiles, 1u);
  EXPECT_EQ(sized.stats.rays, one.stats.rays);
  ASSERT_EQ(sized.image.pixels.size(), one.image.pixels.size());
  for (size_t i = 0; i < one.image.pixels.size(); ++i) ASSERT_EQ(sized.image.pixels[i], one.image.pixels[i]) << "pixel " << i;
}

// ---- A small scene compiled into the shader (InlineScene) --------------------------------------------
RenderOptions path(InlineScene inline_scene) {
  RenderOptions options;
  options.inline_scene = inline_scene;
  return options;
}

TEST_F(RenderTest, SceneCompiledInMatchesTheBvhPixelForPixel) {
  // The same triangle and sphere tests, and the same tie rule, so the same image; a difference means
  // the generated code lost or misplaced a primitive.
  for (const char* file : {"cornell.json", "cornell-spheres.json"}) {
    const Scene scene = load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / file);
    const Image bvh = render(scene, {96, 64, 2}, path(InlineScene::never));
    const Image compiled_in = render(scene, {96, 64, 2}, path(InlineScene::always));
    ASSERT_EQ(bvh.pixels.size(), compiled_in.pixels.size());
    size_t differ = 0;
    for (size_t i = 0; i < bvh.pixels.size(); ++i) differ += bvh.pixels[i] != compiled_in.pixels[i];
    EXPECT_EQ(differ, 0u) << file;
  }
}

TEST_F(RenderTest, ConstantsAppliedOnTheHostGiveTheDriversPixels) {
  // gpu/specialize.h removes the code a variant cannot reach before the driver sees it; the driver,
  // given the whole module and the values (VKRAY_SPECIALIZE=driver), must render the same bytes.
  struct Case {
    const char* file;
    InlineScene inline_scene;
  };
  const Case cases[] = {{"cornell.json", InlineScene::never}, {"cornell.json", InlineScene::always},
                        {"cornell-glass.json", InlineScene::never}, {"rough-spheres.json", InlineScene::never}};
  std::vector<Image> host;
  for (const Case& c : cases) {
    RenderOptions options;
    options.inline_scene = c.inline_scene;
    host.push_back(render(load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / c.file), {64, 48, 2}, options));
  }
  ASSERT_EQ(setenv("VKRAY_SPECIALIZE", "driver", 1), 0);
  SessionOptions session_options;
  session_options.validation = true;
  session_options.shader_dir = shader_dir();
  Session driver(session_options);
  for (size_t i = 0; i < std::size(cases); ++i) {
    RenderOptions options = with_image({}, {64, 48, 2});
    options.inline_scene = cases[i].inline_scene;
    const auto scene = std::make_shared<const Scene>(load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / cases[i].file));
    const Image image = driver.render(driver.upload(scene), options).image;
    ASSERT_EQ(image.pixels.size(), host[i].pixels.size());
    size_t differ = 0;
    for (size_t p = 0; p < image.pixels.size(); ++p) differ += image.pixels[p] != host[i].pixels[p];
    EXPECT_EQ(differ, 0u) << cases[i].file << (cases[i].inline_scene == InlineScene::always ? ", compiled in" : "");
  }
  unsetenv("VKRAY_SPECIALIZE");
  driver.close();
}

TEST_F(RenderTest, AnUnknownPlaceToSpecializeIsAUsageError) {
  ASSERT_EQ(setenv("VKRAY_SPECIALIZE", "gpu", 1), 0);
  SessionOptions session_options;
  session_options.shader_dir = shader_dir();
  Session session(session_options);
  try {
    session.compile_shaders();
    ADD_FAILURE() << "no error";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("VKRAY_SPECIALIZE is 'gpu'; it takes host (the default) or driver"), std::string::npos) << e.what();
  }
  unsetenv("VKRAY_SPECIALIZE");
}

TEST_F(RenderTest, PolicyChoosesThePath) {
  const auto cornell = std::make_shared<const Scene>(load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "cornell.json"));
  const DeviceScene small = session().upload(cornell);
  const auto chooses = [&](const DeviceScene& scene, ImageSettings image, InlineScene policy) {
    return session().compiles_scene_in(scene, with_image(path(policy), image));
  };
  // auto: from 2^17 camera rays a primitive under `path`, 4x that under `direct`, where only up to 32
  // primitives (session.cpp). The Cornell box's 30 triangles under `direct`: from 15.7 M.
  EXPECT_FALSE(chooses(small, {512, 512, 1}, InlineScene::automatic));
  EXPECT_FALSE(chooses(small, {2048, 2048, 3}, InlineScene::automatic));  // 12.6 M
  EXPECT_TRUE(chooses(small, {2048, 2048, 4}, InlineScene::automatic));   // 16.8 M
  EXPECT_TRUE(chooses(small, {8, 8, 1}, InlineScene::always));
  EXPECT_FALSE(chooses(small, {4096, 4096, 1}, InlineScene::never));
  // Under `path`: from 3.9 M.
  Scene traced = *cornell;
  traced.integrator.type = Integrator::Type::path;
  const DeviceScene small_path = session().upload(std::make_shared<const Scene>(traced));
  EXPECT_FALSE(chooses(small_path, {1024, 1024, 3}, InlineScene::automatic));  // 3.1 M
  EXPECT_TRUE(chooses(small_path, {1024, 1024, 4}, InlineScene::automatic));   // 4.2 M
  // 33 triangles: under `direct` never, under `path` from 4.3 M.
  for (const auto type : {Integrator::Type::direct, Integrator::Type::path}) {
    Scene more = *cornell;
    more.integrator.type = type;
    while (more.triangles.size() < 33) more.triangles.push_back(more.triangles.back());
    const DeviceScene uploaded = session().upload(std::make_shared<const Scene>(more));
    EXPECT_FALSE(chooses(uploaded, {2048, 1024, 2}, InlineScene::automatic));  // 4.2 M
    EXPECT_EQ(chooses(uploaded, {4096, 4096, 4}, InlineScene::automatic), type == Integrator::Type::path);
  }
  // 64 triangles under `path`: past 44, the rays needed grow with the square, to 17.7 M.
  Scene most = traced;
  while (most.triangles.size() < 64) most.triangles.push_back(most.triangles.back());
  const DeviceScene uploaded = session().upload(std::make_shared<const Scene>(most));
  EXPECT_FALSE(chooses(uploaded, {4096, 4096, 1}, InlineScene::automatic));  // 16.8 M
  EXPECT_TRUE(chooses(uploaded, {2048, 2048, 5}, InlineScene::automatic));   // 21.0 M

  Scene larger = *cornell;  // one triangle over the limit
  while (larger.triangles.size() <= gpu::kMaxInlinePrimitives) larger.triangles.push_back(larger.triangles.back());
  const DeviceScene large = session().upload(std::make_shared<const Scene>(larger));
  EXPECT_FALSE(chooses(large, {4096, 4096, 1}, InlineScene::always));
  EXPECT_FALSE(session().render(large, with_image(path(InlineScene::always), {16, 16, 1})).stats.inline_scene);
  EXPECT_TRUE(session().render(small, with_image(path(InlineScene::always), {16, 16, 1})).stats.inline_scene);
}

TEST_F(RenderTest, WithoutShadowRaysEveryLightIsVisible) {
  // RenderOptions::shadows = false (vkray bench's camera rays alone) is a pipeline without the
  // shadow-ray code (VKRAY_SPEC_SHADOWS): the floor in the tall block's shadow (pixel (60, 200) at
  // 256^2, CornellTest) is lit as the CPU reference without shadow rays has it, and only camera
  // rays are counted; with shadows again, the same pipeline object serves the shadowed image.
  const Scene scene = load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "cornell.json");
  RenderOptions reference_options;
  reference_options.shadows = false;
  const Image reference = render(scene, {256, 256, 1}, reference_options, /*cpu=*/true);
  const DeviceScene on_device = session().upload(std::make_shared<const Scene>(scene));
  for (const auto inline_scene : {InlineScene::never, InlineScene::always}) {
    RenderOptions options = with_image(path(inline_scene), {256, 256, 1});
    options.shadows = false;
    const RenderResult unshadowed_run = session().render(on_device, options);
    const Image& unshadowed = unshadowed_run.image;
    EXPECT_EQ(unshadowed_run.stats.rays, 256u * 256u);
    expect_radiance(unshadowed.at(60, 200), glm::dvec3(reference.at(60, 200)), "floor behind the tall block, lit");
    EXPECT_GT(unshadowed.at(60, 200).g, 1.2f * 0.75f * 0.1f) << "still in shadow (ambient only)";
    options.shadows = true;
    const RenderResult shadowed_run = session().render(on_device, options);
    const Image& shadowed = shadowed_run.image;
    EXPECT_GT(shadowed_run.stats.rays, 256u * 256u);
    expect_radiance(shadowed.at(60, 200), glm::dvec3(0.15, 0.75, 0.15) * 0.1, "floor in shadow");
  }
}

TEST_F(RenderTest, GeneratedCodeThatDoesNotCompileIsAShaderError) {
  // A shader folder whose traversal.glsl no longer gives the generated code what it calls: its own
  // SPIR-V compiles (nothing after the include calls shear_point), the scene's does not, and the
  // message says where.
  TempDir dir;
  std::filesystem::copy(VKRAY_SHADER_DIR, dir.path(), std::filesystem::copy_options::recursive);
  std::string text;
  {
    std::ifstream in(dir / "traversal.glsl");
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::string include = "#include \"inline_scene.glsl\"";
  ASSERT_NE(text.find(include), std::string::npos);
  text.replace(text.find(include), 0, "#define shear_point(a, k, s) missing_function(a)\n");
  std::ofstream(dir / "traversal.glsl") << text;

  SessionOptions options;
  options.validation = true;
  options.shader_dir = dir.path();
  Session broken(options);
  {
    const DeviceScene scene =
        broken.upload(std::make_shared<const Scene>(load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "cornell.json")));
    EXPECT_NO_THROW(broken.prepare(scene, with_image(path(InlineScene::never), {64, 64, 1})));
    try {
      broken.prepare(scene, with_image(path(InlineScene::always), {64, 64, 1}));
      ADD_FAILURE() << "no ShaderError";
    } catch (const ShaderError& e) {
      EXPECT_NE(std::string(e.what()).find("inline_scene.glsl (generated):"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("missing_function"), std::string::npos) << e.what();
    }
  }
  broken.close();
}

INSTANTIATE_TEST_SUITE_P(Renderers, CornellTest, ::testing::Values(Renderer::gpu_bvh, Renderer::gpu_inline, Renderer::cpu),
                         [](const ::testing::TestParamInfo<Renderer>& param) { return name(param.param); });

}  // namespace
}  // namespace vkray::test
