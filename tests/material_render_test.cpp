// The materials beyond the lecture's, rendered: physics that needs no other renderer (a white rough
// conductor in a furnace reflects its directional albedo, worked out here by quadrature from the
// GGX formulas; a rough dielectric of index 1 is invisible, and a nearly smooth one loses nothing),
// and proof that parity catches mistakes in each BSDF's shader code.
#include <cmath>
#include <filesystem>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "load/scene_loader.h"
#include "support/parity_run.h"
#include "support/temp_dir.h"
#include "support/test_assets.h"

namespace vkray::test {
namespace {

// ---- Physics: a rough conductor whose Fresnel term is 1, under a constant sky --------------------------

// The directional albedo of an isotropic GGX conductor with F = 1, seen at cosine mu: the integral
// of f cos_i = D(h) G1(o) G1(i) / (4 mu) over the directions i, written over the half vectors h
// (d omega_i = 4 (o . h) d omega_h) and with theta_h through the GGX distribution's own CDF,
// tan^2 theta_h = alpha^2 u / (1 - u), which makes D(h) cos theta_h d omega_h = du dphi / 2 pi: what
// is left is smooth, and the midpoint rule in (u, phi) converges at any roughness. Written out here
// from Walter et al. 2007, apart from both renderers' code.
double ggx_albedo(double alpha, double mu) {
  const double pi = 3.14159265358979323846;
  const auto g1 = [&](double c) { return c <= 0 ? 0.0 : 2 / (1 + std::sqrt(1 + alpha * alpha * (1 - c * c) / (c * c))); };
  const double ox = std::sqrt(1 - mu * mu), oz = mu;
  const int n_u = 2000, n_phi = 1000;
  double sum = 0;
  for (int a = 0; a < n_u; ++a) {
    const double u = (a + 0.5) / n_u;
    const double cos_h = 1 / std::sqrt(1 + alpha * alpha * u / (1 - u)), sin_h = std::sqrt(1 - cos_h * cos_h);
    for (int p = 0; p < n_phi; ++p) {
      const double phi = (p + 0.5) * 2 * pi / n_phi;
      const double hx = sin_h * std::cos(phi), hz = cos_h;  // o lies in the xz plane: h's y does not enter
      const double o_h = ox * hx + oz * hz;
      if (o_h <= 0) continue;
      const double iz = 2 * o_h * hz - oz;  // i = 2 (o . h) h - o
      if (iz <= 0) continue;
      sum += g1(oz) * g1(iz) * o_h / (mu * cos_h);
    }
  }
  return sum / (double(n_u) * n_phi);
}

class FurnaceTest : public GpuTest {};

TEST_F(FurnaceTest, ReflectsTheSkyTimesItsDirectionalAlbedo) {
  // A large white plane with eta 0, k 1 under a sky of 1, seen through a narrow camera at cosine mu:
  // one bounce reaches the sky (nothing above the plane), so the image is E(mu), what single
  // scattering keeps: 1 for a smooth surface seen from above, less where the microfacets mask light.
  for (const double alpha : {0.2, 1.0}) {
    for (const double mu : {1.0, 0.4}) {
      const double expected = ggx_albedo(alpha, mu);
      const double height = 1, back = mu == 1.0 ? 1e-4 : height * std::sqrt(1 - mu * mu) / mu;
      const std::string json = R"({
        "camera": {"position": [0, )" + std::to_string(height) + ", " + std::to_string(-back) + R"(], "look_at": [0, 0, 0],
                   "up": [0, 0, 1], "vertical_fov": 0.5},
        "integrator": {"type": "path"},
        "background": [1, 1, 1],
        "materials": {"metal": {"type": "roughconductor", "alpha": )" + std::to_string(alpha) + R"(}},
        "objects": [{"type": "triangles", "material": "metal", "positions": [[-100, 0, -100], [100, 0, -100], [100, 0, 100], [-100, 0, 100]],
                     "indices": [[0, 2, 1], [0, 3, 2]]}]})";
      const Scene scene = parse_scene(json, "furnace.json");
      for (const bool cpu : {false, true}) {
        const double m = image_mean(render(scene, {16, 16, 256}, {}, cpu)).g;
        EXPECT_NEAR(m, expected, 0.01 * expected) << (cpu ? "CPU" : "GPU") << ", alpha " << alpha << ", mu " << mu;
      }
      if (alpha == 1.0) {
        EXPECT_LT(expected, 0.95);  // the case loses light: it would show a lost or a doubled G1
      }
    }
  }
}

