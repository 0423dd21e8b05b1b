// Textures: PNG and JPEG decoding with its limits, every encoding of a sample decoding to the same
// colour, the sRGB decode, the CPU reference's filtering and wrap modes, textures from an OBJ file's
// .mtl, and how they are packed for the shader.
#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>

#include <Imath/half.h>
#include <gtest/gtest.h>
#include <png.h>
#include <turbojpeg.h>

#include "base/errors.h"
#include "cpu/texture.h"
#include "gltf/gltf.h"
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

// ---- Every encoding of a sample decodes to the same colour ----------------------------------------
// A picture's samples can be stored in many ways; the same intended value must give the same texel.
// The files are written with libpng's full API so that each test states exactly what its file holds.

// One pixel's worth of samples (and the file around them), in the order the colour type stores them.
// Each case below names only the fields it sets; the others keep their defaults, as intended.
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
struct PngSpec {
  int bit_depth = 8;
  int colour_type = PNG_COLOR_TYPE_RGB;
  std::vector<uint16_t> samples;      // one pixel, then the picture repeats it over 2 x 2
  std::vector<png_color> palette;     // PNG_COLOR_TYPE_PALETTE: samples are indices
  std::vector<png_byte> palette_alpha;  // tRNS for the palette
  std::optional<double> file_gamma;   // a gAMA chunk (1.0: "linear")
  bool srgb_chunk = false;
  bool iccp_chunk = false;            // a (minimal, well-formed) ICC profile of a grey or RGB display
  bool interlaced = false;            // Adam7
};

// A 132-byte ICC header with no tags: enough for libpng to accept and store it.
std::string minimal_icc_profile(bool grey) {
  std::string p(132, '\0');
  const auto be32 = [&](size_t at, uint32_t v) {
    for (int k = 0; k < 4; ++k) p[at + size_t(k)] = char((v >> (24 - 8 * k)) & 0xff);
  };
  be32(0, 132);
  be32(8, 0x02100000);  // version 2.1
  std::memcpy(&p[12], "mntr", 4);
  std::memcpy(&p[16], grey ? "GRAY" : "RGB ", 4);
  std::memcpy(&p[20], "XYZ ", 4);
  std::memcpy(&p[36], "acsp", 4);
  be32(68, 0x0000f6d6), be32(72, 0x00010000), be32(76, 0x0000d32d);  // the D50 illuminant
  return p;
}

