// Regions of a render, parts and their merge, on the host: --region's forms, bands of equal work,
// the CPU reference's regions against its whole image, the scene digest, and `vkray merge`'s rules.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/errors.h"
#include "image/merge.h"
#include "image/part.h"
#include "scene/digest.h"
#include "session/cpu_render.h"
#include "session/parts.h"
#include "session/regions.h"
#include "support/error_of.h"
#include "support/temp_dir.h"
#include "load/scene_loader.h"
#include "image/image_file.h"

namespace vkray::test {
namespace {

const std::filesystem::path kScenes = VKRAY_SCENE_DIR;

// A floor plane low in the view and a sphere, the sky above: the top rows cost a camera ray each,
// the bottom ones shadow rays and more.
const char* const kSkyAndGround = R"({
  "image": {"width": 48, "height": 64, "samples_per_pixel": 2},
  "camera": {"position": [0, 1, -6], "look_at": [0, 1, 0], "focal_length": 1.2},
  "background": [0.2, 0.3, 0.5],
  "materials": {"white": {"albedo": [0.8, 0.8, 0.8]}, "red": {"albedo": [0.8, 0.2, 0.2]}},
  "lights": [{"type": "point", "position": [0, 5, -2], "power": [400, 400, 400]},
             {"type": "point", "position": [3, 4, -3], "power": [200, 200, 200]}],
  "objects": [
    {"type": "triangles", "positions": [[-50, 0, -50], [50, 0, -50], [0, 0, 50]], "indices": [[0, 2, 1]], "material": "white"},
    {"type": "sphere", "center": [0, 0.8, 0], "radius": 0.8, "material": "red"}]})";

Scene sky_and_ground(const std::filesystem::path& file = "sky.json") { return parse_scene(kSkyAndGround, file); }

bool same_bits(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec3)) == 0;
}

std::vector<glm::vec3> crop(const Image& image, const PixelRegion& r) {
  std::vector<glm::vec3> out;
  for (uint32_t y = r.y0; y < r.y1; ++y)
    for (uint32_t x = r.x0; x < r.x1; ++x) out.push_back(image.at(x, y));
  return out;
}

// ---- --region's two forms --------------------------------------------------------------------

TEST(RegionTest, ParsesPixelBoundsAndBands) {
  EXPECT_EQ(std::get<PixelRegion>(parse_region("0,8,64,16")), (PixelRegion{0, 8, 64, 16}));
  EXPECT_EQ(std::get<Band>(parse_region("2/4")), (Band{2, 4}));
  EXPECT_EQ(std::get<Band>(parse_region("0/1")), (Band{0, 1}));
}

TEST(RegionTest, RefusesEverythingElseSayingWhatWasExpected) {
  for (const char* text : {"", "1,2,3", "1,2,3,4,5", "a,b,c,d", "-1,0,4,4", "0x1,0,4,4", "1/", "/4", "1/2/3", "1.5/4",
                           " 1,2,3,4", "99999999999,0,1,1", "0,0,4,4 "})
    EXPECT_NE(error_of([&] { parse_region(text); }).find("expected X0,Y0,X1,Y1"), std::string::npos) << text;
  EXPECT_NE(error_of([] { parse_region("4/4"); }).find("0 <= I < N"), std::string::npos);
  EXPECT_NE(error_of([] { parse_region("0/0"); }).find("0 <= I < N"), std::string::npos);
  EXPECT_NE(error_of([] { parse_region("4,0,4,8"); }).find("an empty rectangle"), std::string::npos);
  EXPECT_NE(error_of([] { parse_region("0,9,4,8"); }).find("an empty rectangle"), std::string::npos);
}

TEST(RegionTest, ARectangleMustLieWithinTheImage) {
  const Scene scene = sky_and_ground();
  const ImageSettings image{48, 64, 1, 0};
  EXPECT_EQ(resolve_region(scene, image, PixelRegion{0, 0, 48, 64}), (PixelRegion{0, 0, 48, 64}));
  EXPECT_NE(error_of([&] { resolve_region(scene, image, PixelRegion{0, 0, 49, 64}); }).find("within the 48 x 64 image"),
            std::string::npos);
  EXPECT_NE(error_of([&] { resolve_region(scene, image, PixelRegion{0, 60, 8, 65}); }).find("within"), std::string::npos);
}

