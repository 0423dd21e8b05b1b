// libFuzzer target: scene files. Any input must end in a Scene or an InputError; anything else (a
// crash, a sanitizer report, another exception) is a bug.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "base/errors.h"
#include "load/scene_loader.h"
#include "scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    vkray::parse_scene(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz/scene.json");
  } catch (const vkray::InputError&) {
  }
  return 0;
}
