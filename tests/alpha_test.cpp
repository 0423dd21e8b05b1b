// Alpha, rendered: what a see-through surface lets through, worked out from the contract (physics
// that needs no other renderer) on both renderers; proof that parity catches mistakes in the alpha
// code (checks/alpha-*.json). The Khronos model that tests alpha modes is in texture_render_test.cpp.
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "load/scene_loader.h"
#include "support/parity_run.h"
#include "support/temp_dir.h"
#include "support/test_assets.h"

namespace vkray::test {
namespace {

const std::string kFloor = (std::filesystem::path(VKRAY_SCENE_DIR) / "meshes/tiled-floor.obj").string();

// A white floor (y = 0) seen from a narrow camera at height 0.5 looking straight down at the origin,
// lit by a point light 2 above it. `materials`: more members of "materials"; `before`, `after`: more
// objects, listed before and after the floor (JSON, each with a leading or trailing comma).
std::string floor_scene(const std::string& materials, const std::string& before = "", const std::string& after = "") {
  return R"({
    "camera": {"position": [0, 0.5, 0.0001], "look_at": [0, 0, 0], "vertical_fov": 10},
    "materials": {"white": {"albedo": [0.5, 0.5, 0.5]})" + materials + R"(},
    "lights": [{"type": "point", "position": [0, 2, 0], "intensity": [10, 10, 10]}],
    "objects": [)" + before + R"({"type": "mesh", "file": ")" + kFloor + R"(", "material": "white"})" + after + "]}";
}

// The floor, and `sheet` (a material's JSON object, or empty: none) on a 1.6 x 1.6 copy of the tiled
// floor at height 1, between the light and the floor but above the camera.
std::string shadow_scene(const std::string& sheet) {
  if (sheet.empty()) return floor_scene("");
  return floor_scene(R"(, "sheet": )" + sheet, "",
                     R"(, {"type": "mesh", "file": ")" + kFloor + R"(", "material": "sheet", "transform": {"scale": 0.2, "translate": [0, 1, 0]}})");
}

// A one-texel grey picture: as an opacity texture without alpha, its grey is its opacity.
void write_grey(const std::filesystem::path& file, uint8_t grey) { write_file(file, png_bytes({1, 1, {grey, grey, grey}})); }

class AlphaShadingTest : public GpuTest {
 protected:
  double floor_radiance(const Scene& scene, uint32_t spp, bool cpu) { return image_mean(render(scene, {16, 16, spp}, {}, cpu)).g; }
  TempDir dir_;
};

TEST_F(AlphaShadingTest, ABlendedSheetPassesOneMinusItsOpacityOfTheLight) {
  // Each shadow ray passes the sheet with probability 1 - opacity, so the floor below is that much as
  // bright as without it: 0.7 at opacity 0.3, within 4 sigma of 65,536 Bernoulli samples (1.3%).
  const Scene open = parse_scene(shadow_scene(""), dir_ / "open.json");
  const Scene sheet = parse_scene(shadow_scene(R"({"albedo": [0.5, 0.5, 0.5], "opacity": 0.3})"), dir_ / "sheet.json");
  for (const bool cpu : {false, true}) {
    const double expected = 0.7 * floor_radiance(open, 1, cpu);
    EXPECT_NEAR(floor_radiance(sheet, 256, cpu), expected, 0.013 * expected) << (cpu ? "CPU" : "GPU");
  }
}

TEST_F(AlphaShadingTest, ABlendedSphereIsTwoSurfacesToARayThatCrossesIt) {
  // A shadow ray through a sphere blended at opacity 0.5 crosses two surfaces, each deciding on its
  // own: it passes with probability 0.5^2 = 0.25 (the same number for both sides would pass 0.5).
  const std::string json = floor_scene(R"(, "ghost": {"albedo": [0.5, 0.5, 0.5], "opacity": 0.5})", "",
                                       R"(, {"type": "sphere", "center": [0, 1.3, 0], "radius": 0.4, "material": "ghost"})");
  const Scene open = parse_scene(shadow_scene(""), dir_ / "open.json");
  const Scene sphere = parse_scene(json, dir_ / "sphere.json");
  for (const bool cpu : {false, true}) {
    const double expected = 0.25 * floor_radiance(open, 1, cpu);
    EXPECT_NEAR(floor_radiance(sphere, 256, cpu), expected, 0.03 * expected) << (cpu ? "CPU" : "GPU");
  }
}

TEST_F(AlphaShadingTest, ADecalOnAnOpaqueFloorNeverOpensIt) {
  // A blended decal lying on the floor, the same triangles listed first: where a ray passes the decal,
  // the floor at the same distance still stops it (the search goes on in the tie rule's order, not
  // from past the decal's t). With the decal's colour the floor's, the image is the bare floor's, bit
  // for bit, through the BVH and compiled into the shader.
  const std::string json = floor_scene(R"(, "decal": {"albedo": [0.5, 0.5, 0.5], "opacity": 0.5})",
                                       R"({"type": "mesh", "file": ")" + kFloor + R"(", "material": "decal"}, )");
  const Scene bare = parse_scene(shadow_scene(""), dir_ / "bare.json");
  const Scene decal = parse_scene(json, dir_ / "decal.json");
  for (const InlineScene inline_scene : {InlineScene::never, InlineScene::always}) {
    RenderOptions options;
    options.inline_scene = inline_scene;
    for (const bool cpu : {false, true})
      EXPECT_TRUE(render(decal, {16, 16, 4}, options, cpu).pixels == render(bare, {16, 16, 4}, options, cpu).pixels)
          << (cpu ? "CPU" : "GPU") << (inline_scene == InlineScene::always ? ", compiled in" : "");
  }
}

