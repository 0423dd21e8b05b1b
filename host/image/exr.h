// OpenEXR files (through the OpenEXR library): the image as R, G, B, and the first-hit passes as
// named layers, the channel names other tools expect (docs/rendering.md): albedo.R/G/B,
// normal.X/Y/Z, position.X/Y/Z, depth.Z, object.id.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "image/aovs.h"
#include "image/image.h"
#include "image/region.h"

namespace vkray {

struct ExrContent {
  // 32-bit float channels; false: 16-bit half floats for the image, albedo and normal. position and
  // depth are always 32-bit (half floats would round a far depth to infinity, the miss marker), and
  // so is object.id (every id below 2^24 exact).
  bool full_float = false;
  std::vector<Aov> passes;  // the layers written after R, G, B, in this order
};

// Where an image lies in a larger one, for a part of a render (image/part.h): the pixels are `region`
// (the EXR data window) of a full_width x full_height display window, and `part_record` is the
// string attribute "vkray.part".
struct ExrWindow {
  uint32_t full_width = 0, full_height = 0;
  PixelRegion region;
  std::string part_record;
};

// Writes `image` and the `content.passes` of `aovs` (which must then be given, of the same size),
// ZIP-compressed scan lines, top row first; with `window`, as that part of a larger image. Like
// write_image, under a temporary name renamed into place. Throws OutputError.
void write_exr(const std::filesystem::path& file, const Image& image, const Aovs* aovs, const ExrContent& content,
               const ExrWindow* window = nullptr);

struct ExrFile {
  Image image;  // the data window's pixels
  Aovs aovs;  // the passes the file has; the others keep Aovs' defaults
  ExrContent content;  // full_float: whether R is 32-bit
  // The display window's size and the data window within it (when both lie in the first quadrant;
  // zero otherwise), and the "vkray.part" attribute, as written.
  ExrWindow window;
};

// Reads a file written by write_exr (or any scan-line or tiled EXR with R, G, B). Throws InputError
// naming the file.
ExrFile read_exr(const std::filesystem::path& file);

}  // namespace vkray
