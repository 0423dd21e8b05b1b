// Textures: PNG and JPEG decoding with its limits, the sRGB decode, the CPU reference's filtering
// and wrap modes, textures from an OBJ file's .mtl, and how they are packed for the shader.
#include <gtest/gtest.h>

#include "base/errors.h"
#include "cpu/texture.h"
#include "image/decode.h"
#include "image/image.h"
#include "packing/scene_packing.h"
#include "load/scene_loader.h"
#include "scene/scene.h"
#include "scene/texture.h"
#include "support/error_of.h"
#include "support/temp_dir.h"
#include "support/test_assets.h"

namespace vkray {
namespace {

using test::four_colours;

using test::error_of;

TEST(PictureTest, DecodesPngExactly) {
  const Picture p = decode_picture(test::png_bytes(four_colours()), "four.png");
  ASSERT_EQ(p.width, 2u);
  ASSERT_EQ(p.height, 2u);
  const std::vector<uint8_t> expected = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
  EXPECT_EQ(p.rgba, expected);
}

TEST(PictureTest, DecodesJpegClosely) {
  test::TestPicture flat{16, 16, std::vector<uint8_t>(16 * 16 * 3, 0)};
  for (size_t i = 0; i < flat.rgb.size(); i += 3) flat.rgb[i] = 200, flat.rgb[i + 1] = 100, flat.rgb[i + 2] = 50;
  const Picture p = decode_picture(test::jpeg_bytes(flat), "flat.jpg");
  ASSERT_EQ(p.width, 16u);
  for (size_t i = 0; i < p.rgba.size(); i += 4) {
    EXPECT_NEAR(p.rgba[i], 200, 2);
    EXPECT_NEAR(p.rgba[i + 1], 100, 2);
    EXPECT_NEAR(p.rgba[i + 2], 50, 2);
    EXPECT_EQ(p.rgba[i + 3], 255);
  }
}

TEST(PictureTest, RefusesAnAbsurdSizeBeforeDecoding) {
  // The header claims 100000 x 100000 pixels (40 GB as RGBA): refused from the header alone.
  const std::string message = error_of([] { decode_picture(test::png_header_only(100000, 100000), "huge.png"); });
  EXPECT_NE(message.find("huge.png: a picture of 100000 x 100000 pixels; vkray decodes at most 16384"), std::string::npos) << message;
  const std::string wide = error_of([] { decode_picture(test::png_header_only(16384, 8192), "wide.png"); });
  EXPECT_NE(wide.find("at most 16384 on a side and 64M pixels"), std::string::npos) << wide;
}

TEST(PictureTest, NamesWhatIsWrongWithAFile) {
  EXPECT_NE(error_of([] { decode_picture("GIF89a...", "a.gif"); }).find("a.gif: not a PNG or JPEG file"), std::string::npos);
  EXPECT_NE(error_of([] { decode_picture("", "empty.png"); }).find("empty.png: the picture is empty"), std::string::npos);
  std::string truncated = test::png_bytes(four_colours());
  truncated.resize(truncated.size() - 20);
  EXPECT_NE(error_of([&] { decode_picture(truncated, "cut.png"); }).find("cut.png: a damaged PNG file"), std::string::npos);
  std::string jpeg = test::jpeg_bytes(four_colours());
  jpeg.resize(40);
  EXPECT_NE(error_of([&] { decode_picture(jpeg, "cut.jpg"); }).find("cut.jpg: "), std::string::npos);
}

TEST(TextureTest, DecodesSrgbToLinearHalves) {
  const Texture t = make_texture(decode_picture(test::png_bytes({1, 1, {255, 128, 0}}), "x.png"), "x.png");
  const glm::vec4 texel = t.texel(0, 0);
  EXPECT_EQ(texel.r, 1.0f);
  EXPECT_NEAR(texel.g, decode_srgb8(128), 1e-3);  // 0.2158, rounded to a half float
  EXPECT_EQ(texel.b, 0.0f);
  EXPECT_EQ(texel.a, 1.0f);
  const Texture linear = make_texture(decode_picture(test::png_bytes({1, 1, {255, 128, 0}}), "x.png"), "x.png", false);
  EXPECT_NEAR(linear.texel(0, 0).g, 128.0f / 255.0f, 1e-3);
}

// A scene with one 2 x 2 texture of four colours, for the lookups below.
Scene four_colour_scene() {
  Scene scene;
  scene.textures.push_back(std::make_shared<const Texture>(make_texture(decode_picture(test::png_bytes(four_colours()), "4.png"), "4.png")));
  return scene;
}

TEST(TextureTest, NearestPicksTheTexelUnderTheCoordinate) {
  const Scene scene = four_colour_scene();
  TextureRef ref{0, TextureWrap::repeat, TextureWrap::repeat, TextureFilter::nearest};
  EXPECT_EQ(cpu::sample_texture(scene, ref, {0.25, 0.25}), glm::dvec3(1, 0, 0));  // top left: red
  EXPECT_EQ(cpu::sample_texture(scene, ref, {0.75, 0.25}), glm::dvec3(0, 1, 0));  // top right: green
  EXPECT_EQ(cpu::sample_texture(scene, ref, {0.25, 0.75}), glm::dvec3(0, 0, 1));  // bottom left: blue
  EXPECT_EQ(cpu::sample_texture(scene, ref, {1.25, -0.25}), glm::dvec3(0, 0, 1));  // repeat: (0.25, 0.75)
  ref.wrap_s = ref.wrap_t = TextureWrap::clamp_to_edge;
  EXPECT_EQ(cpu::sample_texture(scene, ref, {7.0, -3.0}), glm::dvec3(0, 1, 0));  // clamped to the top right
  ref.wrap_s = ref.wrap_t = TextureWrap::mirrored_repeat;
  EXPECT_EQ(cpu::sample_texture(scene, ref, {1.25, 0.25}), glm::dvec3(0, 1, 0));  // mirrored: u 0.75
  EXPECT_EQ(cpu::sample_texture(scene, ref, {-0.25, 0.25}), glm::dvec3(1, 0, 0));  // mirrored: u 0.25
}

TEST(TextureTest, BilinearBlendsTheFourNearestTexelCentres) {
  const Scene scene = four_colour_scene();
  TextureRef ref{0, TextureWrap::clamp_to_edge, TextureWrap::clamp_to_edge, TextureFilter::linear};
  const glm::dvec3 centre = cpu::sample_texture(scene, ref, {0.5, 0.5});  // all four, equally
  EXPECT_NEAR(centre.r, 0.5, 1e-6);
  EXPECT_NEAR(centre.g, 0.5, 1e-6);
  EXPECT_NEAR(centre.b, 0.5, 1e-6);
  EXPECT_EQ(cpu::sample_texture(scene, ref, {0.25, 0.25}), glm::dvec3(1, 0, 0));  // a texel centre: that texel
  EXPECT_EQ(cpu::sample_texture(scene, ref, {0.0, 0.0}), glm::dvec3(1, 0, 0));    // clamped at the corner
  ref.wrap_s = ref.wrap_t = TextureWrap::repeat;
  const glm::dvec3 corner = cpu::sample_texture(scene, ref, {0.0, 0.0});  // repeat: the four corners' texels, equally
  EXPECT_NEAR(corner.r, 0.5, 1e-6);
  EXPECT_NEAR(corner.b, 0.5, 1e-6);
}

TEST(TextureTest, PackingNamesEachTextureForTheShader) {
  Scene scene = four_colour_scene();
  scene.textures.push_back(scene.textures[0]);
  Material m;
  m.albedo_texture = {1, TextureWrap::mirrored_repeat, TextureWrap::clamp_to_edge, TextureFilter::nearest};
  scene.materials.push_back(m);
  Triangle t;
  t.v = {glm::vec3(0, 0, 0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)};
  t.uv = {glm::vec2(0.1f, 0.2f), glm::vec2(0.3f, 0.4f), glm::vec2(0.5f, 0.6f)};
  scene.triangles.push_back(t);
  const Bvh bvh = build_bvh(primitive_boxes(scene));
  const gpu::PackedScene packed = gpu::pack_scene(scene, bvh);
  ASSERT_EQ(packed.textures.size(), 2u * 4 * 4);  // two 2 x 2 textures, four halves a texel
  const gpu::TextureHeader h = gpu::texture_header(packed.materials[VKRAY_MATERIAL_ALBEDO_TEXTURE]);
  EXPECT_EQ(h.first, 4u);  // after the first texture's 4 texels
  EXPECT_EQ(h.width, 2u);
  EXPECT_EQ(h.height, 2u);
  EXPECT_EQ(gpu::texture_wrap_s(h.mode), VKRAY_WRAP_MIRRORED_REPEAT);
  EXPECT_EQ(gpu::texture_wrap_t(h.mode), VKRAY_WRAP_CLAMP_TO_EDGE);
  EXPECT_EQ(gpu::texture_filter(h.mode), VKRAY_FILTER_NEAREST);
  EXPECT_EQ(gpu::floatBitsToUint(packed.materials[VKRAY_MATERIAL_EMISSION_TEXTURE].y), 0u);  // no emission texture
  EXPECT_EQ(packed.texcoords[0], glm::vec4(0.1f, 0.2f, 0.3f, 0.4f));
  EXPECT_EQ(packed.texcoords[1], glm::vec4(0.5f, 0.6f, 0.0f, 0.0f));
}

class ObjMaterialTest : public ::testing::Test {
 protected:
  void write(const std::string& name, const std::string& text) { test::write_file(dir_ / name, text); }
  Scene load(const std::string& object) {
    write("scene.json", R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "vertical_fov": 40},
                            "lights": [{"type": "point", "position": [0, 0, 5], "intensity": [10, 10, 10]}],
                            "materials": {"grey": {"albedo": [0.5, 0.5, 0.5]}},
                            "objects": [)" + object + "]}");
    return load_scene(dir_ / "scene.json");
  }
  test::TempDir dir_;
};

