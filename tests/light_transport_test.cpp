// Light transport against physics, on both renderers, with no other renderer to trust: a white
// furnace, a diffuse plane under the sky, glass that loses nothing, a symmetric room; the direct
// model against paths of two vertices; and proof that parity catches a 2% energy error, a missing
// bounce and a wrong Fresnel term in the shader.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "support/parity_run.h"
#include "support/temp_dir.h"
#include "load/scene_loader.h"

namespace vkray::test {
namespace {

// Expects each channel of the image's mean within `relative` of `expected`.
void expect_mean(const Image& image, glm::dvec3 expected, double relative, const char* what) {
  const glm::dvec3 m = image_mean(image);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(m[c], expected[c], relative * expected[c]) << what << ", channel " << c;
}

class LightTransportTest : public GpuTest {
 protected:
  // Renders on the device and with the CPU reference, and checks both means.
  void expect_both(const std::string& json, const ImageSettings& image, glm::dvec3 expected, double relative) {
    const Scene scene = parse_scene(json, "physics.json");
    expect_mean(render(scene, image), expected, relative, "GPU");
    expect_mean(render(scene, image, {}, true), expected, relative, "CPU");
  }
};

TEST_F(LightTransportTest, WhiteFurnaceGivesEmissionOverOneMinusAlbedo) {
  // Inside a closed sphere of albedo a, emitting E inward everywhere: L = E (1 + a + a^2 + ...) =
  // E / (1 - a), in every direction. Paths of every length count, so this holds the integrator, the
  // light sampling and its MIS weights, and Russian roulette.
  const std::string json = R"({
    "camera": {"position": [0.1, 0.2, 0], "direction": [0, 0, 1], "vertical_fov": 90},
    "integrator": {"type": "path"},
    "materials": {"wall": {"albedo": [0.2, 0.5, 0.8], "emission": [1, 1, 1]}},
    "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "wall", "flip_normals": true}]})";
  expect_both(json, {32, 32, 64}, {1.25, 2.0, 5.0}, 0.02);
}

TEST_F(LightTransportTest, DiffusePlaneUnderTheSkyGivesAlbedoTimesTheSky) {
  // A plane lit by a constant background B over its whole upper hemisphere reflects a B.
  const std::string json = R"({
    "camera": {"position": [0, 1, 0], "direction": [0, -1, 0], "up": [0, 0, 1], "vertical_fov": 30},
    "integrator": {"type": "path"},
    "background": [0.8, 0.6, 0.4],
    "materials": {"ground": {"albedo": [0.5, 0.25, 1.0]}},
    "objects": [{"type": "triangles", "material": "ground", "positions": [[-50, 0, -50], [50, 0, -50], [50, 0, 50], [-50, 0, 50]],
                 "indices": [[0, 1, 2], [0, 2, 3]]}]})";
  expect_both(json, {32, 32, 16}, {0.4, 0.15, 0.4}, 0.01);
}

TEST_F(LightTransportTest, TheSkyLawHoldsAtBothEndsOfTheFloatRange) {
  // The same plane under a sky near the largest float and under one below the smallest normal
  // float: the image is still a B, which a GPU computing the sky's light unscaled overflows or
  // flushes to zero.
  for (const auto& [b, sky] : {std::pair<std::string, double>{"3e38", 3e38}, {"1e-39", 1e-39}}) {
    const std::string json = R"({
      "camera": {"position": [0, 1, 0], "direction": [0, -1, 0], "up": [0, 0, 1], "vertical_fov": 30},
      "integrator": {"type": "path"},
      "background": [)" + b + ", " + b + ", " + b + R"(],
      "materials": {"ground": {"albedo": [0.5, 0.25, 1.0]}},
      "objects": [{"type": "triangles", "material": "ground", "positions": [[-50, 0, -50], [50, 0, -50], [50, 0, 50], [-50, 0, 50]],
                   "indices": [[0, 1, 2], [0, 2, 3]]}]})";
    expect_both(json, {32, 32, 16}, {0.5 * sky, 0.25 * sky, sky}, 0.01);
  }
}

