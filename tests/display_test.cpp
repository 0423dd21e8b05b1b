// Display transforms (image/display.h): the identity is the PNG encoding vkray always had, the
// exposure is a power of two, and each tone mapper meets its reference's values and shape.
#include <cmath>
#include <filesystem>
#include <unistd.h>

#include <gtest/gtest.h>

#include "image/display.h"
#include "image/image.h"

namespace vkray {
namespace {

// The Khronos PBR Neutral reference (KhronosGroup/ToneMapping) for a grey, worked in double.
double pbr_neutral_grey(double x) {
  const double offset = x < 0.08 ? x - 6.25 * x * x : 0.04;
  const double c = x - offset;
  if (c < 0.76) return c;
  const double d = 0.24;
  return 1.0 - d * d / (c + d - 0.76);  // a grey is scaled to the new peak; desaturating a grey leaves it
}

TEST(DisplayTest, IdentityIsTheSrgbEncodingOfTheContract) {
  const DisplayTransform identity;
  ASSERT_TRUE(identity.is_identity());
  for (float v : {-1.0f, 0.0f, 0.0031308f, 0.18f, 0.5f, 0.999f, 1.0f, 7.0f, INFINITY, NAN}) {
    uint8_t out[3];
    identity.encode(glm::vec3(v, v * 0.5f, 0.25f), out);
    EXPECT_EQ(out[0], encode_srgb8(v)) << v;
    EXPECT_EQ(out[1], encode_srgb8(v * 0.5f)) << v;
    EXPECT_EQ(out[2], encode_srgb8(0.25f));
  }
}

TEST(DisplayTest, ExposureScalesByPowersOfTwo) {
  DisplayTransform plus_one{Tonemap::none, 1.0f};
  EXPECT_EQ(plus_one.scale(), 2.0f);
  EXPECT_EQ(plus_one.apply(glm::vec3(0.25f, 0.125f, 0.6f)), glm::vec3(0.5f, 0.25f, 1.0f));  // clamped at 1
  DisplayTransform minus_three{Tonemap::none, -3.0f};
  EXPECT_EQ(minus_three.apply(glm::vec3(4.0f)), glm::vec3(0.5f));
  uint8_t out[3];
  minus_three.encode(glm::vec3(4.0f), out);
  EXPECT_EQ(out[0], encode_srgb8(0.5f));
}

TEST(DisplayTest, PbrNeutralMatchesTheReference) {
  const DisplayTransform neutral{Tonemap::pbr_neutral, 0.0f};
  for (double x : {0.0, 0.01, 0.05, 0.079, 0.08, 0.18, 0.5, 0.79, 0.8, 1.0, 2.0, 16.0, 1e4}) {
    const glm::vec3 got = neutral.apply(glm::vec3(float(x)));
    EXPECT_NEAR(got.r, pbr_neutral_grey(x), 2e-6) << x;
    EXPECT_EQ(got.r, got.g);
    EXPECT_EQ(got.g, got.b);
  }
  // Below the start of compression it changes colours only by the offset: 0.5 is shown as 0.46.
  EXPECT_NEAR(neutral.apply(glm::vec3(0.5f, 0.3f, 0.2f)).r, 0.46f, 1e-6f);
  // Bright colours are desaturated towards white: a saturated red keeps its hue, loses its purity.
  const glm::vec3 red = neutral.apply(glm::vec3(8.0f, 0.5f, 0.5f));
  EXPECT_GT(red.r, red.g);
  EXPECT_GT(red.g / red.r, (0.5f - 0.04f) / (8.0f - 0.04f));
  EXPECT_LT(red.r, 1.0f);
}

TEST(DisplayTest, AcesIsHillsFit) {
  const DisplayTransform aces{Tonemap::aces, 0.0f};
  // Values of the fit (BakingLab's ACES.hlsl) worked in double.
  EXPECT_NEAR(aces.apply(glm::vec3(0.18f)).g, 0.1055913, 2e-6);
  EXPECT_NEAR(aces.apply(glm::vec3(1.0f)).g, 0.6191154, 2e-6);
  EXPECT_NEAR(aces.apply(glm::vec3(10.0f)).g, 0.9738218, 2e-6);
  EXPECT_EQ(aces.apply(glm::vec3(1e6f)), glm::vec3(1.0f));
  EXPECT_EQ(aces.apply(glm::vec3(0.0f)), glm::vec3(0.0f));
  // Monotonic in a grey.
  float last = -1.0f;
  for (float x = 0.0f; x < 64.0f; x = x * 1.25f + 0.001f) {
    const float v = aces.apply(glm::vec3(x)).g;
    EXPECT_GE(v, last) << x;
    last = v;
  }
}

TEST(DisplayTest, NamesRoundTrip) {
  for (Tonemap t : {Tonemap::none, Tonemap::aces, Tonemap::pbr_neutral}) EXPECT_EQ(parse_tonemap(tonemap_name(t)), t);
  EXPECT_FALSE(parse_tonemap("ACES"));
  EXPECT_FALSE(parse_tonemap(""));
}

TEST(DisplayTest, InfinityShowsAsWhite) {
  for (Tonemap t : {Tonemap::none, Tonemap::aces, Tonemap::pbr_neutral}) {
    const DisplayTransform d{t, 3.0f};
    EXPECT_EQ(d.apply(glm::vec3(INFINITY)), glm::vec3(1.0f)) << tonemap_name(t);
    EXPECT_EQ(d.apply(glm::vec3(3e38f)), glm::vec3(1.0f)) << tonemap_name(t);
  }
}

TEST(DisplayTest, NanAndNegativeShowAsBlack) {
  for (Tonemap t : {Tonemap::none, Tonemap::aces, Tonemap::pbr_neutral}) {
    const DisplayTransform d{t, 2.0f};
    EXPECT_EQ(d.apply(glm::vec3(NAN, -1.0f, -INFINITY)), glm::vec3(0.0f)) << tonemap_name(t);
  }
}

// A PNG written through a transform holds the transform's bytes (read back through read_png, which
// decodes each byte exactly as encode_srgb8 encodes it).
TEST(DisplayTest, PngHoldsTheTransformedBytes) {
  const auto file = std::filesystem::temp_directory_path() / ("vkray-display-test-" + std::to_string(::getpid()) + ".png");
  Image image(4, 2);
  for (uint32_t i = 0; i < 8; ++i) image.pixels[i] = glm::vec3(float(i) * 0.7f, float(i) * 0.1f, 3.0f);
  const DisplayTransform aces{Tonemap::aces, -0.5f};
  write_png(image, file, aces);
  const Image back = read_png(file);
  std::filesystem::remove(file);
  for (uint32_t i = 0; i < 8; ++i) {
    uint8_t want[3];
    aces.encode(image.pixels[i], want);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(encode_srgb8(back.pixels[i][c]), want[c]) << i;
  }
}

}  // namespace
}  // namespace vkray
