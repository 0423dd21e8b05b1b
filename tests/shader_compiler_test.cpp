// Run-time shader compilation: includes, and errors that point at the right file and line.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "base/errors.h"
#include "gpu/shader_compiler.h"
#include "shared/types.h"
#include "support/temp_dir.h"

namespace vkray::test {
namespace {

// A copy of shaders/ that a test may break.
class ShaderCopy {
 public:
  ShaderCopy() {
    std::filesystem::copy(VKRAY_SHADER_DIR, dir_.path(), std::filesystem::copy_options::recursive);
  }
  std::filesystem::path path() const { return dir_.path(); }
  // Replaces the first occurrence of `from` in `file`; returns its 1-based line.
  int edit(const std::string& file, const std::string& from, const std::string& to) {
    std::ifstream in(dir_ / file);
    std::string text((std::istreambuf_iterator<char>(in)), {});
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    std::ofstream(dir_ / file) << text;
    return 1 + int(std::count(text.begin(), text.begin() + long(at), '\n'));
  }

 private:
  TempDir dir_;
};

std::string compile_error(const std::filesystem::path& dir) {
  try {
    gpu::compile_compute_shader(dir / "trace.comp", {dir});
  } catch (const ShaderError& e) {
    return e.what();
  }
  ADD_FAILURE() << "the shader compiled";
  return {};
}

TEST(ShaderCompilerTest, CompilesTheTracerAndListsEveryIncludedFile) {
  const std::filesystem::path dir = VKRAY_SHADER_DIR;
  const gpu::CompiledShader shader = gpu::compile_compute_shader(dir / "trace.comp", {dir});
  EXPECT_GT(shader.spirv.size(), 100u);
  EXPECT_EQ(shader.spirv[0], 0x07230203u);  // SPIR-V magic
  const char* files[] = {"trace.comp",     "shared/glsl_cpp.h", "shared/types.h",  "shared/scene_layout.h",
                         "shared/sampling.h", "camera.glsl",     "ray.glsl",        "resources.glsl",
                         "shade.glsl",      "primitives.glsl",   "intersect.glsl",  "traversal.glsl",
                         "inline_scene.glsl"};
  for (const char* file : files) {
    const auto expected = (dir / file).lexically_normal();
    EXPECT_NE(std::find(shader.sources.begin(), shader.sources.end(), expected), shader.sources.end()) << file;
  }
  EXPECT_EQ(shader.sources.size(), std::size(files));  // each once, though several are included more than once
}

TEST(ShaderCompilerTest, ReflectsTheBindingsTheShaderDeclares) {
  // What DescriptorTable::check holds against the table of what vkray binds.
  const std::filesystem::path dir = VKRAY_SHADER_DIR;
  const gpu::CompiledShader shader = gpu::compile_compute_shader(dir / "trace.comp", {dir});
  std::map<uint32_t, std::pair<std::string, vk::DescriptorType>> found;
  for (const auto& b : shader.bindings) {
    ASSERT_TRUE(b.type.has_value()) << b.name;
    EXPECT_TRUE(found.emplace(b.binding, std::pair(b.name, *b.type)).second) << "binding " << b.binding << " twice";
  }
  using D = vk::DescriptorType;
  const std::map<uint32_t, std::pair<std::string, vk::DescriptorType>> expected = {
      {VKRAY_BINDING_FRAME, {"Frame", D::eUniformBuffer}},
      {VKRAY_BINDING_PRIMITIVES, {"primitives", D::eUniformTexelBuffer}},
      {VKRAY_BINDING_NORMALS, {"normals", D::eUniformTexelBuffer}},
      {VKRAY_BINDING_NODES, {"nodes", D::eUniformTexelBuffer}},
      {VKRAY_BINDING_MATERIALS, {"materials", D::eUniformTexelBuffer}},
      {VKRAY_BINDING_LIGHTS, {"lights", D::eUniformTexelBuffer}},
      {VKRAY_BINDING_OUTPUT, {"Output", D::eStorageBuffer}},
  };
  EXPECT_EQ(found, expected);
}

TEST(ShaderCompilerTest, ErrorInAnIncludedFileNamesThatFileAndLine) {
  ShaderCopy copy;
  const int line = copy.edit("intersect.glsl", "float b = -dot(f, ray.dir);", "float b = -dot(f, ray.dir) + undefined_name;");
  const std::string message = compile_error(copy.path());
  const std::string expected = (copy.path() / "intersect.glsl").lexically_normal().string() + ":" + std::to_string(line) + ": error: ";
  EXPECT_EQ(message.rfind(expected, 0), 0u) << "expected it to start with " << expected << "\n" << message;
  EXPECT_NE(message.find("undefined_name"), std::string::npos) << message;
}

TEST(ShaderCompilerTest, ErrorInTheEntryFile) {
  ShaderCopy copy;
  const int line = copy.edit("trace.comp", "uint rays = 0u;", "uint rays = 0u");
  const std::string message = compile_error(copy.path());
  // A missing semicolon is found on the next line.
  const std::string expected = (copy.path() / "trace.comp").lexically_normal().string() + ":" + std::to_string(line + 1) + ": error: ";
  EXPECT_EQ(message.rfind(expected, 0), 0u) << message;
}

TEST(ShaderCompilerTest, MissingIncludeNamesTheIncludingLine) {
  ShaderCopy copy;
  const int line = copy.edit("shade.glsl", "#include \"traversal.glsl\"", "#include \"no_such_file.glsl\"");
  const std::string message = compile_error(copy.path());
  const std::string expected = (copy.path() / "shade.glsl").lexically_normal().string() + ":" + std::to_string(line) + ":";
  EXPECT_NE(message.find(expected), std::string::npos) << message;
  EXPECT_NE(message.find("no_such_file.glsl"), std::string::npos) << message;
}

TEST(ShaderCompilerTest, MissingEntryFile) {
  TempDir empty;
  EXPECT_THROW(gpu::compile_compute_shader(empty / "trace.comp", {empty.path()}), ShaderError);
}

}  // namespace
}  // namespace vkray::test
