// A file's extension as vkray compares it: lowered, with its dot (".PNG" and ".png" are one type).
#pragma once

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>

namespace vkray {

inline std::string lower_extension(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

// Whether a file name is a glTF file's (.gltf or .glb, any case).
inline bool is_gltf_path(const std::filesystem::path& file) {
  const std::string ext = lower_extension(file);
  return ext == ".gltf" || ext == ".glb";
}

}  // namespace vkray
