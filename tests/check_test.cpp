// `vkray check` as a user runs it: the report of a passing and of a failing device, the command that
// reproduces a failure, the JUnit and JSON reports, and a case that cannot run. The whole suite runs
// installed in installed_check.sh; these use one or two scenes at a small size.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/run_vkray.h"
#include "support/temp_dir.h"

namespace vkray::test {
namespace {

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// A copy of the shaders in dir/shaders with `from` replaced by `to` in trace.comp.
void copy_shaders_with(const TempDir& dir, const std::string& from, const std::string& to) {
  std::filesystem::copy(VKRAY_SHADER_DIR, dir / "shaders", std::filesystem::copy_options::recursive);
  std::string text = read_text(dir / "shaders" / "trace.comp");
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(), to);
  std::ofstream(dir / "shaders" / "trace.comp") << text;
}

TEST(CheckTest, APassingDeviceGetsOneLinePerCaseAndTheJsonReport) {
  TempDir dir;
  const CommandResult text = run_vkray("check --validate --case light-on-surface --width 48 --height 48", dir.path());
  ASSERT_EQ(text.exit_code, 0) << text.err << text.out;
  for (const char* line : {"vkray check: vkray ", "driver ", "Vulkan ", "pass  light-on-surface/bvh/1spp",
                           "pass  light-on-surface/inline/1spp", "pass  light-on-surface/bvh/16spp",
                           "pass  light-on-surface/inline/16spp", "vkray check: 4 of 4 cases pass"})
    EXPECT_NE(text.out.find(line), std::string::npos) << line << " missing from:\n" << text.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "vkray-check-failures"));

  const CommandResult json = run_vkray("check --validate --case cornell --case teapot --width 32 --height 32 --json", dir.path());
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const auto j = nlohmann::json::parse(json.out);
  for (const char* key : {"vkray_version", "device", "driver", "vulkan_version", "device_index"})
    EXPECT_TRUE(j.contains(key)) << key;
  ASSERT_EQ(j["cases"].size(), 6u);  // cornell on both paths, the teapot (6320 triangles) on the BVH; 1 and 16 spp
  EXPECT_EQ(j["cases"][0]["name"], "cornell/bvh/1spp");
  EXPECT_EQ(j["cases"][5]["name"], "teapot/bvh/16spp");
  for (const auto& c : j["cases"]) {
    EXPECT_TRUE(c["pass"].get<bool>()) << c.dump();
    EXPECT_TRUE(c["metrics"].contains("interior_pixels_over_1")) << c.dump();
  }
  EXPECT_EQ(j["passed"], 6);
  EXPECT_EQ(j["failed"], 0);
}

TEST(CheckTest, AFailingDeviceExitsFourWithHeatmapsJunitAndTheCommandThatReproducesEachFailure) {
  // A shader that renders 2% too bright fails every case.
  TempDir dir;
  copy_shaders_with(dir, "vec4(sum", "vec4(sum * 1.02");
  const CommandResult run = run_vkray(
      "check --validate --shader-dir shaders --case cornell --width 48 --height 48 --junit report.xml --failures maps",
      dir.path());
  EXPECT_EQ(run.exit_code, 4) << run.err << run.out;
  EXPECT_NE(run.out.find("vkray check: 0 of 4 cases pass; 4 fail"), std::string::npos) << run.out;
  for (const char* map : {"cornell-bvh-1spp.png", "cornell-inline-1spp.png", "cornell-bvh-16spp.png", "cornell-inline-16spp.png"})
    EXPECT_TRUE(std::filesystem::exists(dir / "maps" / map)) << map;

  const std::string junit = read_text(dir / "report.xml");
  EXPECT_NE(junit.find("tests=\"4\" failures=\"4\" errors=\"0\""), std::string::npos) << junit;
  EXPECT_NE(junit.find("<testcase classname=\"vkray.check.cornell\" name=\"inline_16spp\""), std::string::npos) << junit;
  EXPECT_NE(junit.find("<failure message=\"parity tolerance does not hold: &gt; 1 step on "), std::string::npos) << junit;

  // The printed command reproduces the failure on its own: this vkray, this device, the loader's
  // environment of the run (CTest points VK_DRIVER_FILES at lavapipe), run from another folder.
  const std::string marker = "reproduce: ";
  const size_t at = run.out.find(marker);
  ASSERT_NE(at, std::string::npos) << run.out;
  const std::string command = run.out.substr(at + marker.size(), run.out.find('\n', at) - at - marker.size());
  EXPECT_NE(command.find(std::string(VKRAY_EXECUTABLE) + " parity "), std::string::npos) << command;
  EXPECT_NE(command.find("--inline-scene never --device 0 --shader-dir "), std::string::npos) << command;
  if (std::getenv("VK_DRIVER_FILES")) {
    EXPECT_EQ(command.rfind("VK_DRIVER_FILES=", 0), 0u) << command;
  }
  const TempDir elsewhere;
  const CommandResult again = run_command(command, elsewhere.path());
  EXPECT_EQ(again.exit_code, 4) << command << "\n" << again.err;
  EXPECT_NE(again.out.find("FAIL"), std::string::npos) << again.out;
}