// ---- bands of equal work ---------------------------------------------------------------------

TEST(RegionTest, BandsTileTheImageTopToBottomWithAtLeastOneRowEach) {
  const Scene scene = sky_and_ground();
  for (const uint32_t count : {1u, 2u, 3u, 7u, 63u, 64u}) {
    const std::vector<PixelRegion> bands = work_bands(scene, {48, 64, 4, 0}, count);
    ASSERT_EQ(bands.size(), count);
    uint32_t y = 0;
    for (const PixelRegion& b : bands) {
      EXPECT_EQ(b.x0, 0u);
      EXPECT_EQ(b.x1, 48u);
      EXPECT_EQ(b.y0, y) << count;
      EXPECT_GT(b.y1, b.y0) << count;
      y = b.y1;
    }
    EXPECT_EQ(y, 64u) << count;
  }
  EXPECT_NE(error_of([&] { work_bands(scene, {48, 64, 1, 0}, 65); }).find("1 to 64"), std::string::npos);
  EXPECT_NE(error_of([&] { work_bands(scene, {48, 64, 1, 0}, 0); }).find("1 to 64"), std::string::npos);
}

TEST(RegionTest, BandsFollowTheWorkNotTheRows) {
  // The sky costs one ray a pixel, the ground three (the camera ray and two shadow rays): the bands
  // over the sky are taller than those over the ground.
  const Scene scene = sky_and_ground();
  const std::vector<PixelRegion> bands = work_bands(scene, {48, 64, 1, 0}, 4);
  EXPECT_GT(bands.front().height(), bands.back().height() + 4) << to_string(bands.front()) << " " << to_string(bands.back());
  // Every process gets the same bands: they depend on the scene and the image, not on the call.
  EXPECT_EQ(work_bands(scene, {48, 64, 1, 0}, 4), bands);
  EXPECT_EQ(work_bands(sky_and_ground("elsewhere/sky.json"), {48, 64, 1, 0}, 4), bands);
  // The image's size moves them; the sample count does not (the work a row costs scales alike).
  EXPECT_EQ(work_bands(scene, {48, 64, 16, 0}, 4), bands);
  EXPECT_EQ(resolve_region(scene, {48, 64, 1, 0}, Band{3, 4}), bands[3]);
}

TEST(RegionTest, BandsDoNotDependOnTheSeed) {
  // A path tracer's paths end at random: the probe that weighs the rows must not follow the seed,
  // or `--region I/N` would name other pixels for another seed.
  const Scene scene = load_scene(kScenes / "cornell-path.json");
  const std::vector<PixelRegion> bands = work_bands(scene, {64, 64, 1, 0}, 8);
  for (const uint32_t seed : {1u, 7u, 123456u}) EXPECT_EQ(work_bands(scene, {64, 64, 1, seed}, 8), bands) << seed;
}

// ---- what a face hands over -------------------------------------------------------------------------

TEST(WriteRenderTest, APixelThatIsNotFiniteIsNeverWritten) {
  // Both renderers keep every value in the float range, so a NaN or an infinity is a fault of the
  // shaders or the driver: the render fails naming the pixel, and nothing is written.
  const Scene scene = sky_and_ground();
  RenderOptions options;
  options.threads = 2;
  options.region = PixelRegion{8, 4, 24, 20};
  for (const float bad : {std::nanf(""), INFINITY, -INFINITY}) {
    RenderResult result = render_on_cpu(scene, options);
    result.image.at(3, 2).g = bad;
    result.image.at(9, 9).b = bad;
    for (const char* name : {"out.png", "out.pfm", "out.exr"}) {
      TempDir dir;
      RenderResult shown = result;
      shown.part = std::string(name) != "out.png";
      const std::string message = error_of([&] { write_render(dir / name, scene, shown, {}, "test"); });
      EXPECT_NE(message.find("2 pixels are not finite, the first at (11, 6)"), std::string::npos) << message;
      EXPECT_TRUE(std::filesystem::is_empty(dir.path())) << name;
    }
  }
  EXPECT_NO_THROW(check_finite(render_on_cpu(scene, options)));  // a finite render passes
}

