// glTF files rendered as their authors made them: vertex colours (COLOR_0) times the base colour and its
// alpha, KHR_materials_unlit's flat base colour, and textures on their own texture coordinate sets.
// Both renderers agree, an unlit surface shows exactly its base colour, and parity notices a shader
// that forgets the vertex colours or reads the wrong set.
#include <gtest/gtest.h>

#include "load/scene_loader.h"
#include "support/parity_run.h"
#include "support/temp_dir.h"
#include "support/test_assets.h"

namespace vkray::test {
namespace {

// A quad facing the camera whose corners have the colours red, green, blue and white (and alphas 1,
// 1, 0.25, 1 under BLEND), over a grey floor; `unlit`: its material is KHR_materials_unlit and
// double-sided, so it shows (and emits from both sides, lighting the floor in front of it and
// behind it) its base colour times the vertex colours.
Scene coloured_quad(bool unlit, bool path) {
  GltfBuilder b;
  nlohmann::json material = {{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.25, 0.125, 1}}, {"metallicFactor", 0}}},
                             {"alphaMode", "BLEND"}, {"doubleSided", unlit}};
  if (unlit) {
    material["extensions"] = {{"KHR_materials_unlit", nlohmann::json::object()}};
    b.doc["extensionsUsed"] = {"KHR_materials_unlit"};
  }
  b.quad(b.material(material));
  b.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = b.accessor({1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 0.25f, 1, 1, 1, 1}, "VEC4");
  TempDir dir;
  write_file(dir / "quad.glb", b.glb());
  const std::string integrator = path ? R"({"type": "path", "max_depth": 4})" : R"({"type": "direct"})";
  write_file(dir / "scene.json", R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0, 0], "vertical_fov": 50},
    "integrator": )" + integrator + R"(, "background": [0.1, 0.1, 0.1],
    "lights": [{"type": "point", "position": [1, 2, 3], "intensity": [6, 6, 6]}],
    "materials": {"floor": {"albedo": [0.7, 0.7, 0.7]}},
    "objects": [{"type": "gltf", "file": "quad.glb"},
                {"type": "triangles", "material": "floor", "positions": [[-3, -1.2, -2], [3, -1.2, -2], [3, -1.2, 4], [-3, -1.2, 4]],
                 "indices": [[0, 2, 1], [0, 3, 2]]}]})");
  return load_scene(dir / "scene.json");
}

struct Case {
  bool unlit;
  bool path;
};

class VertexColourParityTest : public ParityTest, public ::testing::WithParamInterface<Case> {};

TEST_P(VertexColourParityTest, BothRenderersColourAlike) {
  const auto [unlit, path] = GetParam();
  const Scene scene = coloured_quad(unlit, path);
  ASSERT_TRUE(scene.see_through());  // the blue corner's alpha, under BLEND
  expect_parity(run(scene, {96, 96, path ? 16u : 4u}), std::string("vertex-colours-") + (unlit ? "unlit-" : "") + (path ? "path" : "direct"));
}

INSTANTIATE_TEST_SUITE_P(Materials, VertexColourParityTest,
                         ::testing::Values(Case{false, false}, Case{false, true}, Case{true, false}, Case{true, true}),
                         [](const auto& p) { return std::string(p.param.unlit ? "Unlit" : "Lit") + (p.param.path ? "Path" : "Direct"); });

