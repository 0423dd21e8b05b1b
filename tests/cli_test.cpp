// The vkray command as a user runs it: outputs, messages and exit codes.

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "image/image.h"
#include "support/run_vkray.h"
#include "support/slow_shaders.h"
#include "support/temp_dir.h"

namespace vkray::test {
namespace {

using Result = CommandResult;

Result vkray(const std::string& args, const std::filesystem::path& cwd) { return run_vkray(args, cwd); }

// Anything left in a folder: an image, or a temporary file a failed write did not remove.
bool has_image_files(const std::filesystem::path& dir) { return !std::filesystem::is_empty(dir); }

const std::string kScenes = VKRAY_SCENE_DIR;

void expect_png_size(const std::filesystem::path& file, uint32_t width, uint32_t height) {
  const Image image = read_png(file);
  EXPECT_EQ(image.width, width);
  EXPECT_EQ(image.height, height);
}

TEST(CliTest, RendersTheDefaultSceneToSceneNamePng) {
  TempDir dir;
  const Result run = vkray("render --validate --width 64 --height 48", dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  expect_png_size(dir / "cornell.png", 64, 48);
  // stderr reports the device, every phase and the ray rate.
  for (const char* word : {"device ", "load ", "compile ", "upload ", "trace ", "read back ", "write ", "Mrays/s", "wrote cornell.png"})
    EXPECT_NE(run.err.find(word), std::string::npos) << word << " missing from:\n" << run.err;
}

TEST(CliTest, QuietPrintsNothing) {
  TempDir dir;
  const Result run = vkray("render --validate " + kScenes + "/cornell-spheres.json -q -o s.pfm --width 32 --height 32 --spp 4", dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err, "");
  EXPECT_EQ(read_pfm(dir / "s.pfm").width, 32u);
}

TEST(CliTest, BadSceneExitsOneNamingFileAndKeyAndWritesNothing) {
  TempDir dir;
  std::ofstream(dir / "bad.json") << R"({"camera": {"position": [0, 0, 0], "direction": [0, 0, 1], "focal_length": 1},
    "materials": {"m": {"albedo": [1, 1, 1]}},
    "objects": [{"type": "sphere", "center": [0, 0, 5], "radius": -2, "material": "m"}]})";
  const Result run = vkray("render --validate bad.json -o out.png", dir.path());
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("bad.json: /objects/0/radius: expected a number > 0"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "out.png"));
  std::filesystem::remove(dir / "bad.json");
  EXPECT_FALSE(has_image_files(dir.path()));
}

TEST(CliTest, AnEnvironmentFlagLightsTheSceneOrNamesItsFile) {
  TempDir dir;
  const std::string sky = std::string(VKRAY_CHECK_DIR) + "/environment/sky.hdr";
  const Result lit = vkray("render --validate " + kScenes + "/gltf/BoxTextured/glTF-Binary/BoxTextured.glb --environment " + sky +
                               " -o box.pfm --width 24 --height 24 --spp 4",
                           dir.path());
  ASSERT_EQ(lit.exit_code, 0) << lit.err;
  EXPECT_EQ(lit.err.find("adds a point light at the camera"), std::string::npos) << lit.err;
  EXPECT_GT(read_pfm(dir / "box.pfm").at(0, 0).b, 0.0f);  // the sky, where the box is not
  const Result missing = vkray("render --validate --environment nowhere.hdr -o out.png", dir.path());
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("nowhere.hdr: not found"), std::string::npos) << missing.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "out.png"));
}

TEST(CliTest, MissingSceneExitsOne) {
  TempDir dir;
  const Result run = vkray("render nowhere.json", dir.path());
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("nowhere.json"), std::string::npos) << run.err;
}

TEST(CliTest, BrokenShaderExitsOneWithFileAndLineAndWritesNothing) {
  TempDir dir;
  std::filesystem::copy(VKRAY_SHADER_DIR, dir / "shaders", std::filesystem::copy_options::recursive);
  {
    std::ofstream(dir / "shaders" / "shade.glsl", std::ios::app) << "\nthis is not glsl;\n";
  }
  const Result run = vkray("render --validate --shader-dir shaders -o out.png", dir.path());
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("shaders/shade.glsl:"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "out.png"));
}

