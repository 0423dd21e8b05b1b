// Run-time shader compilation: includes, errors that point at the right file and line, the cache,
// and a variant's SPIR-V specialized on the host.
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <sys/stat.h>

#include <glslang/SPIRV/spirv.hpp>
#include <gtest/gtest.h>

#include "base/errors.h"
#include "gpu/pipeline.h"
#include "gpu/shader_cache.h"
#include "gpu/shader_compiler.h"
#include "gpu/specialize.h"
#include "scene/scene.h"
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
                         "inline_scene.glsl", "warp.glsl",        "emitters.glsl",   "bsdf.glsl",
                         "direct.glsl",     "path.glsl",         "aovs.glsl",       "texture.glsl",
                         "shared/first_hit_layout.h", "shared/materials.h", "instances.glsl",
                         "environment.glsl"};
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
      {VKRAY_BINDING_EMITTERS, {"emitters", D::eUniformTexelBuffer}},
      {VKRAY_BINDING_AOVS, {"AovOutput", D::eStorageBuffer}},
      {VKRAY_BINDING_TEXCOORDS, {"texcoords", D::eUniformTexelBuffer}},
      {VKRAY_BINDING_TEXTURES, {"textures", D::eUniformTexelBuffer}},
      {VKRAY_BINDING_TANGENTS, {"tangents", D::eUniformTexelBuffer}},
      {VKRAY_BINDING_COLOURS, {"colours", D::eUniformTexelBuffer}},
      {VKRAY_BINDING_INSTANCES, {"instances", D::eUniformTexelBuffer}},
      {VKRAY_BINDING_ENVIRONMENT, {"environment", D::eUniformTexelBuffer}},
      {VKRAY_BINDING_ENVIRONMENT_CDF, {"environment_cdf", D::eUniformTexelBuffer}},
  };
  EXPECT_EQ(found, expected);
}

TEST(ShaderCompilerTest, DeclaresTheSpecializationConstantsOfThePipelinesTable) {
  // The shader's constant_id declarations against gpu::kSpecConstants and the material types, which
  // the pipeline sets: the same ids, the same names, and defaults that are ShaderVariant's, read from
  // the SPIR-V itself.
  const std::filesystem::path dir = VKRAY_SHADER_DIR;
  const gpu::CompiledShader shader = gpu::compile_compute_shader(dir / "trace.comp", {dir});
  std::map<uint32_t, std::string> names;  // by result id
  std::map<uint32_t, bool> defaults;
  std::map<uint32_t, uint32_t> spec_ids;  // result id -> SpecId
  const std::vector<uint32_t>& code = shader.spirv;
  for (size_t at = 5; at < code.size();) {
    const uint32_t words = code[at] >> spv::WordCountShift, opcode = code[at] & spv::OpCodeMask;
    ASSERT_GT(words, 0u);
    ASSERT_LE(at + words, code.size());
    if (opcode == spv::OpName) names[code[at + 1]] = reinterpret_cast<const char*>(&code[at + 2]);
    if (opcode == spv::OpDecorate && code[at + 2] == spv::DecorationSpecId) spec_ids[code[at + 1]] = code[at + 3];
    if (opcode == spv::OpSpecConstantTrue || opcode == spv::OpSpecConstantFalse)
      defaults[code[at + 2]] = opcode == spv::OpSpecConstantTrue;
    at += words;
  }
  std::map<uint32_t, std::pair<std::string, bool>> declared, table;
  for (const auto& [result, id] : spec_ids) {
    ASSERT_TRUE(defaults.count(result)) << "constant_id " << id << " is not a bool";
    EXPECT_TRUE(declared.emplace(id, std::pair(names[result], defaults[result])).second) << "constant_id " << id << " twice";
  }
  const gpu::ShaderVariant defaults_on_host;
  for (const gpu::SpecConstant& row : gpu::kSpecConstants)
    table.emplace(row.id, std::pair(std::string(row.name), defaults_on_host.*row.member));
  // One more a material type, from the materials' table: SCENE_HAS_<its name in scene files>.
  for (uint32_t t = 0; t < VKRAY_MATERIAL_TYPE_COUNT; ++t)
    table.emplace(VKRAY_SPEC_MATERIALS + t, std::pair("SCENE_HAS_" + std::string(material_type_name(MaterialType(t))),
                                                      ((defaults_on_host.materials >> t) & 1u) != 0));
  EXPECT_EQ(declared, table);
}

