// Spot and directional lights (Mitsuba's `spot` and `directional`, KHR_lights_punctual's): what a
// scene file's keys become, each against the physics of a diffuse plane on both renderers, and
// parity catching a shader that gets either wrong.
#include <cmath>
#include <string>

#include <glm/gtc/constants.hpp>
#include <gtest/gtest.h>

#include "load/scene_loader.h"
#include "session/cpu_render.h"
#include "support/error_of.h"
#include "support/parity_run.h"

namespace vkray::test {
namespace {

constexpr double kPi = glm::pi<double>();

// A diffuse plane y = 0 of albedo 0.5 seen from straight above, lit by `light` alone.
std::string plane_under(const std::string& light, const std::string& integrator = "direct") {
  return R"({
    "camera": {"position": [0, 4, 0], "direction": [0, -1, 0], "up": [0, 0, 1], "vertical_fov": 90},
    "integrator": {"type": ")" + integrator + R"("},
    "materials": {"ground": {"albedo": [0.5, 0.5, 0.5]}},
    "lights": [)" + light + R"(],
    "objects": [{"type": "triangles", "material": "ground", "positions": [[-50, 0, -50], [50, 0, -50], [50, 0, 50], [-50, 0, 50]],
                 "indices": [[0, 1, 2], [0, 2, 3]]}]})";
}

TEST(LightsTest, ASpotTakesMitsubasDefaultsAndADirectionalLightItsDirection) {
  const Scene spot = parse_scene(
      R"({"camera": {"position": [0, 0, 0], "direction": [0, 0, 1], "vertical_fov": 40},
          "lights": [{"type": "spot", "position": [1, 2, 3], "look_at": [1, 2, 5], "intensity": [4, 4, 4]},
                     {"type": "spot", "position": [0, 0, 0], "direction": [0, -2, 0], "intensity": [1, 1, 1], "cutoff_angle": 40, "beam_width": 10},
                     {"type": "directional", "direction": [0, -3, 4], "irradiance": [2, 2, 2]}]})",
      "lights.json");
  ASSERT_EQ(spot.lights.size(), 3u);
  EXPECT_EQ(spot.lights[0].type, Light::Type::spot);
  EXPECT_EQ(spot.lights[0].falloff, Light::Falloff::mitsuba);
  EXPECT_EQ(spot.lights[0].direction, glm::vec3(0, 0, 1));
  EXPECT_FLOAT_EQ(spot.lights[0].cutoff_angle, glm::radians(20.0f));
  EXPECT_FLOAT_EQ(spot.lights[0].beam_width, glm::radians(15.0f));
  EXPECT_EQ(spot.lights[1].direction, glm::vec3(0, -1, 0));
  EXPECT_FLOAT_EQ(spot.lights[1].cutoff_angle, glm::radians(40.0f));
  EXPECT_FLOAT_EQ(spot.lights[1].beam_width, glm::radians(10.0f));
  EXPECT_EQ(spot.lights[2].type, Light::Type::directional);
  EXPECT_NEAR(glm::distance(spot.lights[2].direction, glm::vec3(0, -0.6, 0.8)), 0.0f, 1e-7f);
  EXPECT_EQ(spot.lights[2].intensity, glm::vec3(2));
}

class LightPhysicsTest : public GpuTest, public ::testing::WithParamInterface<bool> {
 protected:
  // Both renderers' images of the scene and the CPU's first-hit positions.
  struct Renders {
    Image gpu, cpu;
    Aovs passes;
  };
  Renders render_both(const Scene& scene, const ImageSettings& image) {
    RenderOptions options = with_image({}, image);
    options.aovs = true;
    Renders r{render(scene, image), {}, {}};
    RenderResult cpu = render_on_cpu(scene, options);
    r.cpu = std::move(cpu.image);
    r.passes = std::move(*cpu.aovs);
    return r;
  }
};

TEST_P(LightPhysicsTest, ADirectionalLightGivesAlbedoOverPiTimesIrradianceTimesCosine) {
  // E = 2 arriving 60 degrees from the normal: L = 0.5 / pi * 2 * cos 60 everywhere on the plane,
  // under either integrator (nothing else is there to bounce light back).
  const std::string light = R"({"type": "directional", "direction": [0.8660254037844386, -0.5, 0], "irradiance": [2, 1, 0.5]})";
  const Scene scene = parse_scene(plane_under(light, GetParam() ? "path" : "direct"), "directional.json");
  const glm::dvec3 expected = 0.5 / kPi * glm::dvec3(2, 1, 0.5) * 0.5;
  for (const bool cpu : {false, true}) {
    const Image image = render(scene, {16, 16, 1}, {}, cpu);
    for (const glm::vec3& p : image.pixels)
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(p[c], expected[c], 1e-5 * expected[c]) << (cpu ? "CPU" : "GPU") << ", channel " << c;
  }
}