// ---- the CPU reference's regions ---------------------------------------------------------------

TEST(RegionTest, ACpuRegionIsTheWholeRenderCroppedBitForBit) {
  const Scene scene = sky_and_ground();
  RenderOptions options;
  options.threads = 2;
  options.aovs = true;
  const RenderResult whole = render_on_cpu(scene, options);
  for (const PixelRegion region : {PixelRegion{5, 7, 29, 40}, PixelRegion{0, 63, 48, 64}, PixelRegion{47, 0, 48, 64}}) {
    options.region = region;
    const RenderResult part = render_on_cpu(scene, options);
    EXPECT_EQ(part.region, region);
    EXPECT_EQ(part.settings.width, 48u);
    ASSERT_EQ(part.image.width, region.width());
    ASSERT_EQ(part.image.height, region.height());
    EXPECT_TRUE(same_bits(part.image.pixels, crop(whole.image, region))) << to_string(region);
    ASSERT_TRUE(part.aovs);
    EXPECT_EQ(part.aovs->width, region.width());
    EXPECT_EQ(part.aovs->depth[0], whole.aovs->depth[size_t(region.y0) * 48 + region.x0]);
    EXPECT_EQ(part.aovs->object.back(), whole.aovs->object[size_t(region.y1 - 1) * 48 + region.x1 - 1]);
  }
}

// ---- the scene digest ----------------------------------------------------------------------------

TEST(RegionTest, TheDigestFollowsWhatRendersNotWhereTheFileIs) {
  const std::string digest = scene_digest(sky_and_ground());
  EXPECT_EQ(digest.size(), 32u);
  EXPECT_EQ(scene_digest(sky_and_ground("/other/folder/copy.json")), digest);
  std::string text = kSkyAndGround;
  // A description and the image settings are not in it (a part records those beside it).
  const std::string described = std::string(R"({"description": "the same scene",)") + (text.c_str() + 1);
  EXPECT_EQ(scene_digest(parse_scene(described, "sky.json")), digest);
  std::string resized = text;
  resized.replace(resized.find("\"width\": 48"), 11, "\"width\": 50");
  EXPECT_EQ(scene_digest(parse_scene(resized, "sky.json")), digest);
  // Anything that can change a pixel is.
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {"[0.8, 0.2, 0.2]", "[0.8, 0.2, 0.21]"}, {"[400, 400, 400]", "[400, 400, 401]"}, {"\"radius\": 0.8", "\"radius\": 0.81"},
           {"[0, 1, -6]", "[0, 1, -6.001]"}, {"[0.2, 0.3, 0.5]", "[0.2, 0.3, 0.6]"}, {"[0, 0, 50]", "[0, 0, 51]"}}) {
    std::string edited = text;
    edited.replace(edited.find(from), from.size(), to);
    EXPECT_NE(scene_digest(parse_scene(edited, "sky.json")), digest) << from << " -> " << to;
  }
}

// ---- parts and their merge -----------------------------------------------------------------------

struct Rendered {
  Scene scene;
  RenderResult whole;
};

// What a part of the sky scene records, unless a test says otherwise.
PartRecord sky_record(const Scene& scene, const PixelRegion& region, const std::string& shader = "") {
  return {scene_digest(scene), 48, 64, region, 2, 0, "test", "CPU reference", shader, "", ""};
}

// The sky scene on the CPU, whole and as parts cut by `regions`, each written to `dir` as `suffix`
// with the record `edit` makes of sky_record's.
std::vector<std::filesystem::path> write_parts(const Rendered& r, const std::vector<PixelRegion>& regions,
                                               const std::filesystem::path& dir, const std::string& suffix,
                                               const OutputContent& content = {}, const std::string& shader = "",
                                               const std::function<void(PartRecord&)>& edit = {}) {
  std::vector<std::filesystem::path> files;
  for (size_t i = 0; i < regions.size(); ++i) {
    RenderOptions options;
    options.threads = 2;
    options.aovs = !content.passes.empty();
    options.region = regions[i];
    const RenderResult part = render_on_cpu(r.scene, options);
    PartRecord record = sky_record(r.scene, regions[i], shader);
    if (edit) edit(record);
    files.push_back(dir / ("part" + std::to_string(i) + suffix));
    write_part(files.back(), part.image, part.aovs ? &*part.aovs : nullptr, content, record);
  }
  return files;
}