// The functions a module names (glslang names each "name(parameter types").
std::vector<std::string> function_names(const std::vector<uint32_t>& code) {
  std::vector<uint32_t> functions;
  std::map<uint32_t, std::string> names;
  for (size_t at = 5; at < code.size();) {
    const uint32_t words = code[at] >> spv::WordCountShift, opcode = code[at] & spv::OpCodeMask;
    if (words == 0 || at + words > code.size()) break;
    if (opcode == spv::OpName) names[code[at + 1]] = reinterpret_cast<const char*>(&code[at + 2]);
    if (opcode == spv::OpFunction) functions.push_back(code[at + 2]);
    at += words;
  }
  std::vector<std::string> found;
  for (uint32_t f : functions) found.push_back(names[f].substr(0, names[f].find('(')));
  return found;
}

bool has_specialization_constants(const std::vector<uint32_t>& code) {
  for (size_t at = 5; at < code.size();) {
    const uint32_t words = code[at] >> spv::WordCountShift, opcode = code[at] & spv::OpCodeMask;
    if (words == 0 || at + words > code.size()) break;
    if (opcode == spv::OpSpecConstantTrue || opcode == spv::OpSpecConstantFalse || opcode == spv::OpSpecConstantOp ||
        (opcode == spv::OpDecorate && code[at + 2] == spv::DecorationSpecId))
      return true;
    at += words;
  }
  return false;
}

TEST(SpecializeTest, FreezesTheConstantsAndDropsTheCodeTheVariantCannotReach) {
  const std::filesystem::path dir = VKRAY_SHADER_DIR;
  const gpu::CompiledShader shader = gpu::compile_compute_shader(dir / "trace.comp", {dir});
  ASSERT_TRUE(has_specialization_constants(shader.spirv));
  const auto has = [](const std::vector<std::string>& names, const std::string& name) {
    return std::find(names.begin(), names.end(), name) != names.end();
  };
  ASSERT_TRUE(has(function_names(shader.spirv), "path_step"));
  ASSERT_TRUE(has(function_names(shader.spirv), "direct_radiance"));
  for (const bool path : {false, true}) {
    std::map<uint32_t, bool> values;
    for (const gpu::SpecConstant& row : gpu::kSpecConstants) values[row.id] = gpu::ShaderVariant().*row.member;
    values[VKRAY_SPEC_PATH] = path;
    const std::optional<std::vector<uint32_t>> code = gpu::specialize(shader.spirv, values);
    ASSERT_TRUE(code);
    EXPECT_FALSE(has_specialization_constants(*code));
    const std::vector<std::string> names = function_names(*code);
    EXPECT_EQ(has(names, "path_step"), path);
    EXPECT_EQ(has(names, "direct_radiance"), !path);
    // A variant is a fraction of the module that has every feature.
    EXPECT_LT(code->size(), shader.spirv.size() * 3 / 4) << (path ? "path" : "direct");
  }
}

