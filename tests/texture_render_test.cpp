// Textures rendered: both renderers show a texture where it belongs, with each wrap mode and filter,
// under both integrators and as emission; a picture renders the same in 8 and 16 bits; parity holds
// on textured scenes; and parity notices a shader that samples a texture wrongly.
#include <algorithm>

#include <gtest/gtest.h>
#include <png.h>

#include "support/parity_run.h"
#include "support/temp_dir.h"
#include "support/test_assets.h"
#include "load/scene_loader.h"

namespace vkray::test {
namespace {

// A quad filling most of the view, textured with the four colours (red, green / blue, white), its
// texture coordinates running from -0.5 to 1.5 so that each wrap mode shows; lit by a point light at
// the camera (direct) or a white sky (path).
Scene textured_quad(const nlohmann::json& sampler, bool path, bool emissive = false, const std::string& picture = png_bytes(four_colours())) {
  GltfBuilder b;
  const int texture = b.texture(picture, sampler);
  nlohmann::json material = {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", texture}}}, {"metallicFactor", 0}}}};
  if (emissive) material["emissiveTexture"] = {{"index", texture}}, material["emissiveFactor"] = {2, 2, 2};
  b.quad(b.material(material));
  b.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = b.accessor({-0.5f, 1.5f, 1.5f, 1.5f, 1.5f, -0.5f, -0.5f, -0.5f}, "VEC2");
  TempDir dir;
  write_file(dir / "quad.glb", b.glb());
  const std::string integrator = path ? R"({"type": "path", "max_depth": 3})" : R"({"type": "direct"})";
  write_file(dir / "scene.json", R"({"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0], "vertical_fov": 40},
    "integrator": )" + integrator + R"(, "background": )" + (path && !emissive ? "[1, 1, 1]" : "[0, 0, 0]") + R"(,
    "lights": [)" + (path ? "" : R"({"type": "point", "position": [0, 0, 3], "intensity": [9, 9, 9]})") + R"(],
    "objects": [{"type": "gltf", "file": "quad.glb"}]})");
  return load_scene(dir / "scene.json");
}

// A quad whose base colour and emission textures have transforms of their own (KHR_texture_transform),
// which the shaders apply (a material whose textures share one has it applied to its coordinates
// on the host instead, scene_loader.cpp), over a white floor that its textured emission lights
// through light sampling.
Scene transformed_textures_quad(bool path) {
  GltfBuilder b;
  const int texture = b.texture(png_bytes(four_colours()), {{"magFilter", 9728}});
  const nlohmann::json turned = {{"KHR_texture_transform", {{"offset", {0.1, 0.2}}, {"rotation", 0.4}, {"scale", {1.5, 0.75}}}}};
  const nlohmann::json moved = {{"KHR_texture_transform", {{"offset", {0.5, 0.0}}}}};
  b.quad(b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", texture}, {"extensions", turned}}}, {"metallicFactor", 0}}},
                     {"emissiveTexture", {{"index", texture}, {"extensions", moved}}},
                     {"emissiveFactor", {1, 1, 1}},
                     {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 3}}}}}}));
  b.doc["extensionsUsed"] = {"KHR_texture_transform", "KHR_materials_emissive_strength"};
  TempDir dir;
  write_file(dir / "quad.glb", b.glb());
  const std::string integrator = path ? R"({"type": "path", "max_depth": 3})" : R"({"type": "direct"})";
  write_file(dir / "scene.json", R"({"camera": {"position": [0, 1.5, 4], "look_at": [0, -0.4, 0], "vertical_fov": 45},
    "integrator": )" + integrator + R"(, "background": [0.2, 0.2, 0.2],
    "lights": [{"type": "point", "position": [0, 0, 3], "intensity": [4, 4, 4]}],
    "materials": {"floor": {"albedo": [0.8, 0.8, 0.8]}},
    "objects": [{"type": "gltf", "file": "quad.glb"},
                {"type": "triangles", "material": "floor", "positions": [[-3, -1.2, -2], [3, -1.2, -2], [3, -1.2, 4], [-3, -1.2, 4]],
                 "indices": [[0, 2, 1], [0, 3, 2]]}]})");
  return load_scene(dir / "scene.json");
}

TEST(TextureTransformTest, TexturesWithTransformsOfTheirOwnKeepThem) {
  const Scene scene = transformed_textures_quad(false);
  ASSERT_EQ(scene.materials.size(), 2u);  // the floor's, then the quad's
  EXPECT_TRUE(scene.materials[1].albedo_texture.transformed());
  EXPECT_TRUE(scene.materials[1].emission_texture.transformed());
}

class TextureTransformParityTest : public ParityTest, public ::testing::WithParamInterface<bool> {};

TEST_P(TextureTransformParityTest, BothRenderersTransformAlike) {
  const bool path = GetParam();
  expect_parity(run(transformed_textures_quad(path), {96, 96, path ? 16u : 4u}), path ? "transforms-path" : "transforms-direct");
}