// A closed slab of glass, 2.4 x 2.4 x 0.5, its faces wound so that every normal points out: corner i
// is (x, y, z) = (+-1.2, +-1.2, +-0.25) with the signs of bits 0, 1 and 2 of i.
constexpr const char* kGlassSlab = R"({"type": "triangles", "material": "glass",
    "positions": [[-1.2, -1.2, -0.25], [1.2, -1.2, -0.25], [-1.2, 1.2, -0.25], [1.2, 1.2, -0.25],
                  [-1.2, -1.2, 0.25], [1.2, -1.2, 0.25], [-1.2, 1.2, 0.25], [1.2, 1.2, 0.25]],
    "indices": [[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4], [2, 6, 7], [2, 7, 3],
                [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]]})";

TEST_F(LightTransportTest, GlassLosesNoLight) {
  // Seen through a slab of glass (and a sphere of it), a constant background is the background:
  // what Fresnel reflection takes from one path it gives another, and refraction's radiance
  // scaling (1 / eta^2 going in) is undone going out.
  const std::string json = R"({
    "camera": {"position": [0.3, 0.2, -4], "look_at": [0, 0, 0], "vertical_fov": 40},
    "integrator": {"type": "path"},
    "background": [0.5, 0.7, 0.9],
    "materials": {"glass": {"type": "glass", "ior": 1.5}},
    "objects": [)" + std::string(kGlassSlab) +
                           R"(, {"type": "sphere", "center": [0, 0, 1.5], "radius": 0.8, "material": "glass"}]})";
  expect_both(json, {32, 32, 16}, {0.5, 0.7, 0.9}, 0.01);
}

TEST_F(LightTransportTest, ASymmetricRoomRendersSymmetric) {
  // A room and a light mirror-symmetric about x = 0, seen from on the axis: each pixel's mirror
  // image (column w-1-x) gathers the same light, so the two halves agree within noise.
  const std::string json = R"({
    "camera": {"position": [0, 1, -3], "look_at": [0, 1, 0], "vertical_fov": 40},
    "integrator": {"type": "path"},
    "materials": {"white": {"albedo": [0.7, 0.7, 0.7]}, "lamp": {"albedo": [0, 0, 0], "emission": [4, 4, 4]},
                  "mirror": {"type": "mirror", "reflectance": [0.9, 0.9, 0.9]}},
    "objects": [
      {"type": "triangles", "material": "white", "positions": [[-2, 0, -4], [2, 0, -4], [2, 0, 2], [-2, 0, 2], [-2, 2.5, -4], [2, 2.5, -4], [2, 2.5, 2], [-2, 2.5, 2]],
       "indices": [[0, 1, 2], [0, 2, 3], [4, 6, 5], [4, 7, 6], [0, 3, 7], [0, 7, 4], [1, 5, 6], [1, 6, 2], [3, 2, 6], [3, 6, 7]]},
      {"type": "triangles", "material": "lamp", "positions": [[-1, 2.45, -1], [1, 2.45, -1], [1, 2.45, 1], [-1, 2.45, 1]], "indices": [[0, 1, 2], [0, 2, 3]]},
      {"type": "sphere", "center": [0, 0.6, 0.5], "radius": 0.6, "material": "mirror"}]})";
  const Scene scene = parse_scene(json, "symmetric.json");
  for (const bool cpu : {false, true}) {
    const Image image = render(scene, {32, 32, 256}, {}, cpu);
    glm::dvec3 left(0.0), right(0.0);
    for (uint32_t y = 0; y < 32; ++y)
      for (uint32_t x = 0; x < 16; ++x) {
        left += glm::dvec3(image.at(x, y));
        right += glm::dvec3(image.at(31 - x, y));
      }
    EXPECT_GT(left.g, 10.0);
    EXPECT_NEAR(left.g, right.g, 0.01 * left.g) << (cpu ? "CPU" : "GPU");  // seeds 1 to 3 gave 0.13% to 0.31%
  }
}