TEST(SpecializeTest, DeclinesWhatIsNotSpirV) {
  EXPECT_FALSE(gpu::specialize({0x07230203u, 0x10000u, 0u, 10u, 0u, 0xdeadbeefu}, {{VKRAY_SPEC_PATH, true}}));
  EXPECT_FALSE(gpu::specialize({1u, 2u, 3u}, {}));
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

// ---- The cache of compiled shaders (gpu/shader_cache.h) -------------------------------------------

std::vector<std::filesystem::path> cache_entries(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> entries;
  if (std::filesystem::exists(dir))
    for (const auto& e : std::filesystem::directory_iterator(dir)) entries.push_back(e.path());
  return entries;
}

void expect_same(const gpu::CompiledShader& a, const gpu::CompiledShader& b) {
  EXPECT_EQ(a.spirv, b.spirv);
  EXPECT_EQ(a.sources, b.sources);
  ASSERT_EQ(a.bindings.size(), b.bindings.size());
  for (size_t i = 0; i < a.bindings.size(); ++i) {
    EXPECT_EQ(a.bindings[i].set, b.bindings[i].set);
    EXPECT_EQ(a.bindings[i].binding, b.bindings[i].binding);
    EXPECT_EQ(a.bindings[i].type, b.bindings[i].type);
    EXPECT_EQ(a.bindings[i].count, b.bindings[i].count);
    EXPECT_EQ(a.bindings[i].name, b.bindings[i].name);
  }
}

// The inode of a file: a cache hit keeps the entry (refreshing its time), a compile writes a new one
// and renames it into place.
ino_t inode(const std::filesystem::path& file) {
  struct stat st {};
  EXPECT_EQ(stat(file.c_str(), &st), 0) << file;
  return st.st_ino;
}

TEST(ShaderCacheTest, ASecondCompileIsReadBackAndADamagedEntryIsNot) {
  TempDir cache;
  ShaderCopy shaders;
  const auto entry = shaders.path() / "trace.comp";
  const gpu::CompiledShader compiled = gpu::compile_compute_shader(entry, {shaders.path()});
  expect_same(gpu::compile_compute_shader_cached(cache.path(), entry, {shaders.path()}), compiled);
  const auto entries = cache_entries(cache.path());
  ASSERT_EQ(entries.size(), 1u);
  const ino_t stored = inode(entries[0]);
  const auto old_time = std::filesystem::file_time_type::clock::now() - std::chrono::hours(1);
  std::filesystem::last_write_time(entries[0], old_time);
  expect_same(gpu::compile_compute_shader_cached(cache.path(), entry, {shaders.path()}), compiled);
  EXPECT_EQ(inode(entries[0]), stored) << "compiled again instead of read back";
  EXPECT_GT(std::filesystem::last_write_time(entries[0]), old_time) << "a hit refreshes the entry's time";
  // One byte of the stored SPIR-V changed: the entry is refused and the shader compiled again,
  // never handed to the driver.
  {
    std::fstream file(entries[0], std::ios::in | std::ios::out | std::ios::binary);
    file.seekp(-1, std::ios::end);
    file.put(char(0x5a));
  }
  expect_same(gpu::compile_compute_shader_cached(cache.path(), entry, {shaders.path()}), compiled);
  EXPECT_NE(inode(entries[0]), stored);
}

TEST(ShaderCacheTest, AnEditedIncludeOrANewFileIsCompiledAgain) {
  TempDir cache;
  ShaderCopy shaders;
  const auto entry = shaders.path() / "trace.comp";
  const gpu::CompiledShader before = gpu::compile_compute_shader_cached(cache.path(), entry, {shaders.path()});
  shaders.edit("warp.glsl", "const float PI = 3.14159265358979;", "const float PI = 3.0;");
  const gpu::CompiledShader after = gpu::compile_compute_shader_cached(cache.path(), entry, {shaders.path()});
  EXPECT_NE(after.spirv, before.spirv);
  expect_same(after, gpu::compile_compute_shader(entry, {shaders.path()}));
  EXPECT_EQ(cache_entries(cache.path()).size(), 2u);
  // A file no #include names yet may shadow one later (a search finds it first): a new key too.
  std::ofstream(shaders.path() / "shared" / "unused.h") << "// nothing\n";
  gpu::compile_compute_shader_cached(cache.path(), entry, {shaders.path()});
  EXPECT_EQ(cache_entries(cache.path()).size(), 3u);
}

TEST(ShaderCacheTest, ACacheKeptAmongTheShadersStillHits) {
  ShaderCopy shaders;
  const auto cache = shaders.path() / "cache";  // its own entries must not change the key
  const auto entry = shaders.path() / "trace.comp";
  gpu::compile_compute_shader_cached(cache, entry, {shaders.path()});
  const auto entries = cache_entries(cache);
  ASSERT_EQ(entries.size(), 1u);
  const ino_t stored = inode(entries[0]);
  gpu::compile_compute_shader_cached(cache, entry, {shaders.path()});
  EXPECT_EQ(cache_entries(cache).size(), 1u);
  EXPECT_EQ(inode(entries[0]), stored);
}

TEST(ShaderCacheTest, ACorruptOrUnwritableCacheOnlyMeansCompiling) {
  TempDir cache;
  ShaderCopy shaders;
  const auto entry = shaders.path() / "trace.comp";
  const gpu::CompiledShader compiled = gpu::compile_compute_shader(entry, {shaders.path()});
  gpu::compile_compute_shader_cached(cache.path(), entry, {shaders.path()});
  const auto entries = cache_entries(cache.path());
  ASSERT_EQ(entries.size(), 1u);
  for (const std::string& garbage : {std::string(), std::string("VKRAYSC1"), std::string(5000, '\xff')}) {
    std::ofstream(entries[0], std::ios::binary | std::ios::trunc) << garbage;
    expect_same(gpu::compile_compute_shader_cached(cache.path(), entry, {shaders.path()}), compiled);
  }
  // A cache "folder" that is a file: nothing can be stored, the shader still compiles.
  const auto not_a_folder = cache.path() / "file";
  std::ofstream(not_a_folder) << "x";
  expect_same(gpu::compile_compute_shader_cached(not_a_folder, entry, {shaders.path()}), compiled);
  expect_same(gpu::compile_compute_shader_cached(not_a_folder, entry, {shaders.path()}), compiled);
}

TEST(ShaderCacheTest, ErrorsAreNeverCached) {
  TempDir cache;
  ShaderCopy shaders;
  shaders.edit("warp.glsl", "const float PI", "const floot PI");
  const auto entry = shaders.path() / "trace.comp";
  for (int i = 0; i < 2; ++i) EXPECT_THROW(gpu::compile_compute_shader_cached(cache.path(), entry, {shaders.path()}), ShaderError);
  EXPECT_TRUE(cache_entries(cache.path()).empty());
}

// Sets an environment variable for the scope (nullptr: unset), restoring it after.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value) setenv(name, value, 1); else unsetenv(name);
  }
  ~ScopedEnv() {
    if (old_) setenv(name_, old_->c_str(), 1); else unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

TEST(ShaderCacheTest, TheFolderComesFromTheEnvironment) {
  {
    ScopedEnv off("VKRAY_SHADER_CACHE", "off");
    EXPECT_FALSE(gpu::shader_cache_dir());
  }
  {
    ScopedEnv empty("VKRAY_SHADER_CACHE", "");
    EXPECT_FALSE(gpu::shader_cache_dir());
  }
  {
    ScopedEnv set("VKRAY_SHADER_CACHE", "/somewhere/cache");
    EXPECT_EQ(gpu::shader_cache_dir(), std::filesystem::path("/somewhere/cache"));
  }
  ScopedEnv unset("VKRAY_SHADER_CACHE", nullptr);
  {
    ScopedEnv xdg("XDG_CACHE_HOME", "/xdg");
    EXPECT_EQ(gpu::shader_cache_dir(), std::filesystem::path("/xdg/vkray/shaders"));
  }
  ScopedEnv no_xdg("XDG_CACHE_HOME", nullptr);
  {
    ScopedEnv home("HOME", "/home/student");
    EXPECT_EQ(gpu::shader_cache_dir(), std::filesystem::path("/home/student/.cache/vkray/shaders"));
  }
  ScopedEnv no_home("HOME", nullptr);
  EXPECT_FALSE(gpu::shader_cache_dir());
}

}  // namespace
}  // namespace vkray::test