INSTANTIATE_TEST_SUITE_P(Integrators, TextureTransformParityTest, ::testing::Bool(),
                         [](const auto& p) { return std::string(p.param ? "path" : "direct"); });

struct Sampling {
  const char* name;
  nlohmann::json sampler;
};

class TextureParityTest : public ParityTest, public ::testing::WithParamInterface<std::tuple<Sampling, bool>> {};

TEST_P(TextureParityTest, BothRenderersShowTheTextureAlike) {
  const auto& [sampling, path] = GetParam();
  const Scene scene = textured_quad(sampling.sampler, path);
  const ParityResult r = run(scene, {96, 96, path ? 16u : 4u});
  expect_parity(r, std::string("texture-") + sampling.name + (path ? "-path" : "-direct"));
  // The middle of the quad's texture coordinates, (0.5, 0.5), is at the image's centre; a quarter
  // of the way in from the centre toward the top left lies (0.25, 0.25) of the texture: red.
  for (const Image* image : {&r.gpu.image, &r.cpu.image}) {
    const glm::vec3 top_left = image->at(40, 40), bottom_left = image->at(40, 56);
    EXPECT_GT(top_left.r, 2.0f * top_left.g) << sampling.name << (image == &r.gpu.image ? " GPU" : " CPU");
    EXPECT_GT(bottom_left.b, 2.0f * bottom_left.r) << sampling.name << (image == &r.gpu.image ? " GPU" : " CPU");
  }
}

INSTANTIATE_TEST_SUITE_P(
    Samplers, TextureParityTest,
    ::testing::Combine(::testing::Values(Sampling{"default", nullptr}, Sampling{"nearest", {{"magFilter", 9728}}},
                                         Sampling{"clamp", {{"wrapS", 33071}, {"wrapT", 33071}}},
                                         Sampling{"mirrored", {{"wrapS", 33648}, {"wrapT", 33648}, {"magFilter", 9728}}}),
                       ::testing::Bool()),
    [](const auto& p) { return std::string(std::get<0>(p.param).name) + (std::get<1>(p.param) ? "Path" : "Direct"); });

TEST_F(ParityTest, AnEmissiveTextureLightsTheSceneAlike) {
  const Scene scene = textured_quad(nullptr, true, true);
  const ParityResult r = run(scene, {96, 96, 16});
  expect_parity(r, "texture-emissive");
  const glm::vec3 red = r.gpu.image.at(37, 37);  // texture coordinate (0.25, 0.25): the red texel's centre, emitting 2
  EXPECT_GT(red.r, 1.5f);
  EXPECT_LT(red.g, 0.2f);
}

// The same picture with 16-bit samples (v * 257), as libpng's simplified API writes it: tagged as
// linear light (gAMA 1.0), a tag glTF says to ignore, as vkray ignores it in every texture.
std::string sixteen_bit_png(const TestPicture& picture) {
  std::vector<uint16_t> samples(picture.rgb.begin(), picture.rgb.end());
  std::transform(samples.begin(), samples.end(), samples.begin(), [](uint16_t v) { return uint16_t(v * 257); });
  png_image header{};
  header.version = PNG_IMAGE_VERSION;
  header.width = picture.width;
  header.height = picture.height;
  header.format = PNG_FORMAT_LINEAR_RGB;
  std::string out(PNG_IMAGE_PNG_SIZE_MAX(header), '\0');
  png_alloc_size_t size = out.size();
  EXPECT_TRUE(png_image_write_to_memory(&header, out.data(), &size, 0, samples.data(), 0, nullptr)) << header.message;
  out.resize(size);
  return out;
}

TEST_F(ParityTest, APictureRendersTheSameInEightAndSixteenBits) {
  // A mid grey, a colour, a dark and a light one, each filling a quarter of the quad (nearest).
  const TestPicture picture{2, 2, {128, 128, 128, 200, 100, 50, 30, 60, 90, 240, 230, 220}};
  const nlohmann::json nearest = {{"magFilter", 9728}};
  const ParityResult eight = run(textured_quad(nearest, false, false, png_bytes(picture)), {48, 48, 4});
  const ParityResult sixteen = run(textured_quad(nearest, false, false, sixteen_bit_png(picture)), {48, 48, 4});
  expect_parity(sixteen, "texture-16-bit");
  for (const auto& [a, b] : {std::pair{&eight.gpu.image, &sixteen.gpu.image}, std::pair{&eight.cpu.image, &sixteen.cpu.image}}) {
    float most = 0.0f;
    for (uint32_t y = 0; y < 48; ++y)
      for (uint32_t x = 0; x < 48; ++x) most = std::max(most, glm::length(a->at(x, y) - b->at(x, y)));
    EXPECT_LE(most, 1e-6f) << (a == &eight.gpu.image ? "GPU" : "CPU") << ": the 16-bit picture renders unlike the 8-bit one";
  }
}