TEST_F(LightTransportTest, TheDirectModelIsPathsOfTwoVertices) {
  // With no ambient, diffuse surfaces and an area light, the direct model's image is what paths of
  // max_depth 2 (emission plus direct light) give: two estimators of one integral.
  const std::string room = std::string(R"({
    "camera": {"position": [278, 273, -800], "look_at": [278, 273, 0], "vertical_fov": 39.3},
    "materials": {"white": {"albedo": [0.8, 0.8, 0.8]}, "red": {"albedo": [0.8, 0.1, 0.1]},
                  "light": {"albedo": [0.5, 0.5, 0.5], "emission": [15, 15, 15]}},
    "objects": [
      {"type": "triangles", "material": "light", "positions": [[343, 548, 227], [343, 548, 332], [213, 548, 332], [213, 548, 227]], "indices": [[0, 1, 2], [0, 2, 3]]},
      {"type": "triangles", "material": "white", "positions": [[556, 0, 0], [0, 0, 0], [0, 0, 559], [556, 0, 559], [556, 549, 0], [0, 549, 0], [0, 549, 559], [556, 549, 559]],
       "indices": [[0, 1, 2], [0, 2, 3], [4, 6, 5], [4, 7, 6], [3, 2, 6], [3, 6, 7], [1, 5, 6], [1, 6, 2]]},
      {"type": "sphere", "center": [300, 120, 300], "radius": 120, "material": "red"},
      {"type": "triangles", "material": "red", "positions": [[556, 0, 0], [556, 0, 559], [556, 549, 559], [556, 549, 0]], "indices": [[0, 1, 2], [0, 2, 3]]}])");
  const Scene direct = parse_scene(room + "}", "direct.json");
  const Scene paths = parse_scene(room + R"(, "integrator": {"type": "path", "max_depth": 2}})", "paths.json");
  for (const bool cpu : {false, true}) {
    const glm::dvec3 a = image_mean(render(direct, {32, 32, 256}, {}, cpu)), b = image_mean(render(paths, {32, 32, 256}, {}, cpu));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 0.02 * b[c]) << (cpu ? "CPU" : "GPU") << " channel " << c;
  }
}

TEST_F(LightTransportTest, SeedsGiveIndependentRendersThatAverage) {
  // The same seed renders the same image; another seed another one, and the mean of renders with
  // different seeds is nearer the converged image than either (they can be split across machines).
  const Scene scene = load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "cornell-path.json");
  const auto with_seed = [&](uint32_t seed, uint32_t spp) {
    RenderOptions options;
    options.seed = seed;
    return render(scene, {24, 24, spp}, options);
  };
  // 9 and 1024 samples fill their strata: with 8 of 3 x 3 one cell would be empty in every render alike.
  const Image a = with_seed(1, 9), b = with_seed(2, 9), again = with_seed(1, 9), converged = with_seed(3, 1024);
  EXPECT_EQ(a.pixels, again.pixels);
  EXPECT_NE(a.pixels, b.pixels);
  const auto squared_error = [&](const auto& pixel_of) {
    double sum = 0;
    for (size_t i = 0; i < converged.pixels.size(); ++i) {
      const glm::dvec3 d = pixel_of(i) - glm::dvec3(converged.pixels[i]);
      sum += glm::dot(d, d);
    }
    return sum;
  };
  const double error_a = squared_error([&](size_t i) { return glm::dvec3(a.pixels[i]); });
  const double error_b = squared_error([&](size_t i) { return glm::dvec3(b.pixels[i]); });
  const double error_mean = squared_error([&](size_t i) { return (glm::dvec3(a.pixels[i]) + glm::dvec3(b.pixels[i])) / 2.0; });
  // Independent noise halves the variance of the mean: well below the better of the two.
  EXPECT_LT(error_mean, 0.75 * std::min(error_a, error_b));
}

class LongPathsTest : public ParityTest {};

TEST_F(LongPathsTest, ThousandsOfSamplesOfLongPathsMatchTheReference) {
  // A furnace of albedo 0.9 makes paths of dozens of vertices, each a traversal: far more loop
  // iterations a sample than llvmpipe lets an invocation make (65535), so the renderer must cut
  // the samples into dispatches small enough, or trace a tile again when its loops were cut short.
  const Scene scene = parse_scene(R"({
    "camera": {"position": [0.1, 0.2, 0], "direction": [0, 0, 1], "vertical_fov": 90},
    "integrator": {"type": "path", "rr_depth": 20},
    "materials": {"wall": {"albedo": [0.9, 0.9, 0.9], "emission": [1, 1, 1]},
                  "glass": {"type": "glass", "ior": 1.5}},
    "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "wall", "flip_normals": true},
                {"type": "sphere", "center": [0, 0, 0.5], "radius": 0.2, "material": "glass"}]})",
                                  "long-paths.json");
  const ParityResult r = run(scene, {8, 8, 2048});
  expect_parity(r, "long-paths");
  for (const Image* image : {&r.gpu.image, &r.cpu.image}) expect_mean(*image, {10.0, 10.0, 10.0}, 0.05, "furnace");
}

