#include "gpu/shader_compiler.h"

#include <algorithm>
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

// glslang writes "ERROR: file:line: 'token' : message"; we write "file:line: error: 'token' : message"
// and drop its summary lines ("ERROR: 1 compilation errors.  No code generated.").
std::string format_log(const std::string& log) {
  static const std::regex located(R"(^(ERROR|WARNING): (.+):(\d+): (.*)$)");
  // The include resolver's errors name the #include already (gpu/shader_includes.h); glslang wraps them.
  static const std::regex include_error(R"(^'#include' : (#include .*) for header name: .*$)");
  std::istringstream in(log);
  std::string line, out;
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_match(line, m, located)) {
      std::string message = m[4].str();
      if (std::smatch inner; std::regex_match(message, inner, include_error)) message = inner[1].str();
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
  const InputFile input = read_shader_file(entry_path);
  if (!input.error.empty()) throw ShaderError(entry_path.string() + ": " + input.error);
  const std::string& text = input.text;

  CompiledShader result;

  glslang::TShader shader(EShLangCompute);
  const char* strings[] = {text.c_str()};
  const int lengths[] = {static_cast<int>(text.size())};
  const std::string name = entry_path.string();
  const char* names[] = {name.c_str()};
  shader.setStringsWithLengthsAndNames(strings, lengths, names, 1);
  shader.setEnvInput(glslang::EShSourceGlsl, EShLangCompute, glslang::EShClientVulkan, 100);
  shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_2);
  shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_5);

  ShaderIncludes includes(entry_path, include_dirs, generated);
  const auto messages = static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules);
  if (!shader.parse(GetDefaultResources(), 460, false, messages, includes))
    throw ShaderError(format_log(shader.getInfoLog()));

  result.sources = includes.sources();

  glslang::TProgram program;
  program.addShader(&shader);
  if (!program.link(messages)) throw ShaderError(entry_path.string() + ": link error: " + format_log(program.getInfoLog()));

  // No SPIRV-Tools validation here: glslang would only log what it found (the SPIR-V stands), and it
  // costs more than the rest of the compile (about 0.17 s of 0.28 s for trace.comp); the validation
  // layer checks every module vkray creates under --validate, as the tests run.
  glslang::SpvOptions options;
  options.validate = false;
  spv::SpvBuildLogger logger;
  glslang::GlslangToSpv(*program.getIntermediate(EShLangCompute), result.spirv, &logger, &options);
  const std::string spv_messages = logger.getAllMessages();
  if (result.spirv.empty()) throw ShaderError(entry_path.string() + ": SPIR-V generation failed: " + spv_messages);
  result.bindings = reflect_bindings(program);
  return result;
}

}  // namespace vkray::gpu