std::string png_file(const PngSpec& spec) {
  constexpr uint32_t kSide = 2;
  std::string out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  png_set_write_fn(png, &out, [](png_structp p, png_bytep data, size_t length) {
    static_cast<std::string*>(png_get_io_ptr(p))->append(reinterpret_cast<const char*>(data), length);
  }, nullptr);
  png_set_IHDR(png, info, kSide, kSide, spec.bit_depth, spec.colour_type, spec.interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (!spec.palette.empty()) png_set_PLTE(png, info, spec.palette.data(), int(spec.palette.size()));
  if (!spec.palette_alpha.empty()) png_set_tRNS(png, info, spec.palette_alpha.data(), int(spec.palette_alpha.size()), nullptr);
  if (spec.file_gamma) png_set_gAMA(png, info, *spec.file_gamma);
  if (spec.srgb_chunk) png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  const std::string icc = minimal_icc_profile(!(spec.colour_type & PNG_COLOR_MASK_COLOR));
  if (spec.iccp_chunk) png_set_iCCP(png, info, "display", 0, reinterpret_cast<png_const_bytep>(icc.data()), png_uint_32(icc.size()));
  png_write_info(png, info);
  // The samples packed big-endian at the bit depth, the first sample in the highest bits.
  std::vector<png_byte> row;
  uint32_t bits = 0, pending = 0;
  for (uint32_t x = 0; x < kSide; ++x)
    for (const uint16_t s : spec.samples) {
      pending = (pending << spec.bit_depth) | s;
      for (bits += uint32_t(spec.bit_depth); bits >= 8; bits -= 8) row.push_back(png_byte(pending >> (bits - 8)));
    }
  if (bits > 0) row.push_back(png_byte(pending << (8 - bits)));
  const int passes = png_set_interlace_handling(png);
  for (int pass = 0; pass < passes; ++pass)
    for (uint32_t y = 0; y < kSide; ++y) png_write_row(png, row.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

// A greyscale (one-component) JPEG of a flat grey, 8 x 8.
std::string grey_jpeg(uint8_t grey) {
  const std::unique_ptr<void, int (*)(tjhandle)> handle(tjInitCompress(), tjDestroy);
  const std::vector<uint8_t> pixels(64, grey);
  unsigned char* jpeg = nullptr;
  unsigned long size = 0;
  EXPECT_EQ(tjCompress2(handle.get(), pixels.data(), 8, 0, 8, TJPF_GRAY, &jpeg, &size, TJSAMP_GRAY, 100, 0), 0);
  std::string out(reinterpret_cast<const char*>(jpeg), size);
  tjFree(jpeg);
  return out;
}

glm::vec4 decoded(const std::string& bytes, bool srgb = true) { return make_texture(decode_picture(bytes, "t.png"), "t.png", srgb).texel(1, 1); }

// The texel the 8-bit RGBA file of these samples decodes to: the reference the other encodings must meet.
glm::vec4 reference(uint8_t r, uint8_t g, uint8_t b, uint8_t a = 255, bool srgb = true) {
  return decoded(png_file({8, PNG_COLOR_TYPE_RGB_ALPHA, {r, g, b, a}}), srgb);
}

TEST(PictureEncodingTest, SixteenBitSamplesAreTheSameColourAsEightBit) {
  // v in 8 bits is v * 257 in 16 (255 -> 65535): both name the same fraction of full scale.
  const glm::vec4 grey = reference(128, 128, 128), colour = reference(200, 100, 50);
  EXPECT_NEAR(grey.r, 0.2158f, 1e-3f);  // sRGB 128: a fifth of white's light, not a half
  EXPECT_EQ(decoded(png_file({16, PNG_COLOR_TYPE_RGB, {128 * 257, 128 * 257, 128 * 257}})), grey);
  EXPECT_EQ(decoded(png_file({16, PNG_COLOR_TYPE_RGB, {200 * 257, 100 * 257, 50 * 257}})), colour);
  EXPECT_EQ(decoded(png_file({16, PNG_COLOR_TYPE_RGB_ALPHA, {200 * 257, 100 * 257, 50 * 257, 65535}})), colour);
  EXPECT_EQ(decoded(png_file({16, PNG_COLOR_TYPE_GRAY, {128 * 257}})), grey);
  EXPECT_EQ(decoded(png_file({16, PNG_COLOR_TYPE_GRAY_ALPHA, {128 * 257, 65535}})), grey);
  EXPECT_EQ(decoded(png_file({.bit_depth = 16, .colour_type = PNG_COLOR_TYPE_GRAY, .samples = {128 * 257}, .interlaced = true})), grey);
  // Linear data (not sRGB) is the same in either depth, too.
  EXPECT_EQ(decoded(png_file({16, PNG_COLOR_TYPE_RGB, {200 * 257, 100 * 257, 50 * 257}}), false), reference(200, 100, 50, 255, false));
  // A 16-bit file keeps its precision: half-way between 8-bit 128 and 129 decodes between them.
  const float between = decoded(png_file({16, PNG_COLOR_TYPE_GRAY, {128 * 257 + 128}})).r;
  EXPECT_GT(between, grey.r);
  EXPECT_LT(between, reference(129, 129, 129).r);
}

TEST(PictureEncodingTest, GreyPaletteAndAlphaAreTheSameColourAsRgb) {
  const glm::vec4 grey = reference(128, 128, 128), colour = reference(200, 100, 50);
  EXPECT_EQ(decoded(png_file({8, PNG_COLOR_TYPE_GRAY, {128}})), grey);
  EXPECT_EQ(decoded(png_file({8, PNG_COLOR_TYPE_RGB, {128, 128, 128}})), grey);
  EXPECT_EQ(decoded(png_file({8, PNG_COLOR_TYPE_GRAY_ALPHA, {128, 64}})), reference(128, 128, 128, 64));
  EXPECT_EQ(decoded(png_file({16, PNG_COLOR_TYPE_GRAY_ALPHA, {128 * 257, 64 * 257}})), reference(128, 128, 128, 64));
  EXPECT_EQ(decoded(png_file({16, PNG_COLOR_TYPE_RGB_ALPHA, {200 * 257, 100 * 257, 50 * 257, 64 * 257}})), reference(200, 100, 50, 64));
  // Fewer than 8 bits scale to full range: 4-bit 8 is 8 * 17 = 136, 1-bit 1 is 255.
  EXPECT_EQ(decoded(png_file({4, PNG_COLOR_TYPE_GRAY, {8}})), reference(136, 136, 136));
  EXPECT_EQ(decoded(png_file({1, PNG_COLOR_TYPE_GRAY, {1}})), reference(255, 255, 255));
  // A palette, 8-bit and 2-bit indices, with and without alpha (tRNS).
  const std::vector<png_color> palette = {{0, 0, 0}, {200, 100, 50}, {128, 128, 128}};
  EXPECT_EQ(decoded(png_file({8, PNG_COLOR_TYPE_PALETTE, {1}, palette})), colour);
  EXPECT_EQ(decoded(png_file({2, PNG_COLOR_TYPE_PALETTE, {2}, palette})), grey);
  EXPECT_EQ(decoded(png_file({8, PNG_COLOR_TYPE_PALETTE, {1}, palette, {255, 64}})), reference(200, 100, 50, 64));
  // JPEG: lossy, so within a step or two of 8 bits; greyscale (one component) and YCbCr alike.
  const float step = reference(129, 129, 129).r - grey.r;
  const glm::vec4 grey_jpeg_texel = decoded(grey_jpeg(128));
  EXPECT_NEAR(grey_jpeg_texel.r, grey.r, 2 * step);
  EXPECT_EQ(grey_jpeg_texel.r, grey_jpeg_texel.b);
  EXPECT_NEAR(decoded(test::jpeg_bytes({8, 8, std::vector<uint8_t>(8 * 8 * 3, 128)})).g, grey.r, 2 * step);
}

TEST(PictureEncodingTest, ColourSpaceChunksAreIgnored) {
  // glTF requires a picture's colour-space metadata to be ignored; vkray does so for every texture:
  // the samples are sRGB for colour (base colour, emission) and linear for data, whatever the file says.
  const glm::vec4 grey = reference(128, 128, 128), colour = reference(200, 100, 50);
  EXPECT_EQ(decoded(png_file({.samples = {200, 100, 50}, .file_gamma = 1.0})), colour);
  EXPECT_EQ(decoded(png_file({.samples = {200, 100, 50}, .file_gamma = 1 / 1.8})), colour);
  EXPECT_EQ(decoded(png_file({.bit_depth = 16, .samples = {200 * 257, 100 * 257, 50 * 257}, .file_gamma = 1.0})), colour);
  EXPECT_EQ(decoded(png_file({.bit_depth = 16, .samples = {200 * 257, 100 * 257, 50 * 257}, .srgb_chunk = true})), colour);
  EXPECT_EQ(decoded(png_file({.samples = {200, 100, 50}, .iccp_chunk = true})), colour);
  EXPECT_EQ(decoded(png_file({.bit_depth = 16, .colour_type = PNG_COLOR_TYPE_GRAY, .samples = {128 * 257}, .iccp_chunk = true})), grey);
  EXPECT_EQ(decoded(png_file({.samples = {200, 100, 50}, .file_gamma = 1.0}), false), reference(200, 100, 50, 255, false));
}

TEST(PictureEncodingTest, ImageFilesReadAsTexturesDo) {
  // read_png (parts, tests, tools) decodes a PNG as a texture's is decoded: the samples as stored,
  // whatever their depth or the file's colour-space chunks, each value the texture's texel before
  // its rounding to a half float.
  test::TempDir dir;
  const auto read = [&](const std::string& bytes) {
    std::ofstream(dir / "p.png", std::ios::binary) << bytes;
    return read_png(dir / "p.png").at(1, 1);
  };
  const glm::vec3 colour(decode_srgb8(200), decode_srgb8(100), decode_srgb8(50)), grey(decode_srgb8(128));
  EXPECT_EQ(read(png_file({8, PNG_COLOR_TYPE_RGB, {200, 100, 50}})), colour);
  EXPECT_EQ(read(png_file({16, PNG_COLOR_TYPE_RGB, {200 * 257, 100 * 257, 50 * 257}})), colour);
  EXPECT_EQ(read(png_file({.samples = {200, 100, 50}, .file_gamma = 1.0})), colour);
  EXPECT_EQ(read(png_file({.bit_depth = 16, .samples = {200 * 257, 100 * 257, 50 * 257}, .file_gamma = 1.0})), colour);
  EXPECT_EQ(read(png_file({.samples = {200, 100, 50}, .iccp_chunk = true})), colour);
  EXPECT_EQ(read(png_file({8, PNG_COLOR_TYPE_GRAY, {128}})), grey);
  EXPECT_EQ(read(png_file({16, PNG_COLOR_TYPE_GRAY_ALPHA, {128 * 257, 64 * 257}})), grey);  // alpha dropped
  EXPECT_EQ(read(png_file({8, PNG_COLOR_TYPE_PALETTE, {1}, {{0, 0, 0}, {200, 100, 50}}})), colour);
  // 16 bits keep their precision, and are the texture's light.
  const std::string between = png_file({16, PNG_COLOR_TYPE_RGB, {128 * 257 + 128, 100 * 257, 50 * 257}});
  const glm::vec3 value = read(between);
  EXPECT_GT(value.r, grey.r);
  EXPECT_LT(value.r, decode_srgb8(129));
  const glm::vec4 texel = decoded(between);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(float(Imath::half(value[c])), texel[c]) << c;
  // An image's limit is kMaxImageSide on a side (a texture's is stricter), checked before any pixel.
  std::ofstream(dir / "wide.png", std::ios::binary) << test::png_header_only(16385, 1);
  EXPECT_NE(error_of([&] { read_png(dir / "wide.png"); }).find("wide.png: a PNG of 16385 x 1 pixels (vkray reads up to 16384 on a side)"),
            std::string::npos);
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
  const SceneBvh bvh = build_scene_bvh(scene);
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

TEST_F(ObjMaterialTest, SceneFileMetallicRoughnessTexturesAreSrgbColourAndLinearData) {
  // glTF's rule in a scene file: the base colour from sRGB, metallic (blue) and roughness (green) as
  // stored. One grey picture as both: two textures.
  write("quad.obj", kTexturedQuad);
  write("quad.mtl", "newmtl checker\nnewmtl plain\n");
  test::write_file(dir_ / "grey.png", test::png_bytes({1, 1, {128, 128, 128}}));
  write("scene.json", R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "vertical_fov": 40},
                          "materials": {"gltf": {"type": "metallic_roughness", "base_color_texture": "grey.png",
                                                 "metallic_roughness_texture": "grey.png"}},
                          "objects": [{"type": "mesh", "file": "quad.obj", "material": "gltf"}]})");
  const Scene scene = load_scene(dir_ / "scene.json");
  ASSERT_EQ(scene.materials.size(), 1u);
  const Material& m = scene.materials[0];
  ASSERT_TRUE(m.albedo_texture.present() && m.metallic_roughness_texture.present());
  EXPECT_NEAR(scene.textures[size_t(m.albedo_texture.texture)]->texel(0, 0).g, 0.2158f, 1e-3f);
  EXPECT_NEAR(scene.textures[size_t(m.metallic_roughness_texture.texture)]->texel(0, 0).b, 128.0f / 255.0f, 1e-3f);
  const gpu::PackedLighting packed = gpu::pack_lighting(scene, gpu::PrimitiveSlots{{0, 1}, {}, {}});
  const gpu::TextureHeader h = gpu::texture_header(packed.materials[VKRAY_MATERIAL_LAYERS_TEXTURE]);
  EXPECT_EQ(h.width, 1u);
  EXPECT_EQ(h.first, 1u);  // after the base colour's one texel

  write("scene.json", R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "vertical_fov": 40},
                          "materials": {"gltf": {"type": "metallic_roughness", "metallic_roughness_texture": "gone.png"}},
                          "objects": [{"type": "mesh", "file": "quad.obj", "material": "gltf"}]})");
  const std::string gone = error_of([&] { load_scene(dir_ / "scene.json"); });
  EXPECT_NE(gone.find("/materials/gltf/metallic_roughness_texture"), std::string::npos) << gone;
  EXPECT_NE(gone.find("gone.png"), std::string::npos) << gone;
}

