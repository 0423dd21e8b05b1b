#include "gpu/shader_compiler.h"

#include <algorithm>
#include <fstream>
#include <memory>
#include <regex>
#include <sstream>
#include <string>

#include <glslang/Include/Types.h>
#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>

#include "base/errors.h"

namespace vkray::gpu {
namespace {

// glslang's process-wide state, set up on first use and torn down at exit.
struct GlslangProcess {
  GlslangProcess() { glslang::InitializeProcess(); }
  ~GlslangProcess() { glslang::FinalizeProcess(); }
};

bool read_file(const std::filesystem::path& file, std::string& text) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) return false;
  std::ifstream in(file, std::ios::binary);
  if (!in) return false;
  std::ostringstream buffer;
  buffer << in.rdbuf();
  text = buffer.str();
  return true;
}

class Includer : public glslang::TShader::Includer {
 public:
  Includer(std::vector<std::filesystem::path> dirs, const std::vector<GeneratedInclude>& generated,
           std::vector<std::filesystem::path>& sources)
      : dirs_(std::move(dirs)), generated_(generated), sources_(sources) {}

  IncludeResult* includeLocal(const char* header, const char* includer, size_t) override {
    return find(header, std::filesystem::path(includer).parent_path());
  }
  IncludeResult* includeSystem(const char* header, const char*, size_t) override { return find(header, {}); }
  void releaseInclude(IncludeResult* result) override {
    if (result) {
      delete static_cast<std::string*>(result->userData);
      delete result;
    }
  }

 private:
  IncludeResult* find(const char* header, const std::filesystem::path& local_dir) {
    for (const auto& g : generated_)
      if (g.name == header) {
        auto text = std::make_unique<std::string>(g.text);
        auto* result = new IncludeResult(g.name + " (generated)", text->data(), text->size(), text.get());
        text.release();
        return result;
      }
    std::vector<std::filesystem::path> candidates;
    if (!local_dir.empty()) candidates.push_back(local_dir / header);
    for (const auto& dir : dirs_) candidates.push_back(dir / header);
    for (const auto& candidate : candidates) {
      auto text = std::make_unique<std::string>();
      if (!read_file(candidate, *text)) continue;
      const std::filesystem::path resolved = candidate.lexically_normal();
      if (std::find(sources_.begin(), sources_.end(), resolved) == sources_.end()) sources_.push_back(resolved);
      // headerName becomes the file name in glslang's messages for code in this file.
      auto* result = new IncludeResult(resolved.string(), text->data(), text->size(), text.get());
      text.release();
      return result;
    }
    return nullptr;  // glslang reports "Could not process include directive" at the #include line
  }

  std::vector<std::filesystem::path> dirs_;
  const std::vector<GeneratedInclude>& generated_;
  std::vector<std::filesystem::path>& sources_;
};

// glslang writes "ERROR: file:line: 'token' : message"; we write "file:line: error: 'token' : message"
// and drop its summary lines ("ERROR: 1 compilation errors.  No code generated.").
std::string format_log(const std::string& log) {
  static const std::regex located(R"(^(ERROR|WARNING): (.+):(\d+): (.*)$)");
  std::istringstream in(log);
  std::string line, out;
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_match(line, m, located)) {
      std::string message = m[4].str();
      if (message.rfind("'' : ", 0) == 0) message = message.substr(5);  // no token to quote
      while (!message.empty() && message.front() == ' ') message.erase(0, 1);
      out += m[2].str() + ":" + m[3].str() + ": " + (m[1] == "ERROR" ? "error" : "warning") + ": " + message + "\n";
    } else if (!line.empty() && line.find("compilation errors") == std::string::npos &&
               line.find("No code generated") == std::string::npos) {
      out += line + "\n";
    }
  }
  while (!out.empty() && out.back() == '\n') out.pop_back();
  return out;
}

