// The bad-input corpus (tests/bad-inputs/expectations.txt): every malformed or hostile scene or
// mesh ends in exit code 1 (or 2), one line on stderr that names the file and the key, line or
// element, and no output file, the same on both renderers. Odd but valid inputs (tests/odd-inputs/)
// render.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/run_vkray.h"
#include "support/temp_dir.h"

namespace vkray::test {
namespace {

const std::filesystem::path kCorpus = std::filesystem::path(VKRAY_TEST_DIR) / "bad-inputs";

struct Case {
  std::string file;
  int exit_code;
  std::string expected;
};
void PrintTo(const Case& c, std::ostream* os) { *os << c.file; }

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(' '), e = s.find_last_not_of(' ');
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

std::vector<Case> cases() {
  std::vector<Case> result;
  std::ifstream in(kCorpus / "expectations.txt");
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    const auto a = line.find('|'), b = line.find('|', a + 1);
    result.push_back({trim(line.substr(0, a)), std::stoi(line.substr(a + 1, b - a - 1)), trim(line.substr(b + 1))});
  }
  return result;
}

class CorpusTest : public ::testing::TestWithParam<Case> {};

TEST_P(CorpusTest, FailsCleanlyNamingWhatIsWrong) {
  const Case& c = GetParam();
  TempDir out;
  const CommandResult run = run_vkray("render '" + c.file + "' -q -o '" + (out / "out.png").string() + "'", kCorpus);
  EXPECT_EQ(run.exit_code, c.exit_code) << run.err;
  std::vector<std::string> lines;
  std::istringstream err(run.err);
  for (std::string line; std::getline(err, line);)
    if (!line.empty()) lines.push_back(line);
  ASSERT_EQ(lines.size(), 1u) << "expected one line, got:\n" << run.err;
  EXPECT_NE(lines[0].find(c.file), std::string::npos) << "the message must name the file: " << lines[0];
  EXPECT_NE(lines[0].find(c.expected), std::string::npos) << "expected \"" << c.expected << "\" in: " << lines[0];
  EXPECT_TRUE(std::filesystem::is_empty(out.path())) << "a failed render left a file behind";
  // Both renderers take the same scenes: the CPU reference refuses this one with the same message.
  const CommandResult cpu =
      run_vkray("render --renderer cpu '" + c.file + "' -q -o '" + (out / "out.png").string() + "'", kCorpus);
  EXPECT_EQ(cpu.exit_code, run.exit_code);
  EXPECT_EQ(cpu.err, run.err);
  EXPECT_TRUE(std::filesystem::is_empty(out.path())) << "a failed CPU render left a file behind";
}

INSTANTIATE_TEST_SUITE_P(BadInputs, CorpusTest, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& param) {
                           std::string name = param.param.file;
                           for (char& ch : name)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return name;
                         });

TEST(CorpusSizeTest, AtLeastFortyInputs) { EXPECT_GE(cases().size(), 40u); }

struct OddCase {
  std::string file;
  std::string warning;  // empty: none expected
};

class OddInputTest : public ::testing::TestWithParam<OddCase> {};

TEST_P(OddInputTest, RendersWithAWarningWhereOneHelps) {
  const OddCase& c = GetParam();
  TempDir out;
  const CommandResult run = run_vkray("render --renderer cpu --width 16 --height 16 -q '" + c.file + "' -o '" +
                                          (out / "out.png").string() + "'",
                                      std::filesystem::path(VKRAY_TEST_DIR) / "odd-inputs");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(std::filesystem::exists(out / "out.png"));
  if (c.warning.empty()) {
    EXPECT_EQ(run.err.find("warning"), std::string::npos) << run.err;
  } else {
    EXPECT_NE(run.err.find(c.warning), std::string::npos) << run.err;
  }
}

INSTANTIATE_TEST_SUITE_P(OddInputs, OddInputTest,
                         ::testing::Values(OddCase{"unknown-keys.json", "/camera/fov_typo: unknown key"},
                                           OddCase{"empty-scene.json", ""},
                                           OddCase{"no-lights.json", "no lights, no emission and no ambient"}),
                         [](const ::testing::TestParamInfo<OddCase>& param) {
                           return std::string(param.param.file == "unknown-keys.json" ? "UnknownKeys"
                                              : param.param.file == "empty-scene.json" ? "EmptyScene"
                                                                                       : "NoLights");
                         });

}  // namespace
}  // namespace vkray::test
