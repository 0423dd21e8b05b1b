// libFuzzer target: Wavefront OBJ meshes (vkray's own reader, host/mesh/obj.h), and the same bytes
// as a material library (host/mesh/mtl.h): the two share a line syntax, so each seeds the other.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "base/errors.h"
#include "load/mesh_file.h"
#include "mesh/mtl.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    vkray::parse_mesh(text, "fuzz.obj");
  } catch (const vkray::InputError&) {
  }
  try {
    vkray::parse_mtl(text, "fuzz.mtl");
  } catch (const vkray::InputError&) {
  }
  return 0;
}
