// OpenEXR output: the image and the first-hit passes read back as written (exactly in 32-bit, to
// half precision in 16-bit), the type rules, and bad files. Other tools read the files in
// python/tests/test_exr.py.
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "base/errors.h"
#include "image/exr.h"
#include "image/image_file.h"
#include "support/temp_dir.h"

namespace vkray::test {
namespace {

// An image and passes with a value in every pixel that differs from its neighbours'.
std::pair<Image, Aovs> sample_render(uint32_t w, uint32_t h) {
  Image image(w, h);
  Aovs aovs(w, h);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      image.pixels[i] = glm::vec3(0.01f * float(x), 0.02f * float(y), 3.5f);
      aovs.albedo[i] = glm::vec3(0.5f, 0.25f, float(x) / float(w));
      aovs.normal[i] = glm::vec3(0.0f, -1.0f, 0.125f);
      aovs.position[i] = glm::vec3(float(x) - 7.5f, 100.25f, -float(y));
      aovs.depth[i] = x == 0 ? std::numeric_limits<float>::infinity() : 1.0f + float(x + y);
      aovs.object[i] = x == 0 ? -1 : int32_t(i * 1000);
    }
  return {image, aovs};
}

TEST(ExrTest, FullFloatFilesReadBackExactly) {
  TempDir dir;
  const auto [image, aovs] = sample_render(13, 7);
  OutputContent content{true, {Aov::object, Aov::albedo, Aov::normal, Aov::position, Aov::depth}};
  write_exr(dir / "a.exr", image, &aovs, content);
  const ExrFile read = read_exr(dir / "a.exr");
  EXPECT_TRUE(read.content.full_float);
  EXPECT_EQ(read.content.passes.size(), 5u);
  ASSERT_EQ(read.image.width, 13u);
  ASSERT_EQ(read.image.height, 7u);
  EXPECT_EQ(read.image.pixels, image.pixels);
  EXPECT_EQ(read.aovs.albedo, aovs.albedo);
  EXPECT_EQ(read.aovs.normal, aovs.normal);
  EXPECT_EQ(read.aovs.position, aovs.position);
  EXPECT_EQ(read.aovs.depth, aovs.depth);
  EXPECT_EQ(read.aovs.object, aovs.object);
}

TEST(ExrTest, HalfFilesKeepHalfPrecisionAndExactObjectIds) {
  TempDir dir;
  const auto [image, aovs] = sample_render(9, 5);
  write_exr(dir / "h.exr", image, &aovs, {false, {Aov::depth, Aov::object}});
  const ExrFile read = read_exr(dir / "h.exr");
  EXPECT_FALSE(read.content.full_float);
  EXPECT_EQ(read.content.passes, (std::vector<Aov>{Aov::depth, Aov::object}));
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(read.image.pixels[i][c], image.pixels[i][c], 1e-3 * std::abs(image.pixels[i][c]) + 1e-7);
    if (std::isinf(aovs.depth[i]))
      EXPECT_TRUE(std::isinf(read.aovs.depth[i]));
    else
      EXPECT_NEAR(read.aovs.depth[i], aovs.depth[i], 1e-3 * aovs.depth[i]);
  }
  EXPECT_EQ(read.aovs.object, aovs.object);  // 32-bit even in a half file: ids up to 2^24 exact
}

TEST(ExrTest, WriteImageWritesHalfRgb) {
  TempDir dir;
  const auto [image, aovs] = sample_render(4, 4);
  write_image(image, dir / "plain.EXR");
  const ExrFile read = read_exr(dir / "plain.EXR");
  EXPECT_FALSE(read.content.full_float);
  EXPECT_TRUE(read.content.passes.empty());
}

TEST(ExrTest, PassesAndFullFloatAreForExrOnlyAndLeaveNoFile) {
  TempDir dir;
  const auto [image, aovs] = sample_render(4, 4);
  EXPECT_THROW(write_render_image(dir / "x.png", image, &aovs, {false, {Aov::depth}}), UsageError);
  EXPECT_THROW(write_render_image(dir / "x.pfm", image, nullptr, {true, {}}), UsageError);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
  write_render_image(dir / "x.pfm", image, nullptr, {});
  EXPECT_TRUE(std::filesystem::exists(dir / "x.pfm"));
}

