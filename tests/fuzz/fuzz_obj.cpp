// libFuzzer target: Wavefront OBJ meshes (vkray's own reader, host/mesh/obj.h).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "base/errors.h"
#include "mesh/load.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    vkray::parse_mesh(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.obj");
  } catch (const vkray::InputError&) {
  }
  return 0;
}