// The descriptor type of a uniform that is not a block, from its GL type as glslang's reflection
// gives it (the values of GL_SAMPLER_BUFFER and its kin in the OpenGL headers).
std::optional<vk::DescriptorType> descriptor_type(int gl_type) {
  switch (gl_type) {
    case 0x8DC2:  // GL_SAMPLER_BUFFER
    case 0x8DD0:  // GL_INT_SAMPLER_BUFFER
    case 0x8DD8:  // GL_UNSIGNED_INT_SAMPLER_BUFFER
      return vk::DescriptorType::eUniformTexelBuffer;
    case 0x9051:  // GL_IMAGE_BUFFER
    case 0x905C:  // GL_INT_IMAGE_BUFFER
    case 0x9067:  // GL_UNSIGNED_INT_IMAGE_BUFFER
      return vk::DescriptorType::eStorageTexelBuffer;
    default:
      return std::nullopt;
  }
}

// A resource as reflected: its set (0 when the shader gives none), binding and array size.
ShaderBinding binding_of(const glslang::TObjectReflection& object, std::optional<vk::DescriptorType> type) {
  const glslang::TType& t = *object.getType();
  const uint32_t set = t.getQualifier().hasSet() ? t.getQualifier().layoutSet : 0;
  const uint32_t count = t.isArray() ? uint32_t(std::max(1, t.getCumulativeArraySize())) : 1;
  return {set, uint32_t(object.getBinding()), type, count, object.name};
}

// Every resource in a descriptor set that the linked program uses. Block members and push-constant
// blocks have no binding and are left out.
std::vector<ShaderBinding> reflect_bindings(glslang::TProgram& program) {
  program.buildReflection(EShReflectionSeparateBuffers);
  std::vector<ShaderBinding> bindings;
  for (int i = 0; i < program.getNumUniformVariables(); ++i) {
    const glslang::TObjectReflection& u = program.getUniform(i);
    if (u.getBinding() >= 0) bindings.push_back(binding_of(u, descriptor_type(u.glDefineType)));
  }
  for (int i = 0; i < program.getNumUniformBlocks(); ++i) {
    const glslang::TObjectReflection& b = program.getUniformBlock(i);
    if (b.getBinding() >= 0) bindings.push_back(binding_of(b, vk::DescriptorType::eUniformBuffer));
  }
  for (int i = 0; i < program.getNumBufferBlocks(); ++i) {
    const glslang::TObjectReflection& b = program.getBufferBlock(i);
    if (b.getBinding() >= 0) bindings.push_back(binding_of(b, vk::DescriptorType::eStorageBuffer));
  }
  return bindings;
}

}  // namespace

CompiledShader compile_compute_shader(const std::filesystem::path& entry,
                                      const std::vector<std::filesystem::path>& include_dirs,
                                      const std::vector<GeneratedInclude>& generated) {
  static GlslangProcess process;

  const std::filesystem::path entry_path = entry.lexically_normal();
  std::string text;
  if (!read_file(entry_path, text)) throw ShaderError(entry_path.string() + ": cannot read shader file");

  CompiledShader result;
  result.sources.push_back(entry_path);

  glslang::TShader shader(EShLangCompute);
  const char* strings[] = {text.c_str()};
  const int lengths[] = {static_cast<int>(text.size())};
  const std::string name = entry_path.string();
  const char* names[] = {name.c_str()};
  shader.setStringsWithLengthsAndNames(strings, lengths, names, 1);
  shader.setEnvInput(glslang::EShSourceGlsl, EShLangCompute, glslang::EShClientVulkan, 100);
  shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_2);
  shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_5);

  Includer includer(include_dirs, generated, result.sources);
  const auto messages = static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules);
  if (!shader.parse(GetDefaultResources(), 460, false, messages, includer))
    throw ShaderError(format_log(shader.getInfoLog()));

  glslang::TProgram program;
  program.addShader(&shader);
  if (!program.link(messages)) throw ShaderError(entry_path.string() + ": link error: " + format_log(program.getInfoLog()));

  glslang::SpvOptions options;
  options.validate = true;
  spv::SpvBuildLogger logger;
  glslang::GlslangToSpv(*program.getIntermediate(EShLangCompute), result.spirv, &logger, &options);
  const std::string spv_messages = logger.getAllMessages();
  if (result.spirv.empty()) throw ShaderError(entry_path.string() + ": SPIR-V generation failed: " + spv_messages);
  result.bindings = reflect_bindings(program);
  return result;
}

}  // namespace vkray::gpu
