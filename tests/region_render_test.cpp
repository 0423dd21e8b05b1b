// Regions on the device, and parts through the command line: a region of a GPU render is the whole
// render's pixels bit for bit, whatever the tiles, and `vkray render --region` parts merged by
// `vkray merge` are byte for byte the file a single `vkray render` writes.
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/errors.h"
#include "image/exr.h"
#include "image/image.h"
#include "session/regions.h"
#include "support/gpu_fixture.h"
#include "support/run_vkray.h"
#include "support/temp_dir.h"
#include "load/scene_loader.h"

namespace vkray::test {
namespace {

const std::string kScenes = VKRAY_SCENE_DIR;

using RegionRenderTest = GpuTest;

bool same_crop(const Image& part, const Image& whole, const PixelRegion& r) {
  if (part.width != r.width() || part.height != r.height()) return false;
  for (uint32_t y = 0; y < r.height(); ++y)
    if (std::memcmp(&part.at(0, y), &whole.at(r.x0, r.y0 + y), sizeof(glm::vec3) * r.width()) != 0) return false;
  return true;
}

std::string file_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Direct light, paths with a glass sphere, a textured glTF model: each region is the whole render's
// pixels exactly, and so are its first-hit passes. Odd bounds cut across workgroups and tiles.
TEST_F(RegionRenderTest, ARegionIsTheWholeRenderCroppedBitForBit) {
  for (const char* file : {"cornell.json", "cornell-path.json", "gltf/BoxTextured/glTF-Binary/BoxTextured.glb"}) {
    SCOPED_TRACE(file);
    const auto scene = std::make_shared<const Scene>(load_scene(kScenes + "/" + file));
    const DeviceScene on_device = session().upload(scene);
    RenderOptions options;
    options.width = 70;
    options.height = 53;
    options.samples_per_pixel = 3;
    options.aovs = true;
    const RenderResult whole = session().render(on_device, options);
    for (const PixelRegion region : {PixelRegion{3, 5, 41, 30}, PixelRegion{0, 52, 70, 53}, PixelRegion{69, 0, 70, 53}}) {
      options.region = region;
      options.tile_side = 8;  // other tiles than the whole render's
      const RenderResult part = session().render(on_device, options);
      EXPECT_EQ(part.region, region);
      EXPECT_TRUE(same_crop(part.image, whole.image, region)) << to_string(region);
      ASSERT_TRUE(part.aovs);
      EXPECT_EQ(part.aovs->width, region.width());
      for (uint32_t y = 0; y < region.height(); ++y)
        for (uint32_t x = 0; x < region.width(); ++x) {
          const size_t p = size_t(y) * region.width() + x, w = size_t(region.y0 + y) * 70 + region.x0 + x;
          ASSERT_EQ(std::memcmp(&part.aovs->normal[p], &whole.aovs->normal[w], sizeof(glm::vec3)), 0) << x << "," << y;
          ASSERT_EQ(part.aovs->object[p], whole.aovs->object[w]);
        }
    }
    // A band is resolved at the render when the caller has not.
    options.region = Band{1, 3};
    options.tile_side = 0;
    const RenderResult band = session().render(on_device, options);
    const PixelRegion expected = work_bands(*scene, {70, 53, 3, 0}, 3)[1];
    EXPECT_EQ(band.region, expected);
    EXPECT_TRUE(same_crop(band.image, whole.image, expected));
  }
}

TEST_F(RegionRenderTest, ARegionOutsideTheImageIsAUsageError) {
  const auto scene = std::make_shared<const Scene>(load_scene(kScenes + "/cornell.json"));
  const DeviceScene on_device = session().upload(scene);
  RenderOptions options;
  options.width = 32;
  options.height = 32;
  options.region = PixelRegion{0, 0, 33, 32};
  EXPECT_THROW(session().render(on_device, options), UsageError);
  options.region = Band{0, 33};
  EXPECT_THROW(session().render(on_device, options), UsageError);
}

// ---- through the command line ----------------------------------------------------------------------

CommandResult vkray(const std::string& args, const std::filesystem::path& cwd) { return run_vkray(args, cwd); }

TEST(RegionCliTest, FourBandsMergeIntoTheBytesOfOneRender) {
  TempDir dir;
  const std::string scene = kScenes + "/cornell-path.json --width 64 --height 48 --spp 4 --validate -q";
  for (const std::string type : {"pfm", "exr"}) {
    SCOPED_TRACE(type);
    const std::string extra = type == "exr" ? " --aov albedo,depth,object" : "";
    CommandResult run = vkray("render " + scene + extra + " -o whole." + type, dir.path());
    ASSERT_EQ(run.exit_code, 0) << run.err;
    std::string parts;
    for (int i = 0; i < 4; ++i) {
      const std::string part = "part" + std::to_string(i) + "." + type;
      run = vkray("render " + scene + extra + " --region " + std::to_string(i) + "/4 -o " + part, dir.path());
      ASSERT_EQ(run.exit_code, 0) << run.err;
      parts = part + " " + parts;  // merged in any order
    }
    if (type == "pfm") {
      EXPECT_TRUE(std::filesystem::exists(dir / "part0.pfm.json"));
    }
    run = vkray("merge merged." + type + " " + parts, dir.path());
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_NE(run.err.find("merged 4 parts of a 64 x 48 render (4 spp, seed 0"), std::string::npos) << run.err;
    EXPECT_EQ(file_bytes(dir / ("merged." + type)), file_bytes(dir / ("whole." + type)));
  }
  // An EXR part is a data window of the full display window, as other tools read it.
  const ExrFile part = read_exr(dir / "part2.exr");
  EXPECT_EQ(part.window.full_width, 64u);
  EXPECT_EQ(part.window.region.x1, 64u);
  EXPECT_GT(part.window.region.y0, 0u);
}

TEST(RegionCliTest, PixelBoundsRenderJustThosePixels) {
  TempDir dir;
  const std::string scene = kScenes + "/cornell.json --width 64 --height 48 -q";
  ASSERT_EQ(vkray("render " + scene + " -o whole.pfm", dir.path()).exit_code, 0);
  const CommandResult run = vkray("render " + scene + " --region 10,20,30,25 -o part.pfm", dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(same_crop(read_pfm(dir / "part.pfm"), read_pfm(dir / "whole.pfm"), {10, 20, 30, 25}));
  // One band of one is a part too: the whole image, with its record.
  ASSERT_EQ(vkray("render " + scene + " --region 0/1 -o one.pfm", dir.path()).exit_code, 0);
  EXPECT_TRUE(std::filesystem::exists(dir / "one.pfm.json"));
  ASSERT_EQ(vkray("merge merged.pfm one.pfm", dir.path()).exit_code, 0);
  EXPECT_EQ(file_bytes(dir / "merged.pfm"), file_bytes(dir / "whole.pfm"));
  // The CPU reference renders regions too.
  ASSERT_EQ(vkray("render " + scene + " --renderer cpu --region 0/2 -o cpu0.pfm", dir.path()).exit_code, 0);
  ASSERT_EQ(vkray("render " + scene + " --renderer cpu --region 1/2 -o cpu1.pfm", dir.path()).exit_code, 0);
  ASSERT_EQ(vkray("merge cpu.pfm cpu0.pfm cpu1.pfm", dir.path()).exit_code, 0);
  // GPU and CPU parts merge, and the merge says that the image is not bit-identical to either.
  ASSERT_EQ(vkray("render " + scene + " --region 1/2 -o gpu1.pfm", dir.path()).exit_code, 0);
  const CommandResult both = vkray("merge mixed.pfm cpu0.pfm gpu1.pfm", dir.path());
  ASSERT_EQ(both.exit_code, 0) << both.err;
  EXPECT_NE(both.err.find("more than one device"), std::string::npos) << both.err;
}

TEST(RegionCliTest, BadRegionsAndMergesExitWithAMessageAndWriteNothing) {
  TempDir dir;
  const std::string scene = kScenes + "/cornell.json --width 32 --height 32";
  struct Case {
    std::string args;
    int exit_code;
    std::string says;
  };
  for (const Case& c : std::vector<Case>{
           {"render " + scene + " --region 0,0,33,32 -o p.pfm", 2, "does not lie within the 32 x 32 image"},
           {"render " + scene + " --region 5/4 -o p.pfm", 2, "0 <= I < N"},
           {"render " + scene + " --region 0/33 -o p.pfm", 2, "a band has at least one row, so 1 to 32"},
           {"render " + scene + " --region 1,2 -o p.pfm", 2, "expected X0,Y0,X1,Y1"},
           {"render " + scene + " --region 0/2 -o p.png", 2, "name the output *.exr or *.pfm"},
           {"merge m.pfm", 2, "parts is required"},
           {"merge m.pfm missing.pfm", 1, "missing.pfm.json: not found"},
           {"merge m.txt missing.pfm", 1, "unknown image type"},
       }) {
    const CommandResult run = vkray(c.args, dir.path());
    EXPECT_EQ(run.exit_code, c.exit_code) << c.args << "\n" << run.err;
    EXPECT_NE(run.err.find(c.says), std::string::npos) << c.args << "\n" << run.err;
    EXPECT_TRUE(std::filesystem::is_empty(dir.path())) << c.args;
  }
  // Parts of two different scenes.
  ASSERT_EQ(vkray("render " + scene + " --region 0/2 -o a.pfm -q", dir.path()).exit_code, 0);
  ASSERT_EQ(vkray("render " + kScenes + "/cornell-spheres.json --width 32 --height 32 --region 1/2 -o b.pfm -q", dir.path()).exit_code, 0);
  const CommandResult run = vkray("merge m.pfm a.pfm b.pfm", dir.path());
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("b.pfm: is of another scene"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "m.pfm"));
}

TEST(RegionCliTest, APartRenderedAgainToAFullDiskLeavesTheOldPartAndItsRecord) {
  // `ulimit -f 16` makes the disk "full" after 16 KiB: enough for a record, not for a part's
  // pixels. The part and its record stay as they were, and they still merge.
  TempDir dir;
  const std::string scene = kScenes + "/cornell.json --renderer cpu --width 256 --height 256 -q";
  for (const std::string type : {"pfm", "exr"}) {
    SCOPED_TRACE(type);
    const std::string part = "p0." + type, record = type == "pfm" ? "p0.pfm.json" : part;
    ASSERT_EQ(vkray("render " + scene + " --region 0/2 -o " + part, dir.path()).exit_code, 0);
    ASSERT_EQ(vkray("render " + scene + " --region 1/2 -o p1." + type, dir.path()).exit_code, 0);
    const std::string pixels = file_bytes(dir / part), recorded = file_bytes(dir / record);
    const CommandResult run = run_vkray("render " + scene + " --seed 5 --region 0/2 -o " + part, dir.path(), "ulimit -f 16");
    EXPECT_EQ(run.exit_code, 1) << run.err;
    EXPECT_NE(run.err.find(part + ": "), std::string::npos) << run.err;
    EXPECT_NE(run.err.find("write failed"), std::string::npos) << run.err;
    EXPECT_EQ(file_bytes(dir / part), pixels);
    EXPECT_EQ(file_bytes(dir / record), recorded);
    for (const auto& entry : std::filesystem::directory_iterator(dir.path()))
      EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
    const CommandResult merge = vkray("merge m." + type + " " + part + " p1." + type, dir.path());
    EXPECT_EQ(merge.exit_code, 0) << merge.err;
  }
}

TEST(RegionCliTest, AMergeIntoOneOfItsPartsIsRefusedAndTheirFilesStay) {
  TempDir dir;
  const std::string scene = kScenes + "/cornell.json --renderer cpu --width 32 --height 32 -q";
  ASSERT_EQ(vkray("render " + scene + " --region 0/2 -o p0.pfm", dir.path()).exit_code, 0);
  ASSERT_EQ(vkray("render " + scene + " --region 1/2 -o p1.pfm", dir.path()).exit_code, 0);
  const std::string pixels = file_bytes(dir / "p0.pfm"), record = file_bytes(dir / "p0.pfm.json");
  for (const std::string output : {"p0.pfm", "./p0.pfm"}) {
    const CommandResult run = vkray("merge " + output + " p0.pfm p1.pfm", dir.path());
    EXPECT_EQ(run.exit_code, 1) << run.err;
    EXPECT_NE(run.err.find("the merge would replace it; name another output"), std::string::npos) << run.err;
  }
  EXPECT_EQ(file_bytes(dir / "p0.pfm"), pixels);
  EXPECT_EQ(file_bytes(dir / "p0.pfm.json"), record);
  EXPECT_EQ(vkray("merge m.pfm p0.pfm p1.pfm", dir.path()).exit_code, 0);
}

}  // namespace
}  // namespace vkray::test