TEST(TextureTransformTest, ATransformAllOfAMaterialsTexturesShareIsAppliedToItsCoordinates) {
  // u' = sx u cos r + sy v sin r + ox, v' = sy v cos r - sx u sin r + oy, here with r = 90 degrees:
  // u' = 3 v + 0.5, v' = -2 u + 0.25, then recentred by whole periods of 2 as any coordinates are.
  test::TempDir dir;
  test::GltfBuilder b;
  const int picture = b.texture(test::png_bytes(four_colours()));
  const nlohmann::json transform = {{"KHR_texture_transform", {{"offset", {0.5, 0.25}}, {"rotation", 1.5707963267948966}, {"scale", {2, 3}}}}};
  b.quad(b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", picture}, {"extensions", transform}}},
                                               {"metallicRoughnessTexture", {{"index", picture}, {"extensions", transform}}}}}}));
  test::write_file(dir / "quad.gltf", b.gltf());
  const Scene scene = load_scene(dir / "quad.gltf");
  ASSERT_EQ(scene.materials.size(), 1u);
  EXPECT_FALSE(scene.materials[0].albedo_texture.transformed());
  EXPECT_FALSE(scene.materials[0].metallic_roughness_texture.transformed());
  ASSERT_EQ(scene.triangles.size(), 2u);
  const GltfScene raw = parse_gltf(b.gltf(), dir / "raw.gltf");  // the coordinates as the file gives them
  for (size_t t = 0; t < 2; ++t)
    for (size_t k = 0; k < 3; ++k) {
      const glm::vec2 uv = raw.triangles[t].uv[k], mapped = scene.triangles[t].uv[k];
      const double u = 3.0 * uv.y + 0.5, v = -2.0 * uv.x + 0.25;
      EXPECT_NEAR(std::remainder(mapped.x - u, 2.0), 0.0, 1e-6) << t << " " << k;
      EXPECT_NEAR(std::remainder(mapped.y - v, 2.0), 0.0, 1e-6) << t << " " << k;
    }
}

