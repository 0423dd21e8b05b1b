// A shader's #include directives: cycles, deep chains, guarded headers included again, and files
// that are not regular files. No device needed: these only compile.
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "base/errors.h"
#include "gpu/shader_compiler.h"
#include "support/temp_dir.h"

namespace vkray::test {
namespace {

// "f7.glsl"
std::string numbered(int i) {
  std::string name = "f";
  name += std::to_string(i);
  return name + ".glsl";
}

const std::string kMain = "#version 460\n#extension GL_GOOGLE_include_directive : require\nlayout(local_size_x = 1) in;\n";

class ShaderIncludesTest : public ::testing::Test {
 protected:
  void write(const std::map<std::string, std::string>& files) {
    for (const auto& [name, text] : files) std::ofstream(dir_ / name, std::ios::binary) << text;
  }
  std::string file(const std::string& name) const { return (dir_ / name).lexically_normal().string(); }

  // The error compiling main.comp, which must start with "file:line: error: ".
  std::string error(const std::string& file_and_line) {
    try {
      gpu::compile_compute_shader(dir_ / "main.comp", {dir_.path()});
      ADD_FAILURE() << "the shader compiled";
    } catch (const ShaderError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind(file_and_line + ": error: ", 0), 0u) << message;
      return message;
    }
    return {};
  }

  TempDir dir_;
};

TEST_F(ShaderIncludesTest, AnIncludedFileWhoseConditionalsDoNotBalanceIsRefused) {
  // glslang's preprocessor crashed on an #else in one file closing an #if of another (a fuzzer's
  // find); each included file must balance its own.
  write({{"main.comp", kMain + "#ifndef X\n#include \"else.glsl\"\n#endif\nvoid main() {}\n"},
         {"else.glsl", "// the other half\n#else\n"}});
  std::string message = error(file("main.comp") + ":5");
  EXPECT_NE(message.find(file("else.glsl") + ", line 2: #else with no #if before it in this file"), std::string::npos) << message;
  write({{"main.comp", kMain + "#include \"open.glsl\"\n#endif\nvoid main() {}\n"},
         {"open.glsl", "#ifdef Y\nfloat y;\n/* #endif in a comment\n#endif */\n"}});
  message = error(file("main.comp") + ":4");
  EXPECT_NE(message.find(file("open.glsl") + ", line 1: an #if with no #endif in this file"), std::string::npos) << message;
  // Balanced, with directives in comments and an #elif, it compiles.
  write({{"main.comp", kMain + "#include \"ok.glsl\"\nvoid main() {}\n"},
         {"ok.glsl", "#if 0\n#elif 1\nfloat z; // #endif\n#else\n#endif\n/*\n#if 1\n*/\n"}});
  EXPECT_NO_THROW(gpu::compile_compute_shader(dir_ / "main.comp", {dir_.path()}));
}

TEST_F(ShaderIncludesTest, ACycleIsAnErrorAtTheIncludeThatClosesIt) {
  write({{"main.comp", kMain + "#include \"a.glsl\"\nvoid main() {}\n"},
         {"a.glsl", "// a\n\n#include \"b.glsl\"\n"},
         {"b.glsl", "#include \"a.glsl\"\n"}});
  const std::string message = error(file("b.glsl") + ":1");
  EXPECT_NE(message.find("#include cycle: main.comp -> a.glsl -> b.glsl -> a.glsl"), std::string::npos) << message;
  EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 0) << message;
}

TEST_F(ShaderIncludesTest, AFileIncludingItselfIsACycle) {
  write({{"main.comp", kMain + "#include \"a.glsl\"\nvoid main() {}\n"}, {"a.glsl", "\n\n#include <a.glsl>\n"}});
  const std::string message = error(file("a.glsl") + ":3");
  EXPECT_NE(message.find("#include cycle: main.comp -> a.glsl -> a.glsl"), std::string::npos) << message;
  write({{"main.comp", kMain + "#include \"main.comp\"\nvoid main() {}\n"}});
  EXPECT_NE(error(file("main.comp") + ":4").find("#include cycle: main.comp -> main.comp"), std::string::npos);
}