// A copy of shaders/ in `dir` with `from` replaced by `to` in `file`.
void copy_shaders_with_edit(const std::filesystem::path& dir, const std::string& file, const std::string& from,
                            const std::string& to) {
  std::filesystem::copy(VKRAY_SHADER_DIR, dir / "shaders", std::filesystem::copy_options::recursive);
  std::ifstream in(dir / "shaders" / file);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  ASSERT_NE(text.find(from), std::string::npos) << from;
  text.replace(text.find(from), from.size(), to);
  std::ofstream(dir / "shaders" / file) << text;
}

TEST(CliTest, AShaderThatDeclaresABindingOtherwiseThanVkrayBindsItExitsOne) {
  // Checked against the binding table before any pipeline exists: a message naming the resource,
  // not a validation error or a crash.
  TempDir retyped;
  copy_shaders_with_edit(retyped.path(), "resources.glsl", "binding = VKRAY_BINDING_FRAME) uniform Frame",
                         "binding = VKRAY_BINDING_FRAME) readonly buffer Frame");
  const Result run = vkray("render --validate --shader-dir shaders -o out.png", retyped.path());
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("'Frame' at binding 0 is declared as a buffer block; vkray binds a uniform block there"),
            std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(retyped / "out.png"));

  TempDir moved;
  copy_shaders_with_edit(moved.path(), "resources.glsl", "binding = VKRAY_BINDING_LIGHTS)", "binding = 19)");
  const Result run2 = vkray("render --validate --shader-dir shaders -o out.png", moved.path());
  EXPECT_EQ(run2.exit_code, 1) << run2.err;
  EXPECT_NE(run2.err.find("'lights' is declared at binding 19, where vkray binds nothing"), std::string::npos) << run2.err;

  TempDir other_set;
  copy_shaders_with_edit(other_set.path(), "resources.glsl", "set = 0, binding = VKRAY_BINDING_LIGHTS",
                         "set = 1, binding = VKRAY_BINDING_LIGHTS");
  const Result run3 = vkray("render --validate --shader-dir shaders -o out.png", other_set.path());
  EXPECT_EQ(run3.exit_code, 1) << run3.err;
  EXPECT_NE(run3.err.find("'lights' is declared in descriptor set 1; vkray binds set 0 only"), std::string::npos)
      << run3.err;
}

TEST(CliTest, UsageErrorsExitTwo) {
  TempDir dir;
  EXPECT_EQ(vkray("", dir.path()).exit_code, 2);
  EXPECT_EQ(vkray("frobnicate", dir.path()).exit_code, 2);
  EXPECT_EQ(vkray("render --spp 0", dir.path()).exit_code, 2);
  EXPECT_EQ(vkray("render --width -3", dir.path()).exit_code, 2);
  EXPECT_EQ(vkray("render --no-such-flag", dir.path()).exit_code, 2);
  EXPECT_EQ(vkray("watch --threads 2", dir.path()).exit_code, 2);  // watch has no CPU renderer
  const Result bad_path = vkray("render --inline-scene sometimes", dir.path());
  EXPECT_EQ(bad_path.exit_code, 2);
  EXPECT_NE(bad_path.err.find("sometimes not in {auto,always,never}"), std::string::npos) << bad_path.err;
  EXPECT_FALSE(has_image_files(dir.path()));
}

TEST(CliTest, InlineSceneChoosesTheGpuPathAndSaysWhichItTook) {
  TempDir dir;
  const Result compiled_in = vkray("render --inline-scene always --width 40 --height 30 -o a.png", dir.path());
  ASSERT_EQ(compiled_in.exit_code, 0) << compiled_in.err;
  EXPECT_NE(compiled_in.err.find("scene compiled into the shader"), std::string::npos) << compiled_in.err;
  const Result bvh = vkray("render --inline-scene never --width 40 --height 30 -o b.png", dir.path());
  ASSERT_EQ(bvh.exit_code, 0) << bvh.err;
  EXPECT_EQ(bvh.err.find("compiled into"), std::string::npos) << bvh.err;
  // auto: too few camera rays at 40 x 30 to repay the compile.
  const Result automatic = vkray("render --width 40 --height 30 -o c.png", dir.path());
  ASSERT_EQ(automatic.exit_code, 0) << automatic.err;
  EXPECT_EQ(automatic.err.find("compiled into"), std::string::npos) << automatic.err;
}

TEST(CliTest, UnknownOutputTypeExitsOneBeforeRendering) {
  TempDir dir;
  const Result run = vkray("render -o out.jpg", dir.path());
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("out.jpg"), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find("device "), std::string::npos) << "should fail before touching the device";
}