TEST_F(ObjMaterialTest, WhatIsNotRenderedIsNamedOnce) {
  write("quad.obj", kTexturedQuad);
  write("quad.mtl", "newmtl checker\nd -halo 0.5\nmap_Bump b.png\nbump b.png\nnewmtl plain\nmap_Bump c.png\n");
  const Scene scene = load(R"({"type": "mesh", "file": "quad.obj"})");
  ASSERT_EQ(scene.warnings.size(), 3u);
  EXPECT_NE(scene.warnings[0].find("quad.mtl:2: d -halo: not rendered"), std::string::npos) << scene.warnings[0];
  EXPECT_NE(scene.warnings[1].find("map_Bump: not rendered"), std::string::npos) << scene.warnings[1];
}

TEST_F(ObjMaterialTest, DissolveAndItsMapAreTheOpacityOfABlendedSurface) {
  // d, or Tr = 1 - d (d wins where both are given), times map_d: its alpha, or its grey where it has
  // none (a greyscale PNG here: grey 51 is opacity 0.2).
  write("quad.obj", kTexturedQuad);
  test::write_file(dir_ / "grey.png", test::png_bytes({1, 1, {51, 51, 51}}));
  write("quad.mtl", "newmtl checker\nTr 0.25\nmap_d grey.png\nnewmtl plain\nd 1\n");
  const Scene scene = load(R"({"type": "mesh", "file": "quad.obj"})");
  ASSERT_EQ(scene.triangles.size(), 2u);
  const Material& m = scene.materials[scene.triangles[0].material];
  EXPECT_FALSE(scene.materials[scene.triangles[1].material].see_through());
  EXPECT_EQ(m.alpha_mode, AlphaMode::blend);
  EXPECT_EQ(m.opacity, 0.75f);
  ASSERT_TRUE(m.opacity_texture.present());
  EXPECT_NEAR(scene.textures[size_t(m.opacity_texture.texture)]->texel(0, 0).a, 0.2, 1e-3);
  write("quad.mtl", "newmtl checker\nd 0.5\nTr 0.9\nnewmtl plain\n");
  const Scene both = load(R"({"type": "mesh", "file": "quad.obj"})");
  EXPECT_EQ(both.materials[both.triangles[0].material].opacity, 0.5f);
  write("quad.mtl", "newmtl checker\nd 1.5\nnewmtl plain\n");
  try {
    load(R"({"type": "mesh", "file": "quad.obj"})");
    ADD_FAILURE() << "d 1.5 accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("quad.mtl:2: d: expected a number from 0 to 1, got \"1.5\""), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace vkray