TEST_F(AlphaShadingTest, AMaskedSheetIsGoneBelowItsCutoffAndWholeAtIt) {
  // A texture of opacity 0.4 (grey 102) under the default cutoff 0.5: the sheet is not there for any
  // ray, and the image is the open floor's, bit for bit; at opacity 0.6 (grey 153) it is all there,
  // and the floor below is in its shadow (black: no ambient light).
  write_grey(dir_ / "thin.png", 102);
  write_grey(dir_ / "thick.png", 153);
  const Scene open = parse_scene(shadow_scene(""), dir_ / "open.json");
  const auto masked = [&](const char* picture) {
    return parse_scene(shadow_scene(std::string(R"({"albedo": [0.5, 0.5, 0.5], "alpha_mode": "mask", "opacity_texture": ")") + picture + "\"}"),
                       dir_ / "masked.json");
  };
  for (const bool cpu : {false, true}) {
    const Image without = render(open, {16, 16, 1}, {}, cpu);
    EXPECT_EQ(render(masked("thin.png"), {16, 16, 1}, {}, cpu).pixels, without.pixels) << (cpu ? "CPU" : "GPU");
    EXPECT_GT(image_mean(without).g, 0.1);
    EXPECT_EQ(image_mean(render(masked("thick.png"), {16, 16, 1}, {}, cpu)).g, 0.0) << (cpu ? "CPU" : "GPU");
  }
}

TEST_F(AlphaShadingTest, ASeeThroughLampLightsAsMuchAsItsOpacity) {
  // A square lamp above the floor, blended at opacity 0.25 (a quarter of the rays that reach it meet
  // it), lights the floor a quarter as much as when it is whole: under the direct model (light
  // samples scaled by the coverage) and under paths (light samples, and BSDF samples that meet it,
  // weighed by MIS).
  const auto lamp = [&](const char* alpha, const char* integrator) {
    const std::string json = R"({
      "integrator": {"type": ")" + std::string(integrator) + R"(", "max_depth": 2},
      "camera": {"position": [0, 0.5, 0.0001], "look_at": [0, 0, 0], "vertical_fov": 10},
      "materials": {"white": {"albedo": [0.5, 0.5, 0.5]}, "lamp": {"albedo": [0, 0, 0], "emission": [4, 4, 4])" +
                             std::string(alpha) + R"(}},
      "objects": [{"type": "mesh", "file": ")" + kFloor + R"(", "material": "white"},
                  {"type": "mesh", "file": ")" + kFloor + R"(", "material": "lamp", "transform": {"scale": 0.1, "rotate": [180, 0, 0], "translate": [0, 1.5, 0]}}]})";
    return parse_scene(json, dir_ / "lamp.json");
  };
  for (const char* integrator : {"direct", "path"}) {
    for (const bool cpu : {false, true}) {
      const double whole = floor_radiance(lamp("", integrator), 256, cpu);
      const double quarter = floor_radiance(lamp(R"(, "opacity": 0.25)", integrator), 256, cpu);
      EXPECT_GT(whole, 0.01);
      EXPECT_NEAR(quarter / whole, 0.25, 0.01) << integrator << (cpu ? ", CPU" : ", GPU");
    }
  }
}

// ---- Parity catches mistakes in the alpha code (checks/alpha-*.json) --------------------------------

class BrokenAlpha : public BrokenShaderParityTest {
 protected:
  BrokenAlpha(const std::string& file, const std::string& good, const std::string& bad) : BrokenShaderParityTest(file, good, bad) {}
  // Fails the test unless parity fails on the check scenes of both integrators.
  void expect_caught() {
    expect_caught_on_check("alpha-direct");
    expect_caught_on_check("alpha-path");
  }
};

// Shadow rays that take every surface as whole: the fence's and the canopy's shadows fill in.
class AlphaIgnoredOnShadowRays : public BrokenAlpha {
 protected:
  AlphaIgnoredOnShadowRays()
      : BrokenAlpha("traversal.glsl", "passes = hit.prim != NO_HIT && !meets_hit(ray, hit, key, passed_index);",
                    "passes = hit.prim != NO_HIT && !meets_hit(ray, hit, key, passed_index) && !any_hit;") {}
};
TEST_F(AlphaIgnoredOnShadowRays, IsCaught) { expect_caught(); }

// Opacity read from the texture's red instead of its alpha.
class OpacityFromRed : public BrokenAlpha {
 protected:
  OpacityFromRed() : BrokenAlpha("primitives.glsl", "triangle_texcoord(prim, b)).a;", "triangle_texcoord(prim, b)).r;") {}
};
TEST_F(OpacityFromRed, IsCaught) { expect_caught(); }

// Both sides of a blended sphere deciding on one number: a ray that passes where it enters passes
// where it leaves too, and the sphere lets half the light through instead of a quarter.
class SphereSidesShareANumber : public BrokenAlpha {
 protected:
  SphereSidesShareANumber() : BrokenAlpha("primitives.glsl", "bool far_side = sphere && dot(", "bool far_side = false && dot(") {}
};
TEST_F(SphereSidesShareANumber, IsCaught) { expect_caught(); }

// A masked lamp that sends light from all of its square, the parts its mask cuts away included.
class LampCoverageIgnored : public BrokenAlpha {
 protected:
  LampCoverageIgnored()
      : BrokenAlpha("emitters.glsl", "light.radiance *= alpha_coverage(", "light.radiance *= 1.0 + 0.0 * alpha_coverage(") {}
};
TEST_F(LampCoverageIgnored, IsCaught) { expect_caught(); }

}  // namespace
}  // namespace vkray::test
