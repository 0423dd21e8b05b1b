// libFuzzer target: PLY meshes, ASCII and binary (host/mesh/ply.cpp).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "base/errors.h"
#include "load/mesh_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    vkray::parse_mesh(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.ply");
  } catch (const vkray::InputError&) {
  }
  return 0;
}