// The fraction of a spot's intensity that leaves at `angle` from its axis, as Mitsuba's `spot` and
// KHR_lights_punctual define it.
double mitsuba_falloff(double angle, double cutoff, double beam) {
  return angle >= cutoff ? 0.0 : angle <= beam ? 1.0 : (cutoff - angle) / (cutoff - beam);
}
double gltf_falloff(double angle, double outer, double inner) {
  const double t = std::clamp((std::cos(angle) - std::cos(outer)) / (std::cos(inner) - std::cos(outer)), 0.0, 1.0);
  return t * t;
}

TEST_P(LightPhysicsTest, ASpotLightsThePlaneAsItsFalloffSays) {
  // A spot 2 above the plane, pointing down: at a point r away along the plane, at angle a from
  // the axis, L = albedo / pi * I * falloff(a) * cos a / d^2 with d = 2 / cos a. Compared at each
  // pixel's one sample's hit point (both renderers take the same), to 0.1% of the centre's radiance.
  for (const bool gltf : {false, true}) {
    const std::string light = R"({"type": "spot", "position": [0, 2, 0], "direction": [0, -1, 0], "intensity": [40, 40, 40],
                                  "cutoff_angle": 50, "beam_width": 20})";
    Scene scene = parse_scene(plane_under(light, GetParam() ? "path" : "direct"), "spot.json");
    if (gltf) scene.lights[0].falloff = Light::Falloff::gltf;
    const double cutoff = glm::radians(50.0), beam = glm::radians(20.0);
    const Renders r = render_both(scene, {64, 64, 1});
    const double peak = 0.5 / kPi * 40 / 4;
    int ramp = 0;
    for (size_t i = 0; i < r.gpu.pixels.size(); ++i) {
      const glm::dvec3 x(r.passes.position[i]);
      const double d = std::sqrt(x.x * x.x + x.z * x.z + 4.0), cos_a = 2.0 / d, a = std::acos(cos_a);
      const double falloff = gltf ? gltf_falloff(a, cutoff, beam) : mitsuba_falloff(a, cutoff, beam);
      const double expected = 0.5 / kPi * 40 * falloff * cos_a / (d * d);
      ramp += falloff > 0.05 && falloff < 0.95;
      ASSERT_NEAR(r.gpu.pixels[i].g, expected, 1e-3 * peak) << (gltf ? "glTF" : "Mitsuba") << " falloff, GPU, pixel " << i;
      ASSERT_NEAR(r.cpu.pixels[i].g, expected, 1e-3 * peak) << (gltf ? "glTF" : "Mitsuba") << " falloff, CPU, pixel " << i;
    }
    EXPECT_GT(ramp, 400) << "the image must cover the falloff's ramp";
  }
}

INSTANTIATE_TEST_SUITE_P(Integrators, LightPhysicsTest, ::testing::Bool(), [](const auto& p) { return p.param ? "Path" : "Direct"; });

// Parity catches a spot whose ramp runs in the cosine instead of the angle, and a directional light
// that arrives from the opposite side.
class SpotRampInTheCosine : public BrokenShaderParityTest {
 protected:
  SpotRampInTheCosine() : BrokenShaderParityTest("shade.glsl", "clamp((cone.z - acos(c)) * cone.w, 0.0, 1.0)", "(c - cone.x) / (cone.y - cone.x)") {}
};
TEST_F(SpotRampInTheCosine, FailsParity) { expect_caught_on_check("spot-directional-direct"); }

class DirectionalLightReversed : public BrokenShaderParityTest {
 protected:
  DirectionalLightReversed() : BrokenShaderParityTest("shade.glsl", "w = -texelFetch(lights, base + VKRAY_LIGHT_DIRECTION).xyz;",
                                                      "w = texelFetch(lights, base + VKRAY_LIGHT_DIRECTION).xyz;") {}
};
TEST_F(DirectionalLightReversed, FailsParity) { expect_caught_on_check("spot-directional-path"); }

}  // namespace
}  // namespace vkray::test
