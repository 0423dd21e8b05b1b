// Reading an input file (a scene, a mesh, a shader) whole, with the checks every reader needs: only
// a regular file (a FIFO would block and /dev/zero never ends), at most a given size, and a Ctrl-C
// honoured while reading.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace vkray {

// The largest files vkray reads; docs/limits.md.
constexpr uint64_t kMaxSceneFileBytes = uint64_t(64) << 20;
constexpr uint64_t kMaxMeshFileBytes = uint64_t(4) << 30;
constexpr uint64_t kMaxShaderFileBytes = uint64_t(4) << 20;
constexpr uint64_t kMaxPictureFileBytes = uint64_t(1) << 30;  // a texture's PNG or JPEG file
constexpr uint64_t kMaxGltfFileBytes = uint64_t(2) << 30;     // a .gltf, .glb or .bin file (tinygltf counts in 32 bits)

struct InputFile {
  std::string text;   // the contents, when error is empty
  std::string error;  // why it could not be read: "not found", "is a FIFO, not a regular file", ...
};

// Never throws for the file's sake (the caller wraps `error` in its own kind of error); throws
// Cancelled on an interrupt request and LimitError when host memory runs out.
InputFile read_input_file(const std::filesystem::path& file, uint64_t max_bytes);

}  // namespace vkray