Rendered rendered(bool aovs = false) {
  Rendered r{sky_and_ground(), {}};
  RenderOptions options;
  options.threads = 2;
  options.aovs = aovs;
  r.whole = render_on_cpu(r.scene, options);
  return r;
}

const std::vector<PixelRegion> kQuarters{{0, 0, 20, 30}, {20, 0, 48, 30}, {0, 30, 48, 50}, {0, 50, 48, 64}};

std::string file_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(MergeTest, PfmPartsMergeIntoTheBytesOfTheWholeImage) {
  TempDir dir;
  const Rendered r = rendered();
  const auto files = write_parts(r, kQuarters, dir.path(), ".pfm");
  for (const auto& f : files) EXPECT_TRUE(std::filesystem::exists(sidecar_of(f))) << f;
  const Part part = read_part(files[1]);
  EXPECT_EQ(part.record.region, kQuarters[1]);
  EXPECT_EQ(part.record.scene_digest, scene_digest(r.scene));
  const MergeSummary summary = merge_part_files(dir / "merged.pfm", {files[3], files[0], files[2], files[1]});  // any order
  EXPECT_EQ(summary.parts, 4u);
  EXPECT_FALSE(summary.mixed_devices);
  write_image(r.whole.image, dir / "whole.pfm");
  EXPECT_EQ(file_bytes(dir / "merged.pfm"), file_bytes(dir / "whole.pfm"));
}

TEST(MergeTest, ExrPartsCarryTheirDataWindowAndPassesAndMergeExactly) {
  TempDir dir;
  const Rendered r = rendered(true);
  OutputContent content;
  content.passes = {Aov::albedo, Aov::depth, Aov::object};
  const auto files = write_parts(r, kQuarters, dir.path(), ".exr", content);
  const ExrFile exr = read_exr(files[1]);
  EXPECT_EQ(exr.window.full_width, 48u);
  EXPECT_EQ(exr.window.full_height, 64u);
  EXPECT_EQ(exr.window.region, kQuarters[1]);
  EXPECT_NE(exr.window.part_record.find("\"scene_digest\""), std::string::npos);
  merge_part_files(dir / "merged.exr", files);
  write_exr(dir / "whole.exr", r.whole.image, &*r.whole.aovs, content);
  EXPECT_EQ(file_bytes(dir / "merged.exr"), file_bytes(dir / "whole.exr"));
  // To a PNG, the passes are dropped, and said to be.
  EXPECT_TRUE(merge_part_files(dir / "merged.png", files).passes_dropped);
}

TEST(MergeTest, RefusesOverlapsAndGapsNamingThePixels) {
  TempDir dir;
  const Rendered r = rendered();
  const auto files = write_parts(r, {{0, 0, 48, 32}, {0, 31, 48, 64}, {0, 32, 40, 64}}, dir.path(), ".pfm");
  const std::string overlap = error_of([&] { merge_part_files(dir / "m.pfm", {files[0], files[1]}); });
  EXPECT_NE(overlap.find("part1.pfm: its region 0,31,48,64 overlaps region 0,0,48,32"), std::string::npos) << overlap;
  EXPECT_NE(overlap.find("pixels 0,31,48,32"), std::string::npos) << overlap;
  const std::string gap = error_of([&] { merge_part_files(dir / "m.pfm", {files[0], files[2]}); });
  EXPECT_NE(gap.find("no part covers pixels 40 to 47 of row 32"), std::string::npos) << gap;
  const std::string missing = error_of([&] { merge_part_files(dir / "m.pfm", {files[2]}); });
  EXPECT_NE(missing.find("no part covers pixels 0 to 47 of row 0"), std::string::npos) << missing;
  EXPECT_FALSE(std::filesystem::exists(dir / "m.pfm"));
}