TEST(CheckTest, ACaseThatCannotRunIsAnErrorInTheReportAndEndsTheCheck) {
  TempDir dir;
  copy_shaders_with(dir, "void main() {", "void main() { this does not compile;");
  const CommandResult run = run_vkray("check --shader-dir shaders --case cornell --width 16 --height 16 --junit report.xml",
                                      dir.path());
  EXPECT_EQ(run.exit_code, 1) << run.err;  // a shader error, as every command reports it
  EXPECT_NE(run.err.find("trace.comp"), std::string::npos) << run.err;
  const std::string junit = read_text(dir / "report.xml");
  EXPECT_NE(junit.find("errors=\"1\""), std::string::npos) << junit;
  // The case that was running: the first, whose render compiles the shaders.
  EXPECT_NE(junit.find("<testcase classname=\"vkray.check.cornell\" name=\"bvh_1spp\""), std::string::npos) << junit;
  EXPECT_NE(junit.find("<error message=\""), std::string::npos) << junit;

  // A device that cannot be opened is the report's one error.
  const CommandResult no_device = run_vkray("check --device no-such-device --junit none.xml", dir.path());
  EXPECT_EQ(no_device.exit_code, 3) << no_device.err;
  const std::string report = read_text(dir / "none.xml");
  EXPECT_NE(report.find("tests=\"1\" failures=\"0\" errors=\"1\""), std::string::npos) << report;
  EXPECT_NE(report.find("<testcase classname=\"vkray.check\" name=\"device\""), std::string::npos) << report;
  EXPECT_NE(report.find("no Vulkan device matches --device"), std::string::npos) << report;
}

TEST(CheckTest, AnUnknownCaseOrAnUnusableOutputIsRefusedBeforeAnyCase) {
  TempDir dir;
  const CommandResult run = run_vkray("check --case no-such-scene", dir.path());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--case no-such-scene: no such case; the cases are bunny,"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("light-on-surface"), std::string::npos) << run.err;

  // Where failures and the report go is checked before any case runs.
  std::ofstream(dir / "a-file") << "x";
  const CommandResult failures = run_vkray("check --case cornell --failures a-file", dir.path());
  EXPECT_EQ(failures.exit_code, 1);
  EXPECT_NE(failures.err.find("a-file: exists and is not a folder"), std::string::npos) << failures.err;
  EXPECT_EQ(failures.out, "");
  const CommandResult junit = run_vkray("check --case cornell --junit no/such/folder/r.xml", dir.path());
  EXPECT_EQ(junit.exit_code, 1);
  EXPECT_NE(junit.err.find("folder no/such/folder does not exist"), std::string::npos) << junit.err;
}

}  // namespace
}  // namespace vkray::test
