// Image encoding and files: the contract's sRGB rule, PFM layout, atomic writes (of one file, and of
// files that change together).
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/atomic_file.h"
#include "base/errors.h"
#include "image/image.h"
#include "image/image_file.h"

namespace vkray {
namespace {

class ImageFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("vkray-image-test-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  static Image gradient() {
    Image image(5, 3);
    for (uint32_t y = 0; y < 3; ++y)
      for (uint32_t x = 0; x < 5; ++x) image.at(x, y) = {float(x) * 0.25f, float(y) * 0.5f, 0.125f + float(x * y) * 0.01f};
    return image;
  }
  std::filesystem::path dir_;
};

TEST(SrgbTest, EncodesAsTheContractSays) {
  EXPECT_EQ(encode_srgb8(0.0f), 0);
  EXPECT_EQ(encode_srgb8(1.0f), 255);
  EXPECT_EQ(encode_srgb8(0.5f), 188);     // 255 * (1.055 * 0.5^(1/2.4) - 0.055) = 187.5
  EXPECT_EQ(encode_srgb8(0.001f), 3);     // linear segment: 255 * 12.92 * 0.001 = 3.29
  EXPECT_EQ(encode_srgb8(0.25f), 137);     // 255 * 0.5371 = 136.96
  EXPECT_EQ(encode_srgb8(7.0f), 255);     // clamped
  EXPECT_EQ(encode_srgb8(-1.0f), 0);
  EXPECT_EQ(encode_srgb8(std::numeric_limits<float>::quiet_NaN()), 0);
  EXPECT_EQ(encode_srgb8(std::numeric_limits<float>::infinity()), 255);
}

TEST(SrgbTest, TheTableGivesTheFormulasResultEverywhere) {
  // encode_srgb8 reads a table: one bucket per top 16 bits of the float's bit pattern, each with the
  // float where its value rises by one. Where the two could differ: at each bucket's first and last
  // float and around each rise; checked there, and on a million floats spread over [0, 1]. (All
  // 1.07e9 floats in [0, 1] agreed when the table was written: 10 s, too long for every run.)
  const auto expect_same = [](float x) { ASSERT_EQ(encode_srgb8(x), encode_srgb8_by_formula(x)) << x; };
  const uint32_t one = std::bit_cast<uint32_t>(1.0f);
  for (uint32_t bucket = 0; bucket <= (one >> 16); ++bucket) {
    const uint32_t first = bucket << 16, last = std::min(first + 0xFFFFu, one);
    expect_same(std::bit_cast<float>(first));
    expect_same(std::bit_cast<float>(last));
    // Around the rise: bisection over the bucket for the first float the formula encodes higher.
    uint32_t low = first, high = last;
    while (low < high) {
      const uint32_t middle = low + (high - low) / 2;
      if (encode_srgb8_by_formula(std::bit_cast<float>(middle)) > encode_srgb8_by_formula(std::bit_cast<float>(first))) high = middle;
      else low = middle + 1;
    }
    for (uint32_t bits = std::max(low, first + 1) - 1; bits <= std::min(low + 1, last); ++bits) expect_same(std::bit_cast<float>(bits));
  }
  for (uint32_t i = 0; i < 1000000; ++i) expect_same(float(i) / 1000000.0f);
  for (const float x : {-0.0f, -1e-30f, 1e-45f, 1.0f, std::nextafter(1.0f, 2.0f), 2.0f, 1e30f,
                        std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                        std::numeric_limits<float>::quiet_NaN()})
    expect_same(x);
}

TEST(SrgbTest, DecodeInvertsEncode) {
  for (int v = 0; v < 256; ++v) EXPECT_EQ(encode_srgb8(decode_srgb8(uint8_t(v))), v);
}

TEST_F(ImageFileTest, PfmRoundTripsExactlyWithTheTopRowFirstInMemory) {
  const Image image = gradient();
  write_image(image, dir_ / "g.pfm");
  const Image back = read_pfm(dir_ / "g.pfm");
  ASSERT_EQ(back.width, 5u);
  ASSERT_EQ(back.height, 3u);
  EXPECT_EQ(back.pixels, image.pixels);
  // On disk the bottom row comes first: the first float after the header is the bottom-left red.
  std::ifstream in(dir_ / "g.pfm", std::ios::binary);
  std::string header;
  for (int i = 0; i < 3; ++i) std::getline(in, header);
  EXPECT_EQ(header, "-1.0");
  float first[3];
  in.read(reinterpret_cast<char*>(first), sizeof first);
  EXPECT_EQ(first[1], image.at(0, 2).g);
}

TEST_F(ImageFileTest, PngRoundTripsThroughEightBitSrgb) {
  const Image image = gradient();
  write_image(image, dir_ / "g.png");
  const Image back = read_png(dir_ / "g.png");
  ASSERT_EQ(back.width, 5u);
  for (size_t i = 0; i < image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(encode_srgb8(back.pixels[i][c]), encode_srgb8(image.pixels[i][c]));
}

TEST_F(ImageFileTest, PngRowsArriveInOrderWhateverTheHeight) {
  // Rows are converted to 8-bit sRGB on a second thread in blocks of 64 (image/image.cpp): heights
  // around the block size, and one row, each come back row for row.
  for (const uint32_t height : {1u, 63u, 64u, 65u, 130u}) {
    Image image(7, height);
    for (uint32_t y = 0; y < height; ++y)
      for (uint32_t x = 0; x < 7; ++x) image.at(x, y) = {float(y % 256) / 255.0f, float(x) / 7.0f, float((y * 7 + x) % 97) / 97.0f};
    write_image(image, dir_ / "rows.png");
    const Image back = read_png(dir_ / "rows.png");
    ASSERT_EQ(back.height, height);
    for (size_t i = 0; i < image.pixels.size(); ++i)
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(encode_srgb8(back.pixels[i][c]), encode_srgb8(image.pixels[i][c])) << "height " << height << " pixel " << i;
  }
}

TEST_F(ImageFileTest, FailedWritesLeaveNoFile) {
  EXPECT_THROW(write_image(gradient(), dir_ / "missing-folder" / "x.png"), OutputError);
  EXPECT_THROW(write_image(gradient(), dir_ / "x.jpg"), OutputError);
  EXPECT_TRUE(std::filesystem::is_empty(dir_));  // no partial file, no temporary left behind
}

TEST_F(ImageFileTest, WriteReplacesAnExistingFile) {
  write_image(Image(2, 2), dir_ / "r.pfm");
  write_image(gradient(), dir_ / "r.pfm");
  EXPECT_EQ(read_pfm(dir_ / "r.pfm").width, 5u);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir_), {}), 1);
}