constexpr const char* kTexturedQuad =
    "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "usemtl checker\nf 1/1 2/2 3/3\nusemtl plain\nf 1/1 3/3 4/4\n";

TEST_F(ObjMaterialTest, MapKdTexturesTheFacesThatNameItsMaterial) {
  write("quad.obj", kTexturedQuad);
  write("quad.mtl", "newmtl checker\nKd 1 1 1\nmap_Kd -clamp on tex/four.png\nnewmtl plain\nKd 0.2 0.4 0.6\nKs 0.5 0.5 0.5\n");
  std::filesystem::create_directories(dir_ / "tex");
  test::write_file(dir_ / "tex/four.png", test::png_bytes(four_colours()));
  const Scene scene = load(R"({"type": "mesh", "file": "quad.obj"})");
  ASSERT_EQ(scene.triangles.size(), 2u);
  ASSERT_EQ(scene.textures.size(), 1u);
  const Material& checker = scene.materials[scene.triangles[0].material];
  const Material& plain = scene.materials[scene.triangles[1].material];
  EXPECT_EQ(checker.name, "quad.obj: checker");
  EXPECT_EQ(checker.albedo_texture.texture, 0);
  EXPECT_EQ(checker.albedo_texture.wrap_s, TextureWrap::clamp_to_edge);
  EXPECT_FALSE(plain.textured());
  EXPECT_EQ(plain.albedo, glm::vec3(0.2f, 0.4f, 0.6f));
  // OBJ's v runs up from the bottom: vt (0, 1) is the picture's top left, (0, 0) in vkray's terms.
  EXPECT_EQ(scene.triangles[1].uv[2], glm::vec2(0.0f, 0.0f));
  EXPECT_EQ(scene.triangles[0].uv[0], glm::vec2(0.0f, 1.0f));
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings[0];
  // The watch face reloads when any of them changes.
  for (const char* f : {"quad.obj", "quad.mtl", "tex/four.png"})
    EXPECT_NE(std::find(scene.referenced_files.begin(), scene.referenced_files.end(), (dir_ / f).lexically_normal()),
              scene.referenced_files.end()) << f;
}