TEST(MergeTest, RefusesPartsOfAnotherRenderNamingWhatDiffers) {
  TempDir dir;
  const Rendered r = rendered();
  const std::vector<PixelRegion> halves{{0, 0, 48, 32}, {0, 32, 48, 64}};
  const auto files = write_parts(r, halves, dir.path(), ".pfm", {}, "spirv1");
  // The second half written by a render that differs in each field in turn, with a record of its own.
  for (const auto& [edit, says] : std::vector<std::pair<std::function<void(PartRecord&)>, std::string>>{
           {[](PartRecord& p) { p.scene_digest = std::string(32, 'f'); }, "of another scene"},
           {[](PartRecord& p) { p.width = 49; }, "of an image of 49 x 64, not 48 x 64"},
           {[](PartRecord& p) { p.samples_per_pixel = 3; }, "samples per pixel 3, not 2"},
           {[](PartRecord& p) { p.seed = 7; }, "seed 7, not 0"},
           {[](PartRecord& p) { p.version = "other"; }, "rendered by vkray other, not test"},
           {[](PartRecord& p) { p.shader = "spirv2"; }, "traced by other shaders: SPIR-V spirv2, not spirv1"}}) {
    std::filesystem::create_directories(dir / "other");
    const auto other = write_parts(r, halves, dir / "other", ".pfm", {}, "spirv1", edit);
    const std::string message = error_of([&] { merge_part_files(dir / "m.pfm", {files[0], other[1]}); });
    EXPECT_NE(message.find("part1.pfm"), std::string::npos) << message;
    EXPECT_NE(message.find(says), std::string::npos) << message;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "m.pfm"));
}

// Text `from` replaced by `to` in `file` (in an EXR, text of the same length: its header stays well-formed).
void edit_file(const std::filesystem::path& file, const std::string& from, const std::string& to) {
  if (is_exr(file)) {
    ASSERT_EQ(from.size(), to.size());
  }
  std::string bytes = file_bytes(file);
  const size_t at = bytes.find(from);
  ASSERT_NE(at, std::string::npos) << from << " in " << file;
  bytes.replace(at, from.size(), to);
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
}

TEST(MergeTest, ARecordEditedInAnyFieldIsRefusedNamingIt) {
  // Whatever field of a record is changed after vkray wrote it, in a PFM's sidecar or an EXR's
  // header, the record is refused: its hash covers every field, not only the pixels.
  TempDir dir;
  const Rendered r = rendered();
  for (const std::string type : {".pfm", ".exr"}) {
    SCOPED_TRACE(type);
    for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
             {scene_digest(r.scene), std::string(32, 'f')},
             {"\"width\":48", "\"width\":49"},
             {"\"region\":[0,32,48,64]", "\"region\":[0,32,48,63]"},
             {"\"spp\":2", "\"spp\":3"},
             {"\"seed\":0", "\"seed\":7"},
             {"\"vkray_version\":\"test\"", "\"vkray_version\":\"tess\""},
             {"\"device\":\"CPU reference\"", "\"device\":\"CPU REFERENCE\""},
             {"\"shader\":\"spirv1\"", "\"shader\":\"spirv2\""},
             {"\"pixels\":\"", ""},
             {"\"hash\":\"", ""}}) {
      SCOPED_TRACE(from);
      const auto files = write_parts(r, {{0, 0, 48, 32}, {0, 32, 48, 64}}, dir.path(), type, {}, "spirv1");
      const std::filesystem::path record = type == ".pfm" ? sidecar_of(files[1]) : files[1];
      if (!to.empty()) {
        edit_file(record, from, to);
      } else {  // a hash: its first digit changed
        const std::string text = file_bytes(record);
        const std::string digits = text.substr(text.find(from) + from.size(), 32);
        edit_file(record, from + digits, from + (digits[0] == '0' ? '1' : '0') + digits.substr(1));
      }
      const std::string message = error_of([&] { merge_part_files(dir / ("m" + type), files); });
      EXPECT_NE(message.find((type == ".pfm" ? "part1.pfm.json" : "part1.exr") + std::string(": the part's record is not as vkray")),
                std::string::npos) << message;
      EXPECT_NE(message.find("its fields do not match its \"hash\""), std::string::npos) << message;
      EXPECT_FALSE(std::filesystem::exists(dir / ("m" + type)));
    }
  }
}