std::string text_of(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<std::string> names_in(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// link(2) on a file system without hard links (FAT, some network and FUSE file systems).
int no_hard_links(const char*, const char*) {
  errno = EPERM;
  return -1;
}

TEST_F(ImageFileTest, FilesCommittedTogetherAreAllReplacedOrNone) {
  // An image and its record change together: when the second cannot be renamed into place (here a
  // folder stands in its way), the first is put back as it was, or removed if it was not there. The
  // old image is kept meanwhile under a hard link, or where the file system has none, moved aside.
  for (const LinkFunction link : {LinkFunction(::link), LinkFunction(no_hard_links)}) {
    SCOPED_TRACE(link == ::link ? "with hard links" : "without hard links");
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_ / "record" / "inside");
    std::ofstream(dir_ / "image") << "old image";
    for (const char* first : {"image", "new-image"}) {
      AtomicFile image(dir_ / first), record(dir_ / "record");
      std::fputs("new image", image.get());
      std::fputs("new record", record.get());
      EXPECT_THROW(AtomicFile::commit_together({&image, &record}, link), OutputError) << first;
    }
    EXPECT_EQ(text_of(dir_ / "image"), "old image");
    EXPECT_EQ(names_in(dir_), (std::vector<std::string>{"image", "record"}));  // no temporary file, no second name left
    // When both can be, both are.
    std::filesystem::remove_all(dir_ / "record");
    std::ofstream(dir_ / "record") << "old record";
    AtomicFile image(dir_ / "image"), record(dir_ / "record");
    std::fputs("new image", image.get());
    std::fputs("new record", record.get());
    AtomicFile::commit_together({&image, &record}, link);
    EXPECT_EQ(text_of(dir_ / "image"), "new image");
    EXPECT_EQ(text_of(dir_ / "record"), "new record");
    EXPECT_EQ(names_in(dir_), (std::vector<std::string>{"image", "record"}));
  }
}

// For the link functions below, which are plain function pointers: the targets that were there.
std::vector<std::filesystem::path> g_there;
int link_checking_targets(const char* from, const char* to) {
  for (const auto& target : g_there) EXPECT_TRUE(std::filesystem::exists(target)) << target << " missing before a rename";
  return ::link(from, to);
}
// Before the third rename, a non-empty folder takes the first target's place, so that the first
// old file cannot be put back there.
int link_then_block_the_first(const char* from, const char* to) {
  if (std::string_view(from).ends_with("b")) {
    std::filesystem::remove(g_there[0]);
    std::filesystem::create_directories(g_there[0] / "inside");
  }
  return ::link(from, to);
}

TEST_F(ImageFileTest, TargetsRenamedTogetherAreThereAtEveryStep) {
  // With hard links every target that was there is there before each rename (as its old file or its
  // new one) and after the last; a failed rename puts the old ones back.
  std::filesystem::create_directories(dir_ / "new");
  for (const bool fails : {false, true}) {
    SCOPED_TRACE(fails ? "the last rename fails" : "all renamed");
    std::vector<Rename> renames;
    g_there.clear();
    for (const char* name : {"a", "b", "c"}) {
      std::ofstream(dir_ / name) << "old " << name;
      std::ofstream(dir_ / "new" / name) << "new " << name;
      g_there.push_back(dir_ / name);
      renames.push_back({dir_ / "new" / name, dir_ / name, dir_ / (std::string(name) + ".old")});
    }
    if (fails) renames[2].to = dir_ / "gone" / "c";
    if (fails) {
      EXPECT_THROW(rename_together(renames, link_checking_targets), OutputError);
      EXPECT_EQ(text_of(dir_ / "a"), "old a");
      EXPECT_EQ(text_of(dir_ / "b"), "old b");
    } else {
      rename_together(renames, link_checking_targets);
      EXPECT_EQ(text_of(dir_ / "c"), "new c");
    }
    for (const auto& target : g_there) EXPECT_TRUE(std::filesystem::exists(target));
    for (const char* name : {"a.old", "b.old", "c.old"}) EXPECT_FALSE(std::filesystem::exists(dir_ / name));
  }
}

TEST_F(ImageFileTest, AnOldFileThatCannotBePutBackIsNamedAndKept) {
  std::filesystem::create_directories(dir_ / "new");
  std::vector<Rename> renames;
  g_there.clear();
  for (const char* name : {"a", "b"}) {
    std::ofstream(dir_ / name) << "old " << name;
    std::ofstream(dir_ / "new" / name) << "new " << name;
    g_there.push_back(dir_ / name);
    renames.push_back({dir_ / "new" / name, dir_ / name, dir_ / (std::string(name) + ".old")});
  }
  std::ofstream(dir_ / "new" / "c") << "new c";
  renames.push_back({dir_ / "new" / "c", dir_ / "gone" / "c", dir_ / "c.old"});
  try {
    rename_together(renames, link_then_block_the_first);
    ADD_FAILURE() << "no error";
  } catch (const OutputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("the old " + (dir_ / "a").string() + " is kept as " + (dir_ / "a.old").string()), std::string::npos)
        << message;
  }
  EXPECT_EQ(text_of(dir_ / "a.old"), "old a");
  EXPECT_EQ(text_of(dir_ / "b"), "old b");
}

}  // namespace
}  // namespace vkray