TEST(CliTest, WatchRefusesAnOutputItCannotWriteBeforeStarting) {
  TempDir dir;
  const Result run = vkray("watch -o no-such-folder/live.png", dir.path());
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("no-such-folder does not exist"), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find("device "), std::string::npos) << "should fail before touching the device";
}

TEST(CliTest, UnknownDeviceExitsThreeAndListsDevices) {
  TempDir dir;
  const Result run = vkray("render --device no-such-gpu", dir.path());
  EXPECT_EQ(run.exit_code, 3);
  EXPECT_NE(run.err.find("no Vulkan device matches --device \"no-such-gpu\""), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("0: "), std::string::npos) << run.err;
}

TEST(CliTest, DevicesListsEachDevice) {
  TempDir dir;
  const Result run = vkray("devices", dir.path());
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("0: "), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("max texel buffer elements"), std::string::npos) << run.out;
}

TEST(CliTest, CpuRendererWritesTheSameKindOfImage) {
  TempDir dir;
  const Result run = vkray("render --renderer cpu --threads 2 -o c.pfm --width 40 --height 30", dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(read_pfm(dir / "c.pfm").width, 40u);
  EXPECT_NE(run.err.find("CPU reference, 2 threads"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("Mrays/s"), std::string::npos) << run.err;
  EXPECT_EQ(vkray("render --renderer fpga", dir.path()).exit_code, 2);
}

TEST(CliTest, ParityPassesAndPrintsJson) {
  TempDir dir;
  const Result run = vkray("parity --validate --width 96 --height 96 --json --diff d.png", dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err << run.out;
  const auto j = nlohmann::json::parse(run.out);  // stdout is exactly one JSON object
  EXPECT_TRUE(j.at("pass").get<bool>());
  EXPECT_EQ(j.at("width").get<int>(), 96);
  for (const char* key : {"max_abs_diff", "mean_abs_diff", "psnr_db", "share_over_1", "share_over_2", "worst_pixel",
                          "gpu_trace_seconds", "cpu_trace_seconds"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(read_png(dir / "d.png").width, 96u);
}

TEST(CliTest, ParityPrintsReadableMetrics) {
  TempDir dir;
  const Result run = vkray("parity --validate --width 64 --height 64", dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err << run.out;
  for (const char* text : {"max |GPU - CPU|", "PSNR", "8-bit sRGB differences: > 1 on", "tolerance", "PASS"})
    EXPECT_NE(run.out.find(text), std::string::npos) << text << " missing from:\n" << run.out;
}

TEST(CliTest, ParityCatchesAPerturbedShader) {
  // A shader that renders 2% too bright must fail parity with exit code 4.
  TempDir dir;
  std::filesystem::copy(VKRAY_SHADER_DIR, dir / "shaders", std::filesystem::copy_options::recursive);
  const auto entry = dir / "shaders" / "trace.comp";
  std::ifstream in(entry);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  const std::string from = "direct_radiance(ray, stream, rays) * frame.inv_samples_per_pixel";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(), from + " * 1.02");
  std::ofstream(entry) << text;
  const Result run = vkray("parity --validate --shader-dir shaders --width 64 --height 64 --diff d.png", dir.path());
  EXPECT_EQ(run.exit_code, 4) << run.err << run.out;
  EXPECT_NE(run.out.find("FAIL"), std::string::npos) << run.out;
  EXPECT_TRUE(std::filesystem::exists(dir / "d.png"));
}

TEST(CliTest, BenchPrintsJsonForEachScene) {
  // A benchmark is not a test: this checks the command runs and reports, never how fast.
  TempDir dir, temp;
  // TMPDIR: where the write stage's PNG goes for a moment (checked below to be gone).
  const Result run = run_vkray("bench --scenes cornell,teapot --width 32 --height 32 --repeat 1 --json", dir.path(),
                               "export TMPDIR='" + temp.path().string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  ASSERT_EQ(j.size(), 2u);
  EXPECT_EQ(j[1].at("scene"), "teapot");
  EXPECT_EQ(j[1].at("triangles"), 6322);
  // A scene the shader can hold is measured compiled in, whatever the rays (the compile is not timed).
  EXPECT_EQ(j[0].at("gpu_path"), "inline");
  EXPECT_EQ(j[1].at("gpu_path"), "bvh");
  EXPECT_EQ(j[0].at("vkray_version").get<std::string>().rfind("0.1.0 (", 0), 0u);  // a report names its build
  for (const char* mode : {"primary", "primary_shadow"}) {
    EXPECT_GT(j[0].at(mode).at("gpu_mrays").get<double>(), 0.0);
    EXPECT_GT(j[0].at(mode).at("cpu_reference_mrays").get<double>(), 0.0);
    EXPECT_GE(j[1].at(mode).at("readback_ms").get<double>(), 0.0);
  }
  // Every stage of a render, each measured.
  for (const char* stage : {"load_ms", "bvh_build_ms", "upload_ms", "write_png_ms"}) EXPECT_GT(j[1].at(stage).get<double>(), 0.0) << stage;
  // The teapot's tree is better than one leaf of all 6322 triangles, and no better than a perfect
  // tree could be (at least one traversal step).
  EXPECT_GT(j[1].at("bvh_sah_cost").get<double>(), 1.0);
  EXPECT_LT(j[1].at("bvh_sah_cost").get<double>(), 100.0);
  // The PNG of the write stage is not left behind, nor anything else.
  EXPECT_TRUE(std::filesystem::is_empty(temp.path()));
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(CliTest, TileTimeoutExitsThreeAndWritesNothing) {
  // A tile of these shaders lasts about 200 ms on any device (support/slow_shaders.h): far past 1 ms.
  const SlowShaders shaders;
  TempDir dir;
  const Result run = vkray("render --validate --shader-dir " + shaders.path().string() + " " + kScenes +
                               "/teapot.json --spp 4 --tile-timeout 1 -o out.png",
                           dir.path());
  EXPECT_EQ(run.exit_code, 3) << run.err;
  EXPECT_NE(run.err.find("VK_TIMEOUT"), std::string::npos) << run.err;
  EXPECT_FALSE(has_image_files(dir.path()));
}

TEST(CliTest, AnImageLargerThanTheDevicesLargestStorageBufferRendersAndPassesParity) {
  // 4096^2 pixels of 16 bytes are 256 MiB, twice lavapipe's maxStorageBufferRange: the output holds
  // two tiles, not the image, and the tiles read back make the same image as the CPU reference.
  TempDir dir;
  const Result run = vkray("parity --validate --width 4096 --height 4096 --json", dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err << run.out;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["width"], 4096);
  EXPECT_TRUE(j["pass"].get<bool>()) << run.out;
  EXPECT_EQ(j["interior_pixels_over_1"], 0);
}

// Option values follow one rule per type (cli/flags.h): integers are decimal ("0100" is 100, never
// octal 64; "0x40" is refused), and no text value may be empty (`render ""` was the default scene).
TEST(CliTest, IntegersAreDecimal) {
  TempDir dir;
  const Result run = vkray("render --width 0100 --height 00064 --spp 010 -q -o out.png", dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  expect_png_size(dir / "out.png", 100, 64);
  for (const char* value : {"0x40", "+5", "1e2", "64px", "' 64'", "-", "--5"}) {
    const Result bad = vkray(std::string("render --width ") + value + " -o bad.png", dir.path());
    EXPECT_EQ(bad.exit_code, 2) << value;
    EXPECT_NE(bad.err.find("--width: expected a decimal integer"), std::string::npos) << bad.err;
  }
  EXPECT_EQ(vkray("bench --repeat 0x2", dir.path()).exit_code, 2);
  EXPECT_EQ(vkray("bench --repeat -2", dir.path()).exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.png"));
}

// A number out of its range, negative or past any integer type, is refused with the library's limit
// (session/options.h) and its message, the one the Python module raises as vkray.UsageError.
TEST(CliTest, NumbersOutOfRangeSayTheirLimit) {
  TempDir dir;
  const std::pair<const char*, const char*> cases[] = {
      {"render --width -5 -o bad.png", "--width: expected an integer from 1 to 16384, got -5"},
      {"render --height 16385 -o bad.png", "--height: expected an integer from 1 to 16384, got 16385"},
      {"render --spp 99999999999999999999999 -o bad.png", "--spp: expected an integer from 1 to 65536, got 99999999999999999999999"},
      {"render --seed -1 -o bad.png", "--seed: expected an integer from 0 to 4294967295, got -1"},
      {"render --seed 4294967296 -o bad.png", "--seed: expected an integer from 0 to 4294967295, got 4294967296"},
      {"render --renderer cpu --threads 1000000 -o bad.png", "--threads: expected an integer from 1 to 256, got 1000000"},
      {"parity --threads 0", "--threads: expected an integer from 1 to 256, got 0"},
      {"render --tile-timeout 0 -o bad.png", "--tile-timeout: expected an integer from 1 to 3600000, got 0"},
  };
  for (const auto& [args, message] : cases) {
    const Result bad = vkray(args, dir.path());
    EXPECT_EQ(bad.exit_code, 2) << args;
    EXPECT_NE(bad.err.find(message), std::string::npos) << bad.err;
  }
  EXPECT_EQ(vkray("render --seed 4294967295 --width 8 --height 8 -q -o max-seed.png", dir.path()).exit_code, 0);
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.png"));
}

TEST(CliTest, EmptyValuesAreRefused) {
  TempDir dir;
  for (const char* args : {"render ''", "render -o ''", "render --shader-dir '' -o x.png", "render --device '' -o x.png",
                           "parity --diff ''", "watch ''", "bench --scenes ''"}) {
    const Result run = vkray(args, dir.path());
    EXPECT_EQ(run.exit_code, 2) << args << ": " << run.err;
    EXPECT_NE(run.err.find("the value is empty"), std::string::npos) << args << ": " << run.err;
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(CliTest, AnUnknownCommandIsNamed) {
  TempDir dir;
  const Result run = vkray("rendr scene.json", dir.path());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("unknown command \"rendr\" (commands: render, merge, parity, check, watch, view, bench, devices)"), std::string::npos)
      << run.err;
}

TEST(CliTest, MessagesQuoteArgumentsPrintably) {
  TempDir dir;
  for (const char* args : {"$(printf 'x\\033[2Jy')", "render --width $(printf '\\033]0;x\\007')",
                           "render $(printf 'a\\033[31m.json')"}) {
    const Result run = vkray(args, dir.path());
    EXPECT_NE(run.exit_code, 0) << args;
    EXPECT_EQ(run.err.find('\x1b'), std::string::npos) << args << ": " << run.err;
    EXPECT_EQ(run.err.find('\x07'), std::string::npos) << args << ": " << run.err;
    EXPECT_NE(run.err.find('?'), std::string::npos) << args << ": " << run.err;
  }
}

// A reader that closes stderr early (`| head -1`) killed the render with SIGPIPE halfway.
TEST(CliTest, AClosedStderrDoesNotStopARender) {
  TempDir dir;
  // The shell waits for both ends of the pipe; its status is head's, so the image tells.
  const std::string command = "cd '" + dir.path().string() + "' && '" VKRAY_EXECUTABLE
                              "' render --width 64 --height 64 -o out.png 2>&1 | head -c 1 >/dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0);
  expect_png_size(dir / "out.png", 64, 64);
}

// Running out of resources (docs/limits.md): a clear message, exit 1, and never a partial
// output file. `ulimit -f` makes the disk "full" partway through the PNG; `ulimit -v` makes host
// memory run out for a large CPU render.
TEST(CliTest, AFullDiskFailsTheWriteAndLeavesNoFile) {
  TempDir dir;
  ASSERT_EQ(vkray("render --renderer cpu --width 512 --height 512 -q -o out.png", dir.path()).exit_code, 0);
  const Result run = run_vkray("render --renderer cpu --width 512 --height 512 -q -o out.png", dir.path(), "ulimit -f 4");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("out.png: PNG write failed: Write Error: File too large"), std::string::npos) << run.err;
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) names.push_back(entry.path().filename().string());
  EXPECT_EQ(names, std::vector<std::string>{"out.png"}) << "a temporary file was left behind";
  EXPECT_EQ(read_png(dir / "out.png").width, 512u);  // the first, complete render; not half of the second
}

TEST(CliTest, RunningOutOfHostMemoryExitsOne) {
  TempDir dir;
  const Result run =
      run_vkray("render --renderer cpu --width 16384 --height 16384 -q -o big.png", dir.path(), "ulimit -v 2000000");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("out of host memory"), std::string::npos) << run.err;
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(CliTest, VersionNamesTheCommitItWasBuiltFrom) {
  TempDir dir;
  const Result run = vkray("--version", dir.path());
  EXPECT_EQ(run.exit_code, 0);
  // A clone of the repository is where the suite runs: the commit is known.
  EXPECT_TRUE(std::regex_search(run.out, std::regex("^vkray 0\\.1\\.0 \\(commit [0-9a-f]{12}( \\+ changes)?\\)\n$")))
      << run.out;
}

TEST(CliTest, HelpDocumentsExitCodes) {
  TempDir dir;
  const Result run = vkray("render --help", dir.path());
  EXPECT_EQ(run.exit_code, 0);
  EXPECT_NE(run.out.find("Exit codes"), std::string::npos) << run.out;
}

}  // namespace
}  // namespace vkray::test