TEST_F(FurnaceTest, AWhiteGltfMetalIsAWhiteRoughConductorOfAlphaRoughnessSquared) {
  // glTF's metal with base colour 1 has Schlick's F = 1: under a constant sky it reflects the
  // directional albedo of GGX with alpha = roughness^2, the same quadrature as above.
  const double roughness = 0.5, alpha = roughness * roughness;
  const std::string json = R"({
    "camera": {"position": [0, 1, -1e-4], "look_at": [0, 0, 0], "up": [0, 0, 1], "vertical_fov": 0.5},
    "integrator": {"type": "path"},
    "background": [1, 1, 1],
    "materials": {"metal": {"type": "metallic_roughness", "base_color": [1, 1, 1], "metallic": 1, "roughness": )" +
                           std::to_string(roughness) + R"(}},
    "objects": [{"type": "triangles", "material": "metal", "positions": [[-100, 0, -100], [100, 0, -100], [100, 0, 100], [-100, 0, 100]],
                 "indices": [[0, 2, 1], [0, 3, 2]]}]})";
  const Scene scene = parse_scene(json, "furnace.json");
  const double expected = ggx_albedo(alpha, 1.0);
  for (const bool cpu : {false, true})
    EXPECT_NEAR(image_mean(render(scene, {16, 16, 256}, {}, cpu)).g, expected, 0.01 * expected) << (cpu ? "CPU" : "GPU");
}

TEST_F(FurnaceTest, AGltfMetalTexturedToHalfRoughnessIsTheUntexturedOne) {
  // The same furnace, the roughness now from a metallic-roughness texture: one texel of green 128
  // (roughness 128 / 255, linear data) and blue 255 (metal), factors 1. Its channels exchanged, or
  // the texel decoded from sRGB, the plane would reflect another albedo.
  TempDir dir;
  write_file(dir.path() / "plane.obj", "v -100 0 -100\nv 100 0 -100\nv 100 0 100\nv -100 0 100\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                       "f 1/1 3/3 2/2\nf 1/1 4/4 3/3\n");
  write_file(dir.path() / "layers.png", png_bytes({1, 1, {0, 128, 255}}));
  write_file(dir.path() / "furnace.json", R"({
    "camera": {"position": [0, 1, -1e-4], "look_at": [0, 0, 0], "up": [0, 0, 1], "vertical_fov": 0.5},
    "integrator": {"type": "path"},
    "background": [1, 1, 1],
    "materials": {"metal": {"type": "metallic_roughness", "base_color": [1, 1, 1], "metallic_roughness_texture": "layers.png"}},
    "objects": [{"type": "mesh", "file": "plane.obj", "material": "metal"}]})");
  const Scene scene = load_scene(dir.path() / "furnace.json");
  const double roughness = 128.0 / 255.0, expected = ggx_albedo(roughness * roughness, 1.0);
  for (const bool cpu : {false, true})
    EXPECT_NEAR(image_mean(render(scene, {16, 16, 256}, {}, cpu)).g, expected, 0.01 * expected) << (cpu ? "CPU" : "GPU");
}

TEST_F(FurnaceTest, AWhiteThinTransmittingSheetLosesOnlyWhatARoughMetalLoses) {
  // A white glTF dielectric with transmission 1 reflects F and passes 1 - F of each microfacet's
  // light, through a sheet with no inside: under a constant sky, seen from either side, it shows
  // the directional albedo of GGX with F = 1 and alpha = roughness^2 (the quadrature above). At
  // roughness 0 it is invisible.
  for (const double roughness : {0.0, 0.7}) {
    for (const double mu : {1.0, 0.4}) {
      for (const double side : {1.0, -1.0}) {
        const double alpha = std::max(roughness * roughness, 1e-4), expected = ggx_albedo(alpha, mu);
        const double back = mu == 1.0 ? 1e-4 : std::sqrt(1 - mu * mu) / mu;
        const std::string json = R"({
          "camera": {"position": [0, )" + std::to_string(side) + ", " + std::to_string(-back) + R"(], "look_at": [0, 0, 0],
                     "up": [0, 0, 1], "vertical_fov": 0.5},
          "integrator": {"type": "path"},
          "background": [1, 1, 1],
          "materials": {"sheet": {"type": "metallic_roughness", "base_color": [1, 1, 1], "metallic": 0, "transmission": 1,
                                  "roughness": )" + std::to_string(roughness) + R"(}},
          "objects": [{"type": "triangles", "material": "sheet", "positions": [[-100, 0, -100], [100, 0, -100], [100, 0, 100], [-100, 0, 100]],
                       "indices": [[0, 2, 1], [0, 3, 2]]}]})";
        const Scene scene = parse_scene(json, "furnace.json");
        for (const bool cpu : {false, true}) {
          const double m = image_mean(render(scene, {16, 16, 256}, {}, cpu)).g;
          EXPECT_NEAR(m, expected, 0.01 * expected) << (cpu ? "CPU" : "GPU") << ", roughness " << roughness << ", mu " << mu << ", side " << side;
        }
      }
    }
  }
}