TEST(MergeTest, PfmRecordsWithTheirRegionsSwappedAreRefused) {
  // Two parts of one size whose records trade their regions would merge into the two halves
  // swapped; records that trade places, each beside the other's pixels, likewise.
  TempDir dir;
  const Rendered r = rendered();
  const auto files = write_parts(r, {{0, 0, 48, 32}, {0, 32, 48, 64}}, dir.path(), ".pfm");
  edit_file(sidecar_of(files[0]), "\"region\":[0,0,48,32]", "\"region\":[0,32,48,64]");
  edit_file(sidecar_of(files[1]), "\"region\":[0,32,48,64]", "\"region\":[0,0,48,32]");
  EXPECT_NE(error_of([&] { merge_part_files(dir / "m.pfm", files); }).find("its fields do not match"), std::string::npos);
  write_parts(r, {{0, 0, 48, 32}, {0, 32, 48, 64}}, dir.path(), ".pfm");
  std::filesystem::rename(sidecar_of(files[0]), dir / "record0");
  std::filesystem::rename(sidecar_of(files[1]), sidecar_of(files[0]));
  std::filesystem::rename(dir / "record0", sidecar_of(files[1]));
  const std::string message = error_of([&] { merge_part_files(dir / "m.pfm", files); });
  EXPECT_NE(message.find("part0.pfm: its pixels are not the ones its record part0.pfm.json was written with"), std::string::npos)
      << message;
  EXPECT_FALSE(std::filesystem::exists(dir / "m.pfm"));
}