TEST_F(ObjMaterialTest, AFilePlacedTwiceBringsItsMaterialsOnce) {
  // Faces before the first usemtl take the file's "(no usemtl)" grey; the library has a line vkray
  // warns about. Placed twice, the file's materials, textures and warnings are the scene's once.
  write("quad.obj", "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                    "f 1/1 2/2 4/4\nusemtl checker\nf 1/1 2/2 3/3\nusemtl plain\nf 1/1 3/3 4/4\n");
  write("quad.mtl", "newmtl checker\nKd 1 1 1\nmap_Kd tex/four.png\nnewmtl plain\nKd 0.2 0.4 0.6\nmap_Bump bump.png\n");
  std::filesystem::create_directories(dir_ / "tex");
  test::write_file(dir_ / "tex/four.png", test::png_bytes(four_colours()));
  const Scene once = load(R"({"type": "mesh", "file": "quad.obj"})");
  const Scene twice = load(R"({"type": "mesh", "file": "quad.obj"}, {"type": "mesh", "file": "quad.obj", "transform": {"translate": [0, 0, 1]}})");
  EXPECT_EQ(twice.materials.size(), once.materials.size());
  EXPECT_EQ(twice.textures.size(), 1u);
  ASSERT_EQ(once.warnings.size(), 1u);
  EXPECT_NE(once.warnings[0].find("map_Bump: not rendered"), std::string::npos) << once.warnings[0];
  EXPECT_EQ(twice.warnings, once.warnings);
  EXPECT_EQ(once.materials[once.triangles[0].material].name, "quad.obj: (no usemtl)");
  ASSERT_EQ(twice.triangles.size(), 2 * once.triangles.size());
  for (size_t i = 0; i < once.triangles.size(); ++i) {
    EXPECT_EQ(twice.triangles[i].material, once.triangles[i].material) << i;
    EXPECT_EQ(twice.triangles[once.triangles.size() + i].material, once.triangles[i].material) << i;
  }
}

TEST_F(ObjMaterialTest, ASceneMaterialOverridesTheFileAndNeedsNoLibrary) {
  write("quad.obj", kTexturedQuad);  // quad.mtl does not exist
  const Scene scene = load(R"({"type": "mesh", "file": "quad.obj", "material": "grey"})");
  EXPECT_EQ(scene.triangles[0].material, 0u);
  EXPECT_TRUE(scene.textures.empty());
}

TEST_F(ObjMaterialTest, BadLibrariesAndTexturesNameTheFileAndLine) {
  write("quad.obj", kTexturedQuad);
  const std::string missing = error_of([&] { load(R"({"type": "mesh", "file": "quad.obj"})"); });
  EXPECT_NE(missing.find("/objects/0/file: quad.obj: mtllib quad.mtl: material library not found"), std::string::npos) << missing;

  write("quad.mtl", "newmtl checker\nKd 1 nan 1\n");
  const std::string colour = error_of([&] { load(R"({"type": "mesh", "file": "quad.obj"})"); });
  EXPECT_NE(colour.find("quad.mtl:2: Kd: expected 1 or 3 non-negative numbers"), std::string::npos) << colour;

  write("quad.mtl", "newmtl checker\nmap_Kd gone.png\nnewmtl plain\n");
  const std::string texture = error_of([&] { load(R"({"type": "mesh", "file": "quad.obj"})"); });
  EXPECT_NE(texture.find("gone.png: texture file not found"), std::string::npos) << texture;

  write("quad.mtl", "newmtl checker\nmap_Kd huge.png\nnewmtl plain\n");
  test::write_file(dir_ / "huge.png", test::png_header_only(100000, 4));
  const std::string huge = error_of([&] { load(R"({"type": "mesh", "file": "quad.obj"})"); });
  EXPECT_NE(huge.find("huge.png: a picture of 100000 x 4 pixels"), std::string::npos) << huge;

  write("quad.mtl", "newmtl checker\n");
  const std::string undefined = error_of([&] { load(R"({"type": "mesh", "file": "quad.obj"})"); });
  EXPECT_NE(undefined.find("usemtl plain: no material library it names (mtllib) defines it"), std::string::npos) << undefined;
}

TEST_F(ObjMaterialTest, RepeatingCoordinatesAreMovedNearZeroWholePeriodsAtATime) {
  // A floor tiled thousands of times: both renderers then interpolate small numbers (float and
  // double would otherwise sample it half a texel apart). Clamped axes stay where they are.
  write("far.obj", "mtllib far.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 5000.25 -3001.5\nvt 5001.75 -3001\nvt 5000.5 -2999\n"
                   "usemtl repeat\nf 1/1 2/2 3/3\nusemtl clamp\nf 1/1 2/2 3/3\n");
  write("far.mtl", "newmtl repeat\nmap_Kd four.png\nnewmtl clamp\nmap_Kd -clamp on four.png\n");
  test::write_file(dir_ / "four.png", test::png_bytes(four_colours()));
  const Scene scene = load(R"({"type": "mesh", "file": "far.obj"})");
  ASSERT_EQ(scene.triangles.size(), 2u);
  // u: 5000.25 - 5000; v (flipped: 1 - v, so 3002.5 ...): minus 3000.
  EXPECT_EQ(scene.triangles[0].uv[0], glm::vec2(0.25f, 2.5f));
  EXPECT_EQ(scene.triangles[0].uv[1], glm::vec2(1.75f, 2.0f));
  EXPECT_EQ(scene.triangles[1].uv[0], glm::vec2(5000.25f, 3002.5f));
  const std::string past = error_of([&] {
    write("far.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 2e9 0\nf 1/1 2/1 3/1\n");
    load(R"({"type": "mesh", "file": "far.obj", "material": "grey"})");
  });
  EXPECT_NE(past.find("far.obj:4: texture coordinate"), std::string::npos) << past;
}

TEST_F(ObjMaterialTest, WhatIsNotRenderedIsNamedOnce) {
  write("quad.obj", kTexturedQuad);
  write("quad.mtl", "newmtl checker\nd 0.5\nmap_Bump b.png\nbump b.png\nnewmtl plain\nd 0.3\n");
  const Scene scene = load(R"({"type": "mesh", "file": "quad.obj"})");
  ASSERT_EQ(scene.warnings.size(), 3u);
  EXPECT_NE(scene.warnings[0].find("quad.mtl:2: d: transparency is not rendered"), std::string::npos) << scene.warnings[0];
  EXPECT_NE(scene.warnings[1].find("map_Bump: not rendered"), std::string::npos) << scene.warnings[1];
}

}  // namespace
}  // namespace vkray