TEST_F(ShaderIncludesTest, GuardedHeadersMayBeIncludedAgainAndInACycle) {
  // A diamond (main -> left, right -> common) and a guarded pair that include each other.
  write({{"main.comp", kMain + "#include \"left.glsl\"\n#include \"right.glsl\"\n#include \"a.glsl\"\n"
                               "void main() { uint x = common_value + A + B; }\n"},
         {"left.glsl", "#include \"common.glsl\"\n"},
         {"right.glsl", "#include \"common.glsl\"\n"},
         {"common.glsl", "/* guarded */\n#ifndef COMMON_GLSL\n#define COMMON_GLSL\nconst uint common_value = 1u;\n#endif\n"},
         {"a.glsl", "#ifndef A_GLSL\n  #  define A_GLSL\n#include \"b.glsl\"\nconst uint A = B;\n#endif\n"},
         {"b.glsl", "// b\n#ifndef B_GLSL // the guard\n#define B_GLSL\n#include \"a.glsl\"\nconst uint B = 2u;\n#endif\n"}});
  const gpu::CompiledShader shader = gpu::compile_compute_shader(dir_ / "main.comp", {dir_.path()});
  EXPECT_EQ(shader.sources.size(), 6u);
}

TEST_F(ShaderIncludesTest, AChainDeeperThan32IsAnError) {
  // main -> f1 -> ... -> fN: 32 levels compile, 33 do not.
  const auto chain = [&](int depth) {
    std::filesystem::remove_all(dir_.path());
    std::filesystem::create_directories(dir_.path());
    write({{"main.comp", kMain + "#include \"f1.glsl\"\nvoid main() {}\n"}});
    for (int i = 1; i <= depth; ++i)
      write({{numbered(i), i == depth ? "\n" : "#include \"" + numbered(i + 1) + "\"\n"}});
  };
  chain(32);
  EXPECT_EQ(gpu::compile_compute_shader(dir_ / "main.comp", {dir_.path()}).sources.size(), 33u);
  chain(33);
  EXPECT_NE(error(file("f32.glsl") + ":1").find("#include nested more than 32 deep: main.comp -> f1.glsl -> f2.glsl"),
            std::string::npos);
}

TEST_F(ShaderIncludesTest, IncludesThatMultiplyAreCutOff) {
  // Each of 24 files includes the next twice: 2^24 includes, not a cycle and not too deep.
  write({{"main.comp", kMain + "#include \"f1.glsl\"\nvoid main() {}\n"}, {"f24.glsl", "\n"}});
  for (int i = 1; i < 24; ++i) {
    const std::string next = "#include \"" + numbered(i + 1) + "\"\n";
    write({{numbered(i), next + next}});
  }
  EXPECT_NE(error(file("f23.glsl") + ":2").find("the shader includes more than 4096 files"), std::string::npos);
}

TEST_F(ShaderIncludesTest, AnIncludeThatIsNotARegularFileIsAnErrorNotAHang) {
  ASSERT_EQ(mkfifo((dir_ / "pipe.glsl").c_str(), 0600), 0);
  write({{"main.comp", kMain + "#include \"pipe.glsl\"\nvoid main() {}\n"}});
  EXPECT_NE(error(file("main.comp") + ":4").find("is a FIFO"), std::string::npos);
  write({{"main.comp", kMain + "\n#include \"/dev/zero\"\nvoid main() {}\n"}});
  EXPECT_NE(error(file("main.comp") + ":5").find("is a character device"), std::string::npos);
  write({{"main.comp", kMain + "#include \"big.glsl\"\nvoid main() {}\n"}, {"big.glsl", ""}});
  std::filesystem::resize_file(dir_ / "big.glsl", 5 << 20);  // sparse: nothing is written
  EXPECT_NE(error(file("main.comp") + ":4").find("at most 4 MiB"), std::string::npos);
}

TEST_F(ShaderIncludesTest, TheEntryFileIsReadWithTheSameChecks) {
  ASSERT_EQ(mkfifo((dir_ / "main.comp").c_str(), 0600), 0);
  try {
    gpu::compile_compute_shader(dir_ / "main.comp", {dir_.path()});
    ADD_FAILURE() << "the shader compiled";
  } catch (const ShaderError& e) {
    EXPECT_EQ(std::string(e.what()), file("main.comp") + ": is a FIFO (named pipe), not a regular file");
  }
}

}  // namespace
}  // namespace vkray::test
