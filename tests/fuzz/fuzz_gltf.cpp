// libFuzzer target: glTF 2.0 files, .gltf or .glb (host/gltf/gltf.h): vkray's checks, tinygltf's
// parser (compiled in, so instrumented) and the PNG and JPEG decoding of the pictures materials use.
// Files outside the input are never read, and a file may place at most 2^20 triangles.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "base/errors.h"
#include "gltf/gltf.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  vkray::GltfLimits limits;
  limits.read_files = false;
  limits.max_triangles = size_t(1) << 20;
  try {
    vkray::parse_gltf(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.glb", limits);
  } catch (const vkray::InputError&) {
  }
  return 0;
}