// A shader that reads textures upside down (v where it should read 1 - v: the slip between OBJ's and
// glTF's conventions) must fail parity.
class UpsideDownTextureTest : public BrokenShaderParityTest {
 protected:
  UpsideDownTextureTest()
      : BrokenShaderParityTest("texture.glsl", "y = reduce_coordinate(uv.y, wrap_t)", "y = reduce_coordinate(1.0 - uv.y, wrap_t)") {}
};

TEST_F(UpsideDownTextureTest, FailsParity) {
  const ParityResult r = run(textured_quad({{"magFilter", 9728}}, false), {96, 96, 1});
  EXPECT_FALSE(r.metrics.pass);
  EXPECT_GT(r.metrics.interior_over_1, 100u);
}

// A shader that ignores KHR_texture_transform (the texture read at the primitive's own coordinate)
// must fail parity where textures keep their transforms.
class TextureTransformIgnoredTest : public BrokenShaderParityTest {
 protected:
  TextureTransformIgnoredTest() : BrokenShaderParityTest("texture.glsl", "if (texture_transformed(t.mode)) {", "if (false) {") {}
};

TEST_F(TextureTransformIgnoredTest, FailsParity) {
  for (const bool path : {false, true}) {
    const ParityResult r = run(transformed_textures_quad(path), {96, 96, path ? 16u : 4u});
    EXPECT_FALSE(r.metrics.pass) << (path ? "paths" : "direct");
  }
}

// A shader whose camera rays meet the back faces of single-sided triangles must fail parity on the
// Khronos model that tests doubleSided (its "single-sided" row shows the red X behind the quad then).
class SingleSidedIgnoredTest : public BrokenShaderParityTest {
 protected:
  SingleSidedIgnoredTest()
      : BrokenShaderParityTest("traversal.glsl", "if (SCENE_HAS_SINGLE_SIDED && cull_back && t > 0.0 && culled(ray, a, b, c)) t = -1.0;",
                               "") {}
};

TEST_F(SingleSidedIgnoredTest, FailsParity) {
  const Scene scene = load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "gltf/TextureSettingsTest/glTF/TextureSettingsTest.gltf");
  const ParityResult r = run(scene, {96, 96, 1}, InlineScene::never);
  EXPECT_FALSE(r.metrics.pass);
}

// Every shipped glTF sample model, as the scene it makes by itself, renders alike on both
// renderers: their textures (PNG with a palette, a progressive JPEG), samplers, texture transforms,
// materials and hierarchies.
class ShippedModelTest : public ParityTest, public ::testing::WithParamInterface<const char*> {};

TEST_P(ShippedModelTest, HoldsParity) {
  const Scene scene = load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "gltf" / GetParam());
  EXPECT_TRUE(!scene.triangles.empty() || !scene.instances.empty());
  expect_parity(run(scene, {96, 96, 1}), std::filesystem::path(GetParam()).stem().string());
}

INSTANTIATE_TEST_SUITE_P(Khronos, ShippedModelTest,
                         ::testing::Values("BoxTextured/glTF/BoxTextured.gltf", "BoxTextured/glTF-Binary/BoxTextured.glb",
                                           "BoxTextured/glTF-Embedded/BoxTextured.gltf", "CesiumMilkTruck/glTF/CesiumMilkTruck.gltf",
                                           "TextureSettingsTest/glTF/TextureSettingsTest.gltf",
                                           "TextureCoordinateTest/glTF/TextureCoordinateTest.gltf", "Cameras/glTF/Cameras.gltf",
                                           "TextureTransformTest/glTF/TextureTransformTest.gltf",
                                           "MetalRoughSpheresNoTextures/glTF-Binary/MetalRoughSpheresNoTextures.glb",
                                           "NormalTangentTest/glTF/NormalTangentTest.gltf",
                                           "NormalTangentMirrorTest/glTF/NormalTangentMirrorTest.gltf", "TwoSidedPlane/glTF/TwoSidedPlane.gltf",
                                           "AlphaBlendModeTest/glTF/AlphaBlendModeTest.gltf",
                                           "TransmissionTest/glTF-Binary/TransmissionTest.glb",
                                           "BoxVertexColors/glTF-Binary/BoxVertexColors.glb",
                                           "VertexColorTest/glTF-Binary/VertexColorTest.glb",
                                           "SimpleSparseAccessor/glTF-Embedded/SimpleSparseAccessor.gltf",
                                           "SimpleMorph/glTF-Embedded/SimpleMorph.gltf",
                                           "SimpleInstancing/glTF-Binary/SimpleInstancing.glb", "UnlitTest/glTF-Binary/UnlitTest.glb",
                                           "MultiUVTest/glTF-Binary/MultiUVTest.glb",
                                           "TextureEncodingTest/glTF-Binary/TextureEncodingTest.glb",
                                           "LightsPunctualLamp/glTF/LightsPunctualLamp.gltf"),
                         [](const auto& p) {
                           std::string name = std::filesystem::path(p.param).parent_path().string();
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

}  // namespace
}  // namespace vkray::test
