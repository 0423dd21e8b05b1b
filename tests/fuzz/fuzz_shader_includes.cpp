// libFuzzer target: a shader's #include directives (gpu/shader_includes.h) through glslang's
// preprocessor, on a set of files decoded from the input, so that the fuzzer can make cycles, deep
// chains, missing files, odd names and files that cannot be read. The input is split-file text:
//   text of main.comp
//   //--- name       a file that "#include "name"" finds (name relative to the shader folder)
//   //+++ name       generated code served for "#include "name""
//   //!!! name       a file that cannot be read (as a FIFO would be refused)
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>

#include "gpu/shader_includes.h"

namespace {

const std::filesystem::path kFolder = "/shaders";

struct Files {
  std::string entry;
  std::map<std::filesystem::path, vkray::InputFile> files;  // by lexically normal path
  std::vector<vkray::gpu::GeneratedInclude> generated;
};

Files decode(std::string_view data) {
  Files result;
  std::string* text = &result.entry;
  while (!data.empty()) {
    const size_t end = std::min(data.find('\n'), data.size());
    const std::string_view line = data.substr(0, end);
    data.remove_prefix(std::min(end + 1, data.size()));
    const std::string_view marker = line.substr(0, 6);
    if (marker == "//--- " || marker == "//!!! ") {
      vkray::InputFile& file = result.files[(kFolder / std::string(line.substr(6))).lexically_normal()];
      if (marker == "//!!! ") file.error = "is a FIFO (named pipe), not a regular file";
      text = &file.text;
    } else if (marker == "//+++ ") {
      result.generated.push_back({std::string(line.substr(6)), {}});
      text = &result.generated.back().text;
    } else {
      text->append(line).append("\n");
    }
  }
  return result;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool initialized = glslang::InitializeProcess();
  (void)initialized;
  const Files files = decode(std::string_view(reinterpret_cast<const char*>(data), size));
  const auto read = [&](const std::filesystem::path& path) {
    const auto file = files.files.find(path.lexically_normal());
    return file == files.files.end() ? vkray::InputFile{{}, "not found"} : file->second;
  };
  const std::filesystem::path entry = kFolder / "main.comp";
  vkray::gpu::ShaderIncludes includes(entry, {kFolder}, files.generated, read);

  glslang::TShader shader(EShLangCompute);
  const char* strings[] = {files.entry.c_str()};
  const int lengths[] = {static_cast<int>(files.entry.size())};
  const std::string name = entry.string();
  const char* names[] = {name.c_str()};
  shader.setStringsWithLengthsAndNames(strings, lengths, names, 1);
  shader.setEnvInput(glslang::EShSourceGlsl, EShLangCompute, glslang::EShClientVulkan, 100);
  shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_2);
  shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_5);
  std::string preprocessed;
  shader.preprocess(GetDefaultResources(), 460, ENoProfile, false, false,
                    static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules), &preprocessed, includes);

  // Every source is the entry or a file that exists, and none is listed twice.
  std::vector<std::filesystem::path> sources = includes.sources();
  if (sources.empty() || sources[0] != entry) __builtin_trap();
  for (size_t i = 1; i < sources.size(); ++i)
    if (!files.files.count(sources[i]) || !files.files.at(sources[i]).error.empty()) __builtin_trap();
  std::sort(sources.begin(), sources.end());
  if (std::adjacent_find(sources.begin(), sources.end()) != sources.end()) __builtin_trap();
  return 0;
}