// ---- Single-sided materials: camera rays pass their back faces, shadow rays do not -------------------------

class SingleSidedTest : public GpuTest {};

TEST_F(SingleSidedTest, CameraRaysPassTheBackFaceWhichStillCastsItsShadow) {
  // A glTF quad in z = 0 facing +z, seen from behind by a camera at z = -5, with a point light beside
  // the camera and a white wall at z = 3 behind the quad. Single-sided, the quad is not seen and the
  // wall's middle lies in its shadow: black. Double-sided, the camera sees the quad's lit back face.
  TempDir dir;
  for (const bool double_sided : {false, true}) {
    GltfBuilder b;
    b.quad(b.material({{"pbrMetallicRoughness", {{"metallicFactor", 0}}}, {"doubleSided", double_sided}}));
    write_file(dir.path() / "quad.gltf", b.gltf());
    write_file(dir.path() / "scene.json", R"({
      "camera": {"position": [0, 0, -5], "look_at": [0, 0, 0], "vertical_fov": 10},
      "lights": [{"type": "point", "position": [0, 0.05, -3], "intensity": [20, 20, 20]}],
      "materials": {"wall": {"albedo": [1, 1, 1]}},
      "objects": [{"type": "gltf", "file": "quad.gltf"},
                  {"type": "triangles", "material": "wall", "positions": [[-9, -9, 3], [9, -9, 3], [9, 9, 3], [-9, 9, 3]],
                   "indices": [[0, 1, 2], [0, 2, 3]]}]})");
    Scene scene = load_scene(dir.path() / "scene.json");
    for (const Integrator::Type type : {Integrator::Type::direct, Integrator::Type::path}) {
      scene.integrator.type = type;
      scene.integrator.max_depth = 2;  // paths: the light a first hit receives directly, as the direct model
      for (const int renderer : {0, 1, 2}) {  // GPU through the BVH, GPU compiled in, CPU
        RenderOptions options;
        options.inline_scene = renderer == 1 ? InlineScene::always : InlineScene::never;
        const Image image = render(scene, {9, 9, 4}, options, renderer == 2);
        const float middle = image.at(4, 4).g;
        const std::string what = std::string(double_sided ? "double" : "single") + "-sided, " +
                                 (type == Integrator::Type::path ? "paths, " : "direct, ") +
                                 (renderer == 0 ? "GPU (BVH)" : renderer == 1 ? "GPU (compiled in)" : "CPU");
        if (double_sided)
          EXPECT_GT(middle, 0.01f) << what;  // the quad's back, lit by the light behind the camera
        else
          EXPECT_EQ(middle, 0.0f) << what;  // the wall, in the quad's shadow
      }
    }
  }
}

TEST_F(FurnaceTest, TheQuadratureKeepsEverythingForASmoothSurface) {
  // The test's own integral: alpha -> 0 reflects everything at normal incidence.
  EXPECT_NEAR(ggx_albedo(0.02, 1.0), 1.0, 2e-3);
}

// ---- Physics: rough dielectrics ---------------------------------------------------------------------------

std::string dielectric_sphere_in_a_furnace(double alpha, double ior) {
  return R"({
    "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "vertical_fov": 20},
    "integrator": {"type": "path"},
    "background": [1, 1, 1],
    "materials": {"glass": {"type": "roughdielectric", "alpha": )" + std::to_string(alpha) + R"(, "int_ior": )" + std::to_string(ior) + R"(}},
    "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "glass"}]})";
}