TEST(MergeTest, TheOutputIsNeverOneOfThePartsOrTheirRecords) {
  // However the output is spelled or linked, a merge that would replace a part (or a PFM part's
  // record) writes nothing, and the parts still merge.
  TempDir dir;
  const Rendered r = rendered();
  const auto files = write_parts(r, {{0, 0, 48, 32}, {0, 32, 48, 64}}, dir.path(), ".pfm");
  std::filesystem::create_directory(dir / "sub");
  std::filesystem::create_symlink(files[0], dir / "link.pfm");
  std::filesystem::create_symlink(sidecar_of(files[1]), dir / "record-link.pfm");
  std::filesystem::create_hard_link(files[1], dir / "hard.pfm");
  std::filesystem::create_directory_symlink(dir.path(), dir / "same-folder");
  const std::string part0 = file_bytes(files[0]), record0 = file_bytes(sidecar_of(files[0]));
  for (const std::filesystem::path& output : {files[0], dir / "sub" / ".." / "part0.pfm", dir / "." / "part1.pfm",
                                              dir / "link.pfm", dir / "record-link.pfm", dir / "hard.pfm",
                                              dir / "same-folder" / "part0.pfm"}) {
    SCOPED_TRACE(output);
    try {
      merge_part_files(output, files);
      ADD_FAILURE() << "merged into a part";
    } catch (const OutputError& e) {
      EXPECT_NE(std::string(e.what()).find("the merge would replace it; name another output"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(file_bytes(files[0]), part0);
  EXPECT_EQ(file_bytes(sidecar_of(files[0])), record0);
  // A part given twice, however spelled, is named as such rather than as an overlap.
  EXPECT_NE(error_of([&] { merge_part_files(dir / "m.pfm", {files[0], files[1], dir / "sub" / ".." / "part1.pfm"}); })
                .find("part1.pfm: is given twice (also as "),
            std::string::npos);
  EXPECT_EQ(merge_part_files(dir / "m.pfm", files).parts, 2u);
}

TEST(MergeTest, ACpuReferencePartJoinsGpuPartsWithAWarning) {
  // The CPU reference has no shader: its part may join parts a GPU traced, and the merge says that
  // the image is then the render's within parity only.
  TempDir dir;
  const Rendered r = rendered();
  auto files = write_parts(r, {{0, 0, 48, 32}}, dir.path(), ".pfm", {}, "");
  std::filesystem::create_directory(dir / "gpu");
  const auto gpu = write_parts(r, {{0, 0, 48, 32}, {0, 32, 48, 64}}, dir / "gpu", ".pfm", {}, "spirv1",
                               [](PartRecord& p) { p.device = "a GPU (driver 1)"; });
  files.push_back(gpu[1]);
  EXPECT_TRUE(merge_part_files(dir / "m.pfm", files).mixed_devices);
  // The CPU part first does not let GPU parts of two shaders through.
  std::filesystem::create_directory(dir / "other");
  const auto other = write_parts(r, {{0, 32, 48, 48}, {0, 48, 48, 64}}, dir / "other", ".pfm", {}, "spirv2");
  const std::string message = error_of([&] { merge_part_files(dir / "m2.pfm", {files[0], gpu[1], other[1]}); });
  EXPECT_NE(message.find("part1.pfm: was traced by other shaders: SPIR-V spirv2, not spirv1"), std::string::npos) << message;
}

TEST(MergeTest, APartWrittenAgainAfterItsRecordIsRefused) {
  // A record holds the hash of the pixels it was written with: another render's pixels under the
  // same name (a rerun that failed half-way, a copy from elsewhere) do not pass for the part,
  // beside a PFM's sidecar or under an EXR's header attribute (its data window still the region).
  TempDir dir;
  const Rendered r = rendered();
  const auto pfm = write_parts(r, {{0, 0, 48, 32}, {0, 32, 48, 64}}, dir.path(), ".pfm");
  const auto exr = write_parts(r, {{0, 0, 48, 32}, {0, 32, 48, 64}}, dir.path(), ".exr");
  Image other(48, 32);
  other.at(5, 5) = glm::vec3(1.0f);
  write_image(other, pfm[0]);
  const ExrPartHeader header{48, 64, {0, 0, 48, 32}, [record = read_exr(exr[0]).window.part_record](const std::string&) { return record; }};
  write_exr(exr[0], other, nullptr, {}, &header);
  for (const auto& [files, says] : std::vector<std::pair<std::vector<std::filesystem::path>, std::string>>{
           {pfm, "part0.pfm: its pixels are not the ones its record part0.pfm.json was written with"},
           {exr, "part0.exr: its pixels are not the ones its record (attribute \"vkray.part\") was written with"}}) {
    std::filesystem::path output = dir / "m";
    output += files[0].extension();  // not "m" + ...: GCC 12 warns falsely (-Wrestrict) on that concatenation
    const std::vector<std::filesystem::path>& parts = files;  // a lambda cannot capture a structured binding in clang 14
    const std::string message = error_of([&] { merge_part_files(output, parts); });
    EXPECT_NE(message.find(says), std::string::npos) << message;
    EXPECT_FALSE(std::filesystem::exists(output));
  }
}

TEST(MergeTest, RefusesFilesThatAreNotPartsNamingThem) {
  TempDir dir;
  const Rendered r = rendered();
  const auto files = write_parts(r, {{0, 0, 48, 64}}, dir.path(), ".pfm");
  write_image(r.whole.image, dir / "whole.exr");
  write_image(r.whole.image, dir / "whole.png");
  EXPECT_NE(error_of([&] { read_part(dir / "whole.exr"); }).find("no \"vkray.part\" attribute"), std::string::npos);
  EXPECT_NE(error_of([&] { read_part(dir / "whole.png"); }).find("parts are the .exr or .pfm files"), std::string::npos);
  std::filesystem::remove(sidecar_of(files[0]));
  EXPECT_NE(error_of([&] { read_part(files[0]); }).find("part0.pfm.json: not found"), std::string::npos);
  for (const char* bad : {"{", "[]", R"({"scene_digest": 1})", R"({"scene_digest": "x", "width": -1, "height": 64, "region": [0,0,1,1], "spp": 1, "seed": 0, "vkray_version": "v", "device": "d", "shader": ""})",
                          R"({"scene_digest": "x", "width": 48, "height": 64, "region": [0,0,49,1], "spp": 1, "seed": 0, "vkray_version": "v", "device": "d", "shader": ""})",
                          R"({"scene_digest": "x", "width": 48, "height": 64, "region": [0,0,48,64], "spp": 1, "seed": 0, "vkray_version": "v", "device": "d"})",
                          R"({"scene_digest": "x", "width": 48, "height": 64, "region": [0,0,48,64], "spp": 1, "seed": 0, "vkray_version": "v", "device": "d", "shader": ""})"}) {
    std::ofstream(sidecar_of(files[0]), std::ios::trunc) << bad;
    const std::string message = error_of([&] { read_part(files[0]); });
    EXPECT_NE(message.find("part0.pfm.json: the part's record"), std::string::npos) << bad << ": " << message;
  }
  // A record of an older build, which did not record the shaders: said so.
  std::ofstream(sidecar_of(files[0]), std::ios::trunc)
      << R"({"scene_digest": "x", "width": 48, "height": 64, "region": [0,0,48,64], "spp": 1, "seed": 0, "vkray_version": "0.0.9", "device": "d"})";
  EXPECT_NE(error_of([&] { read_part(files[0]); }).find("has no \"shader\" (it was written by vkray 0.0.9: render the part again"),
            std::string::npos);
  // A record of the build before records had a hash of their own.
  std::ofstream(sidecar_of(files[0]), std::ios::trunc)
      << R"x({"scene_digest":"ee7d9f1b0876cc1b8749e8d83c87dd95","width":48,"height":64,"region":[0,0,48,64],"spp":1,"seed":0,"vkray_version":"0.1.0 (commit 56ace8ef142e)","device":"CPU reference","shader":"","pixels":"d05a5917148f434b606ddf4277b6f93d"})x";
  EXPECT_NE(error_of([&] { read_part(files[0]); })
                .find("has no \"hash\" (it was written by vkray 0.1.0 (commit 56ace8ef142e): render the part again with this build)"),
            std::string::npos);
  // A key no build records: the hash does not cover it.
  PartRecord record{"x", 48, 64, {0, 0, 48, 64}, 1, 0, "v", "d", "", "x", ""};
  record.hash = part_record_hash(record);
  std::string json = part_record_json(record);
  json.insert(1, R"("note": "mine", )");
  std::ofstream(sidecar_of(files[0]), std::ios::trunc) << json;
  EXPECT_NE(error_of([&] { read_part(files[0]); }).find("has a key \"note\" that this build does not record"), std::string::npos);
  // A record, whole, whose region is not the picture's size.
  record.region = {0, 0, 48, 32};
  record.hash = part_record_hash(record);
  std::ofstream(sidecar_of(files[0]), std::ios::trunc) << part_record_json(record);
  EXPECT_NE(error_of([&] { read_part(files[0]); }).find("48 x 64 pixels, but its record names region 0,0,48,32"),
            std::string::npos);
  EXPECT_NE(error_of([] { merge_parts({}); }).find("no parts"), std::string::npos);
}

TEST(MergeTest, APfmWhoseHeaderIsNotItsSizeIsRefusedBeforeAnythingIsAllocated) {
  TempDir dir;
  std::ofstream(dir / "huge.pfm", std::ios::binary) << "PF\n65536 65536\n-1\n" << std::string(12, '\0');
  EXPECT_NE(error_of([&] { read_pfm(dir / "huge.pfm"); }).find("a PFM header of 65536 x 65536 pixels in a file of"),
            std::string::npos);
  std::ofstream(dir / "long.pfm", std::ios::binary) << "PF\n1 1\n-1\n" << std::string(13, '\0');
  EXPECT_NE(error_of([&] { read_pfm(dir / "long.pfm"); }).find("in a file of 23 bytes"), std::string::npos);
  std::ofstream(dir / "word.pfm", std::ios::binary) << std::string(1 << 20, 'P');
  EXPECT_NE(error_of([&] { read_pfm(dir / "word.pfm"); }).find("not a little-endian RGB PFM"), std::string::npos);
}

}  // namespace
}  // namespace vkray::test