TEST(ExrTest, AnUnwritableFolderIsAnOutputError) {
  const auto [image, aovs] = sample_render(4, 4);
  EXPECT_THROW(write_exr("/nonexistent-vkray-folder/x.exr", image, &aovs, {}), OutputError);
}

TEST(ExrTest, ABrokenFileIsAnInputErrorNamingIt) {
  TempDir dir;
  std::ofstream(dir / "bad.exr") << "v/1\x01 this is not an EXR file";
  try {
    read_exr(dir / "bad.exr");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.exr"), std::string::npos) << e.what();
  }
  // A real file cut short.
  const auto [image, aovs] = sample_render(64, 64);
  write_exr(dir / "whole.exr", image, &aovs, {true, {Aov::position}});
  const auto size = std::filesystem::file_size(dir / "whole.exr");
  std::filesystem::copy_file(dir / "whole.exr", dir / "cut.exr");
  std::filesystem::resize_file(dir / "cut.exr", size / 2);
  EXPECT_THROW(read_exr(dir / "cut.exr"), InputError);
}

TEST(ExrTest, AHeaderClaimingAHugeImageIsRefused) {
  // A real file whose header says its data window is a billion pixels wide: refused by the header's
  // check, before any line buffer for it is allocated.
  TempDir dir;
  const auto [image, aovs] = sample_render(8, 8);
  write_exr(dir / "small.exr", image, nullptr, {});
  std::ifstream in(dir / "small.exr", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // The attribute: name, type, a 4-byte size of 16, then xMin, yMin, xMax, yMax.
  const std::string attribute("dataWindow\0box2i\0", 17);
  const size_t at = bytes.find(attribute);
  ASSERT_NE(at, std::string::npos);
  const int32_t x_max = 1 << 30;
  std::memcpy(bytes.data() + at + attribute.size() + 4 + 8, &x_max, sizeof(x_max));
  std::ofstream(dir / "huge.exr", std::ios::binary) << bytes;
  try {
    read_exr(dir / "huge.exr");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("huge.exr"), std::string::npos) << e.what();
  }
}