TEST_F(FurnaceTest, ARoughDielectricOfIndexOneIsInvisible) {
  // Index 1 inside and out is no interface: the sphere, however rough, lets the sky through whole.
  // So under the direct model too, which passes the ray on there as at glass.
  Scene scene = parse_scene(dielectric_sphere_in_a_furnace(0.5, 1.0), "furnace.json");
  for (const Integrator::Type type : {Integrator::Type::path, Integrator::Type::direct}) {
    scene.integrator.type = type;
    for (const bool cpu : {false, true}) {
      const Image image = render(scene, {16, 16, 4}, {}, cpu);
      for (const glm::vec3& p : image.pixels)
        ASSERT_NEAR(p.g, 1.0f, 1e-6f) << (cpu ? "CPU" : "GPU") << (type == Integrator::Type::path ? ", paths" : ", direct");
    }
  }
}

TEST_F(FurnaceTest, ANearlySmoothDielectricLosesNothing) {
  // Reflection and refraction together keep the power, and a sphere under a uniform sky then shows
  // the sky: what masking takes at alpha 0.01 is below the tolerance. The same sphere at alpha 0.5
  // loses what single scattering loses at each of the many times a path meets its surface (0.61 of
  // the sky is left on both renderers; Mitsuba 3 agrees on such spheres, docs/rendering.md), and
  // never gains.
  const Scene smooth = parse_scene(dielectric_sphere_in_a_furnace(0.01, 1.5), "furnace.json");
  const Scene rough = parse_scene(dielectric_sphere_in_a_furnace(0.5, 1.5), "furnace.json");
  for (const bool cpu : {false, true}) {
    EXPECT_NEAR(image_mean(render(smooth, {16, 16, 256}, {}, cpu)).g, 1.0, 0.01) << (cpu ? "CPU" : "GPU");
    const double m = image_mean(render(rough, {16, 16, 256}, {}, cpu)).g;
    EXPECT_LT(m, 1.0) << (cpu ? "CPU" : "GPU");
    EXPECT_GT(m, 0.5) << (cpu ? "CPU" : "GPU");
  }
}

// ---- Parity catches mistakes in the rough conductor's shader code -------------------------------------

// A copy of the shaders with one line broken, against the CPU reference on a material's check scenes
// (checks/<scenes>-direct.json and -path.json).
class BrokenMaterialShader : public BrokenShaderParityTest {
 protected:
  BrokenMaterialShader(std::string scenes, const std::string& file, const std::string& good, const std::string& bad)
      : BrokenShaderParityTest(file, good, bad), scenes_(std::move(scenes)) {}
  void expect_caught(const char* integrator) { expect_caught_on_check(scenes_ + "-" + integrator); }

 private:
  std::string scenes_;
};

class BrokenConductor : public BrokenMaterialShader {
 protected:
  BrokenConductor(const std::string& good, const std::string& bad) : BrokenMaterialShader("rough-conductors", "bsdf.glsl", good, bad) {}
};

class ConductorFresnelWithKNotSquared : public BrokenConductor {
 protected:
  ConductorFresnelWithKNotSquared() : BrokenConductor("vec3 eta2 = eta * eta, k2 = k * k;", "vec3 eta2 = eta * eta, k2 = k;") {}
};
TEST_F(ConductorFresnelWithKNotSquared, IsCaught) {
  expect_caught("direct");
  expect_caught("path");
}

class ConductorEvalWithoutTheReflectionJacobian : public BrokenConductor {
 protected:
  // The 1 / (4 wi . m) that turns a density of normals into one of directions, lost from eval.
  ConductorEvalWithoutTheReflectionJacobian() : BrokenConductor("(dg / (4.0 * wo.z));", "(dg / wo.z);") {}
};
TEST_F(ConductorEvalWithoutTheReflectionJacobian, IsCaught) {
  expect_caught("direct");
  expect_caught("path");
}

class ConductorSampleWithoutMasking : public BrokenConductor {
 protected:
  // The sampled direction's masking G1(wi) left out of the weight: only paths that bounce see it.
  ConductorSampleWithoutMasking()
      : BrokenConductor("fresnel_conductor(dot(o, m), s.eta, s.k) * smith_masking(i, m, s.alpha);",
                        "fresnel_conductor(dot(o, m), s.eta, s.k);") {}
};
TEST_F(ConductorSampleWithoutMasking, IsCaught) { expect_caught("path"); }

