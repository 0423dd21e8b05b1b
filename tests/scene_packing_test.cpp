// The lighting as the shader reads it: radiance scaled by a power of two that keeps the shader's
// floats in range, and the area lights' sampling densities computed in double.
#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "load/scene_loader.h"
#include "packing/scene_packing.h"
#include "scene/emitters.h"

namespace vkray::gpu {
namespace {

Scene lit_by(const std::string& rest) {
  return parse_scene(R"({"camera": {"position": [0, 0, 0], "direction": [0, 0, 1], "focal_length": 1},
                         "integrator": {"type": "path"}, )" + rest + "}", "test.json");
}

TEST(ScenePackingTest, TheBrightestRadianceIsBroughtToTwoToTheTwenty) {
  for (const float brightest : {3.4e38f, 3e38f, 18.387f, 1.0f, 1e-25f, 1.17e-38f, 1e-39f, 1.4e-45f}) {
    Scene scene = lit_by(R"("background": [0, 0, 0])");
    scene.background = glm::vec3(brightest * 0.5f, brightest, 0.0f);
    const int k = radiance_exponent(scene);
    const float scaled = std::ldexp(brightest, k);
    EXPECT_GE(scaled, std::ldexp(1.0f, 19)) << brightest;
    EXPECT_LT(scaled, std::ldexp(1.0f, 20)) << brightest;
  }
  EXPECT_EQ(radiance_exponent(lit_by(R"("background": [0, 0, 0])")), 0);  // nothing shines
}

TEST(ScenePackingTest, ScaledRadianceComesBackBitForBit) {
  // Any float the shader computes in range returns exactly; past FLT_MAX it is held at FLT_MAX.
  std::mt19937 random(7);
  std::uniform_real_distribution<float> mantissa(0.5f, 1.0f);
  std::uniform_int_distribution<int> exponent(-125, 128), scale(-200, 200);
  for (int i = 0; i < 100000; ++i) {
    const float v = std::ldexp(mantissa(random), exponent(random));
    const int k = scale(random);
    const float scaled = std::ldexp(v, k);
    if (!(scaled >= FLT_MIN && scaled <= FLT_MAX)) continue;  // the shader never holds such a one
    EXPECT_EQ(unscale_radiance(glm::vec3(scaled), k).x, v) << v << " " << k;
  }
  EXPECT_EQ(unscale_radiance(glm::vec3(1.0f), -200).x, FLT_MAX);
  // Bit for bit what ldexp gives, subnormal results and infinities and NaN included.
  std::uniform_int_distribution<uint32_t> bits;
  for (int i = 0; i < 100000; ++i) {
    const float scaled = std::bit_cast<float>(bits(random));
    const int k = scale(random);
    const float expected = std::min(std::ldexp(scaled, -k), FLT_MAX);
    EXPECT_EQ(std::bit_cast<uint32_t>(unscale_radiance(glm::vec3(scaled), k).x), std::bit_cast<uint32_t>(expected))
        << scaled << " " << k;
  }
}

TEST(ScenePackingTest, EveryRadianceIsScaledAlike) {
  const Scene scene = lit_by(R"("background": [3e28, 1, 0], "ambient": [0.5, 0, 0],
      "materials": {"e": {"albedo": [0.5, 0.5, 0.5], "emission": [2, 3, 4]}},
      "lights": [{"type": "point", "position": [0, 1, 0], "intensity": [5, 6, 7]}],
      "objects": [{"type": "sphere", "center": [0, 0, 5], "radius": 1, "material": "e"}])");
  const int k = radiance_exponent(scene);
  const PackedLighting packed = pack_lighting(scene, PrimitiveSlots{{0}, {}, {}});
  EXPECT_EQ(packed.frame.radiance_exponent, k);
  EXPECT_EQ(packed.materials[VKRAY_MATERIAL_EMISSION].y, std::ldexp(3.0f, k));
  EXPECT_EQ(packed.lights[VKRAY_LIGHT_INTENSITY].z, std::ldexp(7.0f, k));
  const FrameUniforms frame = pack_frame(scene, 1, packed.frame, scene.image);
  EXPECT_EQ(frame.background.x, std::ldexp(3e28f, k));
  EXPECT_EQ(frame.ambient.x, std::ldexp(0.5f, k));
}

TEST(ScenePackingTest, AnAreaLightsDensityIsComputedInDouble) {
  // A sphere of radius 1e-8 emitting 1e-25, the only light: its power, 1.3e-40, is below the
  // smallest normal float, and 1 / power overflows one. Its density per unit area is 1 / area.
  const Scene scene = lit_by(R"("materials": {"e": {"albedo": [0.5, 0.5, 0.5], "emission": [1e-25, 1e-25, 1e-25]}},
      "objects": [{"type": "sphere", "center": [0, 0, 5], "radius": 1e-8, "material": "e"}])");
  const EmitterTable table = build_emitter_table(scene);
  ASSERT_EQ(table.entries.size(), 1u);
  EXPECT_TRUE(std::isinf(float(1.0 / table.total_weight)));
  const PackedLighting packed = pack_lighting(scene, PrimitiveSlots{{0}, {}, {}});
  const double area = 4.0 * 3.141592653589793 * 1e-8 * 1e-8;
  EXPECT_NEAR(packed.materials[VKRAY_MATERIAL_LIGHT].x, 1.0 / area, 1e-5 / area);
}

// ---- The materials' table and texels (shared/materials.h) -----------------------------------------------

TEST(ScenePackingTest, EveryMaterialTypeHasItsNameAndOneKindOfLobe) {
  for (uint32_t t = 0; t < VKRAY_MATERIAL_TYPE_COUNT; ++t) {
    const MaterialType type = MaterialType(t);
    const std::string_view name = material_type_name(type);
    EXPECT_NE(name, "unknown") << t;
    EXPECT_EQ(material_type_named(name), type) << name;
    // A delta BSDF has no other lobe; every other has a diffuse or a glossy one.
    const uint32_t p = material_properties(t);
    if (p & VKRAY_BSDF_DELTA)
      EXPECT_EQ(p & (VKRAY_BSDF_DIFFUSE | VKRAY_BSDF_GLOSSY), 0u) << name;
    else
      EXPECT_NE(p & (VKRAY_BSDF_DIFFUSE | VKRAY_BSDF_GLOSSY), 0u) << name;
  }
  EXPECT_EQ(material_properties(VKRAY_MATERIAL_TYPE_COUNT), 0u);
  EXPECT_FALSE(material_type_named("metal"));
}

TEST(ScenePackingTest, EachMaterialsValuesComeBackFromItsTexels) {
  // Every value through the shared pack and unpack, as the shader unpacks what the host packed, and
  // the properties in the texel the table's, with those the values add.
  for (uint32_t t = 0; t < VKRAY_MATERIAL_TYPE_COUNT; ++t) {
    MaterialValues m;
    m.color = vec3(0.25f, 0.5f, 0.75f) + float(t);
    m.type = t;
    m.emission = vec3(3.0f, 5.0f, 7.0f);
    m.ior = 1.33f + float(t);
    m.eta = vec3(0.2f, 0.4f, 1.4f);
    m.k = vec3(3.9f, 2.4f, 1.6f);
    m.alpha_u = 0.05f;
    m.alpha_v = 0.6f;
    m.metallic = 0.25f;
    m.roughness = 0.75f;
    m.normal_scale = -1.5f;
    m.transmission = 0.625f;
    const MaterialValueTexels texels = material_value_texels(m);
    const MaterialValues back = material_values(texels);
    EXPECT_EQ(back.color, m.color);
    EXPECT_EQ(back.type, m.type);
    EXPECT_EQ(back.emission, m.emission);
    EXPECT_EQ(back.ior, m.ior);
    EXPECT_EQ(back.eta, m.eta);
    EXPECT_EQ(back.k, m.k);
    EXPECT_EQ(back.alpha_u, m.alpha_u);
    EXPECT_EQ(back.alpha_v, m.alpha_v);
    EXPECT_EQ(back.metallic, m.metallic);
    EXPECT_EQ(back.roughness, m.roughness);
    EXPECT_EQ(back.normal_scale, m.normal_scale);
    EXPECT_EQ(back.transmission, m.transmission);
    // The table's properties, and TRANSMISSION where a metallic_roughness transmits.
    const uint32_t expected = material_properties(t) | (t == VKRAY_MATERIAL_METALLIC_ROUGHNESS ? VKRAY_BSDF_TRANSMISSION : 0u);
    EXPECT_EQ(material_properties_of(texels.color), expected);
    m.transmission = 0.0f;
    EXPECT_EQ(material_properties_of(material_value_texels(m).color), material_properties(t));
    static_assert(sizeof(MaterialValues) == 80, "a MaterialValues member is not checked here");
  }
}

TEST(ScenePackingTest, APackedMaterialCarriesItsTypeAndProperties) {
  const Scene scene = lit_by(R"("materials": {"d": {"albedo": [0.5, 0.5, 0.5]}, "g": {"type": "glass", "ior": 1.7}},
      "objects": [{"type": "sphere", "center": [0, 0, 5], "radius": 1, "material": "g"}])");
  const PackedLighting packed = pack_lighting(scene, PrimitiveSlots{{0}, {}, {}});
  const vec4* glass = &packed.materials[size_t(material_texel(1))];
  EXPECT_EQ(material_type_of(glass[VKRAY_MATERIAL_COLOR]), VKRAY_MATERIAL_GLASS);
  EXPECT_EQ(material_properties_of(glass[VKRAY_MATERIAL_COLOR]), VKRAY_BSDF_DELTA | VKRAY_BSDF_TRANSMISSION | VKRAY_BSDF_CLEAR);
  EXPECT_EQ(glass[VKRAY_MATERIAL_EMISSION].w, 1.7f);
}

}  // namespace
}  // namespace vkray::gpu