// The bytes of a small EXR that write_exr wrote, for tests that change what its header claims.
std::string small_exr_bytes(const TempDir& dir) {
  const auto [image, aovs] = sample_render(8, 8);
  write_exr(dir / "small.exr", image, nullptr, {});
  std::ifstream in(dir / "small.exr", std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// `value` over the bytes of `bytes` at `at`.
template <typename T>
void put(std::string& bytes, size_t at, T value) {
  ASSERT_LE(at + sizeof value, bytes.size());
  std::memcpy(bytes.data() + at, &value, sizeof value);
}

// What read_exr says of `bytes`, written to `name` in `dir`: the message of the InputError it throws.
std::string refusal(const TempDir& dir, const std::string& name, const std::string& bytes) {
  std::ofstream(dir / name, std::ios::binary | std::ios::trunc) << bytes;
  try {
    read_exr(dir / name);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ExrTest, AHeaderClaimingMorePixelsThanTheFileHoldsIsRefusedBeforeAnythingIsAllocated) {
  // An 8 x 8 file whose data window says 16384 x 16384 (within vkray's limit on a side): its chunk
  // offset table alone would be 8 KiB, its pixels gigabytes. Refused for what the file can hold.
  TempDir dir;
  std::string bytes = small_exr_bytes(dir);
  const std::string attribute("dataWindow\0box2i\0", 17);
  const size_t at = bytes.find(attribute) + attribute.size() + 4;
  put(bytes, at + 8, int32_t(16383));
  put(bytes, at + 12, int32_t(16383));
  const std::string message = refusal(dir, "claims.exr", bytes);
  EXPECT_NE(message.find("claims.exr: its header claims 16384 x 16384 pixels in 1024 blocks, which need at least"),
            std::string::npos) << message;
  EXPECT_NE(message.find("in a file of " + std::to_string(bytes.size()) + " bytes"), std::string::npos) << message;
}

TEST(ExrTest, AnAttributeOrPreviewClaimingMoreThanTheFileIsRefused) {
  TempDir dir;
  const std::string small = small_exr_bytes(dir);
  // An attribute's size: the string "software" claims a gigabyte.
  std::string bytes = small;
  const std::string software("software\0string\0", 16);
  const size_t at = bytes.find(software);
  ASSERT_NE(at, std::string::npos);
  put(bytes, at + software.size(), int32_t(1) << 30);
  std::string message = refusal(dir, "attribute.exr", bytes);
  EXPECT_NE(message.find("attribute.exr: its header attribute \"software\" claims 1073741824 bytes past byte"), std::string::npos)
      << message;
  // A preview image of 65535 x 65535 pixels in 8 bytes, in the place of "software" (as long:
  // name, type, size, value), which OpenEXR would allocate 17 GB for before reading it.
  bytes = small;
  std::string preview("prev\0preview\0", 13);
  preview.append(4 + 8, '\0');
  put(preview, 13, int32_t(8));
  put(preview, 17, uint32_t(65535));
  put(preview, 21, uint32_t(65535));
  ASSERT_EQ(preview.size(), software.size() + 4 + std::strlen("vkray"));
  bytes.replace(at, preview.size(), preview);
  message = refusal(dir, "preview.exr", bytes);
  EXPECT_NE(message.find("preview.exr: its preview image claims 65535 x 65535 pixels in an attribute of 8 bytes"), std::string::npos)
      << message;
}

TEST(ExrTest, AChunkOffsetOutsideTheFileOrASubsampledChannelIsRefused) {
  TempDir dir;
  const std::string small = small_exr_bytes(dir);
  // The one chunk's offset: the first 8 bytes that hold their own position plus 8 (the table's end).
  std::string bytes = small;
  size_t table = 0;
  for (size_t at = 0; at + 8 <= bytes.size() && !table; ++at) {
    uint64_t value;
    std::memcpy(&value, bytes.data() + at, sizeof value);
    if (value == at + 8) table = at;
  }
  ASSERT_NE(table, 0u);
  put(bytes, table, uint64_t(1) << 40);
  std::string message = refusal(dir, "offset.exr", bytes);
  EXPECT_NE(message.find("offset.exr: its chunk offset table points outside the file: block 0 at byte 1099511627776"),
            std::string::npos) << message;
  // Channel B (the channel list's first) sampled every second column.
  bytes = small;
  const std::string channels("channels\0chlist\0", 16);
  const size_t list = bytes.find(channels) + channels.size() + 4;
  ASSERT_EQ(bytes.substr(list, 2), std::string("B\0", 2));
  put(bytes, list + 2 + 8, int32_t(2));
  message = refusal(dir, "sampled.exr", bytes);
  EXPECT_NE(message.find("sampled.exr: channel B is subsampled (2 x 1)"), std::string::npos) << message;
}

TEST(ExrTest, WhatIsReadIsHashedAsStored) {
  // The hash read_exr gives is that of the values as the file holds them: the same for a file
  // written again with the same pixels, another for one value changed by less than a half float's
  // step in a 32-bit file.
  TempDir dir;
  auto [image, aovs] = sample_render(13, 7);
  const OutputContent content{true, {Aov::depth, Aov::object}};
  write_exr(dir / "a.exr", image, &aovs, content);
  write_exr(dir / "b.exr", image, &aovs, content);
  image.pixels[20].g = std::nextafter(image.pixels[20].g, 1.0f);
  write_exr(dir / "c.exr", image, &aovs, content);
  aovs.object[3] += 1;
  write_exr(dir / "d.exr", image, &aovs, content);
  const std::string a = read_exr(dir / "a.exr").pixels_hash;
  EXPECT_EQ(a.size(), 32u);
  EXPECT_EQ(read_exr(dir / "b.exr").pixels_hash, a);
  EXPECT_NE(read_exr(dir / "c.exr").pixels_hash, a);
  EXPECT_NE(read_exr(dir / "d.exr").pixels_hash, read_exr(dir / "c.exr").pixels_hash);
}

}  // namespace
}  // namespace vkray::test