// ---- Parity catches errors of light transport ---------------------------------------------------------
// The shader with one edit, against the CPU reference: each must fail the noisy images' tolerance.
class BrokenShaderParityTest : public ParityTest {
 protected:
  // A copy of the shaders in which `from` (which must be there) in `file` becomes `to`.
  BrokenShaderParityTest(const char* file, const std::string& from, const std::string& to) {
    std::filesystem::copy(VKRAY_SHADER_DIR, shaders_.path(), std::filesystem::copy_options::recursive);
    std::ifstream in(shaders_.path() / file);
    std::string text((std::istreambuf_iterator<char>(in)), {});
    const size_t at = text.find(from);
    if (at == std::string::npos) {
      missing_ = std::string(file) + " no longer has \"" + from + "\": the test breaks nothing";
      return;
    }
    std::ofstream(shaders_.path() / file) << text.replace(at, from.size(), to);
  }
  void SetUp() override {
    ParityTest::SetUp();  // the session compiles the copy
    if (!missing_.empty()) FAIL() << missing_;
  }
  std::filesystem::path shader_dir() const override { return shaders_.path(); }
  void expect_caught(const Scene& scene, const ImageSettings& image) {
    const ParityResult r = run(scene, image);
    EXPECT_TRUE(r.tolerance.stochastic);
    EXPECT_FALSE(r.metrics.pass) << describe_metrics(r.metrics);
  }

 private:
  TempDir shaders_;
  std::string missing_;
};

Scene shipped(const char* name) { return load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / name); }

class TwoPercentDarker : public BrokenShaderParityTest {
 protected:
  TwoPercentDarker()
      : BrokenShaderParityTest("trace.comp", "sum += path.radiance * frame.inv_samples_per_pixel;",
                               "sum += path.radiance * frame.inv_samples_per_pixel * 0.98;") {}
};
TEST_F(TwoPercentDarker, IsCaught) { expect_caught(shipped("cornell-path.json"), {64, 64, 16}); }

class MissingBounce : public BrokenShaderParityTest {
 protected:
  MissingBounce()
      : BrokenShaderParityTest("path.glsl", "if (++p.depth >= uint(frame.max_depth)) return true;",
                               "if (++p.depth + 1u >= uint(frame.max_depth)) return true;") {}
};
TEST_F(MissingBounce, IsCaught) {
  Scene scene = shipped("cornell-path.json");
  scene.integrator.max_depth = 4;  // light after three bounces; the broken shader stops after two
  expect_caught(scene, {64, 64, 16});
}

class WrongFresnel : public BrokenShaderParityTest {
 protected:
  // Only the s-polarized part: off by up to a factor of 2, and right at normal incidence.
  WrongFresnel() : BrokenShaderParityTest("bsdf.glsl", "return 0.5 * (rs * rs + rp * rp);", "return rs * rs;") {}
};
TEST_F(WrongFresnel, IsCaught) { expect_caught(shipped("cornell-glass.json"), {64, 64, 16}); }

class SquaredDensities : public BrokenShaderParityTest {
 protected:
  // The power heuristic as a^2 / (a^2 + b^2): a tiny light seen at a grazing angle has a density
  // whose square overflows, and the weight is inf / inf.
  SquaredDensities()
      : BrokenShaderParityTest("path.glsl", "return larger > 0.0 ? (a >= b ? w_larger : 1.0 - w_larger) : 1.0;",
                               "return (a * a) / (a * a + b * b);") {}
};
TEST_F(SquaredDensities, IsCaught) {
  expect_caught(load_scene(std::filesystem::path(VKRAY_CHECK_DIR) / "lights-at-float-limits.json"), {96, 96, 16});
}

}  // namespace
}  // namespace vkray::test
