// OpenEXR files (through the OpenEXR library): the image as R, G, B, and the first-hit passes as
// named layers, the channel names other tools expect (docs/rendering.md): albedo.R/G/B,
// normal.X/Y/Z, position.X/Y/Z, depth.Z, object.id. write_exr is in exr_write.cpp, read_exr in
// exr_read.cpp (after exr_header.h has checked the header against the file); the channel names and
// the hash of the pixels as stored, which both use, in exr_channels.h.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "image/aovs.h"
#include "image/display.h"
#include "image/image.h"
#include "image/region.h"

namespace vkray {

// What a render's image file holds besides the pixels: for an EXR file, the precision and the
// first-hit passes; for a PNG file, the display transform (image/display.h).
struct OutputContent {
  // EXR: 32-bit float channels; false: 16-bit half floats for the image, albedo and normal. position and
  // depth are always 32-bit (half floats would round a far depth to infinity, the miss marker), and
  // so is object.id (every id below 2^24 exact).
  bool full_float = false;
  std::vector<Aov> passes;  // EXR: the layers written after R, G, B, in this order
  DisplayTransform display;  // PNG: exposure and tone mapper; EXR and PFM hold linear radiance
};

// Where an image lies in a larger one, as read_exr finds it in a file: the pixels are `region` (the
// EXR data window) of a full_width x full_height display window, and `part_record` is the string
// attribute "vkray.part" (image/part.h).
struct ExrWindow {
  uint32_t full_width = 0, full_height = 0;
  PixelRegion region;
  std::string part_record;
};

// What write_exr writes of a part of a render: its window, and its record, made by `record` from
// the hash of the pixels as the file stores them (ExrFile::pixels_hash), so that the record can
// vouch for them.
struct ExrPartHeader {
  uint32_t full_width = 0, full_height = 0;
  PixelRegion region;
  std::function<std::string(const std::string& pixels_hash)> record;
};

// Writes `image` and the `content.passes` of `aovs` (which must then be given, of the same size),
// ZIP-compressed scan lines, top row first; with `part`, as that part of a larger image. Like
// write_image, under a temporary name renamed into place. Throws OutputError, LimitError.
void write_exr(const std::filesystem::path& file, const Image& image, const Aovs* aovs, const OutputContent& content,
               const ExrPartHeader* part = nullptr);

struct ExrFile {
  Image image;  // the data window's pixels
  Aovs aovs;  // the passes the file has; the others keep Aovs' defaults
  OutputContent content;  // full_float: whether R is 32-bit
  // The display window's size and the data window within it (when both lie in the first quadrant;
  // zero otherwise), and the "vkray.part" attribute, as written.
  ExrWindow window;
  // The hash (base/hash.h) of the pixels as the file stores them: the data window's size, then the
  // channels vkray reads (R, G, B and the passes' layers), each named with its type, in the channel
  // list's order, and their values row by row, top first, in the file's own types.
  std::string pixels_hash;
};

// Reads a single-part, flat (not deep) scan-line or tiled EXR with R, G, B, such as write_exr
// writes. Every claim of the header is checked against the file before anything is allocated for
// it: each attribute's size, a preview image's, the data window (at most kMaxImageSide on a side),
// the channel list (at most kMaxExrChannels, the ones read not subsampled) and the chunk offset
// table (the file holds it, and every offset in it lies within the file). Throws InputError naming
// the file, LimitError when pixels the file holds do not fit in memory, Cancelled.
ExrFile read_exr(const std::filesystem::path& file);

// The most channels a file read_exr reads may have (vkray writes at most 14): OpenEXR's buffers for
// a block of scan lines grow with them.
constexpr uint32_t kMaxExrChannels = 64;

}  // namespace vkray