class ConductorWithItsTangentsSwapped : public BrokenConductor {
 protected:
  // alpha_u and alpha_v exchanged in the distribution alone: the anisotropic sphere's highlight turns.
  ConductorWithItsTangentsSwapped() : BrokenConductor("vec2 slope = m.xy / alpha;", "vec2 slope = m.xy / alpha.yx;") {}
};
TEST_F(ConductorWithItsTangentsSwapped, IsCaught) { expect_caught("direct"); }

// ---- ... in glTF's metallic-roughness material's (checks/metallic-roughness-*.json) ----------------------
class BrokenMetallicRoughness : public BrokenMaterialShader {
 protected:
  BrokenMetallicRoughness(const std::string& good, const std::string& bad) : BrokenMaterialShader("metallic-roughness", "bsdf.glsl", good, bad) {}
};

class GltfRoughnessNotSquared : public BrokenMetallicRoughness {
 protected:
  // glTF's alpha is roughness squared; roughness itself makes every highlight wider.
  GltfRoughnessNotSquared()
      : BrokenMetallicRoughness("return max(s.roughness * s.roughness, VKRAY_MIN_GGX_ALPHA);", "return max(s.roughness, VKRAY_MIN_GGX_ALPHA);") {}
};
TEST_F(GltfRoughnessNotSquared, IsCaught) {
  expect_caught("direct");
  expect_caught("path");
}

class GltfMetalWithTheDielectricsFresnel : public BrokenMetallicRoughness {
 protected:
  // The metal's Schlick term from 0.04 instead of the base colour: gold turns grey.
  GltfMetalWithTheDielectricsFresnel()
      : BrokenMetallicRoughness("vec3 metal = specular * (s.albedo + (1.0 - s.albedo) * schlick);", "vec3 metal = vec3(specular * fresnel);") {}
};
TEST_F(GltfMetalWithTheDielectricsFresnel, IsCaught) {
  expect_caught("direct");
  expect_caught("path");
}

class GltfDiffuseWithoutFresnel : public BrokenMetallicRoughness {
 protected:
  // The dielectric's Lambert layer not weighed by 1 - F: light reflected twice.
  GltfDiffuseWithoutFresnel()
      : BrokenMetallicRoughness("vec3 dielectric = (1.0 - fresnel) * (1.0 - s.transmission) * s.albedo / PI + vec3(fresnel * specular);",
                                "vec3 dielectric = (1.0 - s.transmission) * s.albedo / PI + vec3(fresnel * specular);") {}
};
TEST_F(GltfDiffuseWithoutFresnel, IsCaught) { expect_caught("direct"); }

// ---- ... in its textures (checks/metallic-roughness-textured-*.json) --------------------------------------
class BrokenMetallicRoughnessTexture : public BrokenMaterialShader {
 protected:
  BrokenMetallicRoughnessTexture(const std::string& good, const std::string& bad)
      : BrokenMaterialShader("metallic-roughness-textured", "primitives.glsl", good, bad) {}
};

class GltfTextureChannelsExchanged : public BrokenMetallicRoughnessTexture {
 protected:
  // glTF packs metalness in blue and roughness in green; read the other way round, the bands trade.
  GltfTextureChannelsExchanged()
      : BrokenMetallicRoughnessTexture("s.metallic *= layers.b;\n      s.roughness *= layers.g;",
                                       "s.metallic *= layers.g;\n      s.roughness *= layers.b;") {}
};
TEST_F(GltfTextureChannelsExchanged, IsCaught) {
  expect_caught("direct");
  expect_caught("path");
}

class GltfRoughnessTextureIgnored : public BrokenMetallicRoughnessTexture {
 protected:
  // The roughnessFactor everywhere: every band as rough as the roughest.
  GltfRoughnessTextureIgnored() : BrokenMetallicRoughnessTexture("s.roughness *= layers.g;", "s.roughness *= 1.0;") {}
};
TEST_F(GltfRoughnessTextureIgnored, IsCaught) {
  expect_caught("direct");
  expect_caught("path");
}

// ---- ... and in the rough dielectric's (checks/rough-dielectrics-*.json) --------------------------------
class BrokenDielectric : public BrokenMaterialShader {
 protected:
  BrokenDielectric(const std::string& file, const std::string& good, const std::string& bad)
      : BrokenMaterialShader("rough-dielectrics", file, good, bad) {}
};