// An unlit surface sends its base colour and nothing else: a quad filling the view, its corners
// white, shows (0.5, 0.25, 0.125) at every pixel on both renderers, lit or not, under both
// integrators; double-sided, from behind too.
TEST_F(ParityTest, AnUnlitSurfaceShowsExactlyItsBaseColour) {
  for (const bool path : {false, true})
    for (const bool behind : {false, true}) {
      GltfBuilder b;
      b.quad(b.material({{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.25, 0.125, 1}}}}, {"doubleSided", behind},
                         {"extensions", {{"KHR_materials_unlit", nlohmann::json::object()}}}}));
      b.doc["extensionsUsed"] = {"KHR_materials_unlit"};
      TempDir dir;
      write_file(dir / "quad.glb", b.glb());
      const std::string z = behind ? "-1" : "1";
      write_file(dir / "scene.json", R"({"camera": {"position": [0, 0, )" + z + R"(], "look_at": [0, 0, 0], "vertical_fov": 60},
        "integrator": {"type": ")" + (path ? "path" : "direct") + R"("}, "lights": [{"type": "point", "position": [0, 0, )" + z + R"(], "intensity": [5, 5, 5]}],
        "objects": [{"type": "gltf", "file": "quad.glb"}]})");
      const ParityResult r = run(load_scene(dir / "scene.json"), {16, 16, 4});
      for (const Image* image : {&r.gpu.image, &r.cpu.image})
        for (const auto& [x, y] : {std::pair{8u, 8u}, std::pair{2u, 3u}, std::pair{13u, 12u}}) {
          const glm::vec3 c = image->at(x, y);
          const std::string what = std::string(image == &r.gpu.image ? "GPU" : "CPU") + (path ? " path" : " direct") + (behind ? " behind" : "");
          EXPECT_NEAR(c.r, 0.5f, 1e-5f) << what;
          EXPECT_NEAR(c.g, 0.25f, 1e-5f) << what;
          EXPECT_NEAR(c.b, 0.125f, 1e-5f) << what;
        }
    }
}

std::filesystem::path khronos(const char* model) { return std::filesystem::path(VKRAY_SCENE_DIR) / "gltf" / model; }

// A shader that ignores vertex colours must fail parity on the Khronos model that tests them.
class VertexColoursIgnoredTest : public BrokenShaderParityTest {
 protected:
  VertexColoursIgnoredTest() : BrokenShaderParityTest("primitives.glsl", "      s.albedo *= colour;", "      s.albedo *= 1.0;") {}
};

TEST_F(VertexColoursIgnoredTest, FailsParity) {
  const ParityResult r = run(load_scene(khronos("VertexColorTest/glTF-Binary/VertexColorTest.glb")), {96, 96, 1});
  EXPECT_FALSE(r.metrics.pass);
}

// So must one that reads every texture through the first texture coordinate set.
class TexCoordSetIgnoredTest : public BrokenShaderParityTest {
 protected:
  TexCoordSetIgnoredTest()
      : BrokenShaderParityTest("texture.glsl", "vec2 uv = texture_texcoord_set(t.mode) == 0u ? coords.first : coords.second;",
                               "vec2 uv = coords.first;") {}
};

TEST_F(TexCoordSetIgnoredTest, FailsParity) {
  const ParityResult r = run(load_scene(khronos("MultiUVTest/glTF-Binary/MultiUVTest.glb")), {96, 96, 1});
  EXPECT_FALSE(r.metrics.pass);
}

// And one whose light sampling takes a double-sided unlit emitter's back for its dark side: the floor
// behind the quad goes unlit.
class BackOfATwoSidedEmitterIgnoredTest : public BrokenShaderParityTest {
 protected:
  BackOfATwoSidedEmitterIgnoredTest()
      : BrokenShaderParityTest("shade.glsl", "float cos_l = light.both_sides ? abs(dot(light.normal, w)) : -dot(light.normal, w);",
                               "float cos_l = -dot(light.normal, w);") {}
};

TEST_F(BackOfATwoSidedEmitterIgnoredTest, FailsParity) {
  const ParityResult r = run(coloured_quad(true, false), {96, 96, 4});
  EXPECT_FALSE(r.metrics.pass);
}

// And one whose unlit emitters, picked by light sampling, forget their vertex colours.
class UnlitEmitterColoursIgnoredTest : public BrokenShaderParityTest {
 protected:
  UnlitEmitterColoursIgnoredTest() : BrokenShaderParityTest("emitters.glsl", "    light.radiance *= vertex_colour(prim, w.yz).rgb;", "") {}
};

TEST_F(UnlitEmitterColoursIgnoredTest, FailsParity) {
  const ParityResult r = run(coloured_quad(true, true), {96, 96, 16});
  EXPECT_FALSE(r.metrics.pass);
}

}  // namespace
}  // namespace vkray::test