class DielectricTransmissionWithoutFresnel : public BrokenDielectric {
 protected:
  // Refraction's share, 1 - F, left out of eval: light from behind comes through too bright.
  DielectricTransmissionWithoutFresnel() : BrokenDielectric("bsdf.glsl", "return vec3((1.0 - f) * ggx_density(h, s.alpha)", "return vec3(ggx_density(h, s.alpha)") {}
};
TEST_F(DielectricTransmissionWithoutFresnel, IsCaught) {
  expect_caught("direct");
  expect_caught("path");
}

class DielectricRefractionWithoutRadianceScaling : public BrokenDielectric {
 protected:
  // The 1 / eta^2 by which refraction compresses radiance, lost from a sampled refraction's weight.
  DielectricRefractionWithoutRadianceScaling()
      : BrokenDielectric("bsdf.glsl", "b.weight = vec3(smith_masking(i, m, s.alpha) / (eta * eta));", "b.weight = vec3(smith_masking(i, m, s.alpha));") {}
};
TEST_F(DielectricRefractionWithoutRadianceScaling, IsCaught) { expect_caught("path"); }

class DielectricShadowRaysOnTheWrongSide : public BrokenDielectric {
 protected:
  // Shadow rays toward a light behind the surface leaving from the front: the surface itself hides
  // every light that shines through it.
  DielectricShadowRaysOnTheWrongSide()
      : BrokenDielectric("shade.glsl", "return p.both_sides && dot(p.n_geometric, w) < 0.0 ? p.origin_back : p.origin_front;", "return p.origin_front;") {}
};
TEST_F(DielectricShadowRaysOnTheWrongSide, IsCaught) {
  expect_caught("direct");
  expect_caught("path");
}

// ---- ... and in glTF's thin-walled transmission (checks/transmission-*.json) ------------------------------
class BrokenTransmission : public BrokenMaterialShader {
 protected:
  BrokenTransmission(const std::string& file, const std::string& good, const std::string& bad)
      : BrokenMaterialShader("transmission", file, good, bad) {}
};

class TransmissionWithTheUnmirroredHalfVector : public BrokenTransmission {
 protected:
  // H_T from the direction below the surface itself, not its mirror image: the lobe looks away.
  TransmissionWithTheUnmirroredHalfVector()
      : BrokenTransmission("bsdf.glsl", "vec3 l = vec3(wi.xy, abs(wi.z)), h = normalize(wo + l);", "vec3 l = vec3(wi.xy, abs(wi.z)), h = normalize(wo + wi);") {}
};
TEST_F(TransmissionWithTheUnmirroredHalfVector, IsCaught) {
  expect_caught("direct");
  expect_caught("path");
}

class TransmissionWithoutFresnel : public BrokenTransmission {
 protected:
  // The transmitted share not weighed by 1 - F: light from behind comes through as if nothing were reflected.
  TransmissionWithoutFresnel()
      : BrokenTransmission("bsdf.glsl", "(1.0 - s.metallic) * (1.0 - fresnel) * s.transmission", "(1.0 - s.metallic) * s.transmission") {}
};
TEST_F(TransmissionWithoutFresnel, IsCaught) {
  expect_caught("direct");
  expect_caught("path");
}

class TransmissionSampledOnTheReflectedSide : public BrokenTransmission {
 protected:
  // The transmission lobe's sample left above the surface: eval and pdf still say where light passes.
  TransmissionSampledOnTheReflectedSide() : BrokenTransmission("bsdf.glsl", "if (u_lobe >= p.x) i.z = -i.z;", "") {}
};
TEST_F(TransmissionSampledOnTheReflectedSide, IsCaught) { expect_caught("path"); }

class TransmissionTextureReadFromGreen : public BrokenTransmission {
 protected:
  // glTF's transmissionTexture keeps the transmission in red.
  TransmissionTextureReadFromGreen()
      : BrokenTransmission("primitives.glsl", "material + VKRAY_MATERIAL_TRANSMISSION_TEXTURE, uv).r;", "material + VKRAY_MATERIAL_TRANSMISSION_TEXTURE, uv).g;") {}
};
TEST_F(TransmissionTextureReadFromGreen, IsCaught) {
  expect_caught("direct");
  expect_caught("path");
}

}  // namespace
}  // namespace vkray::test
