// The channels vkray names in an EXR file and the hash of their values as the file stores them: one
// definition for the writer (exr_write.cpp), the header check (exr_header.cpp) and the reader
// (exr_read.cpp), so that a layer's name, the choice of channels read and the bytes hashed cannot
// differ between the file written and the file read back.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfPixelType.h>

#include "base/hash.h"
#include "image/aovs.h"

namespace vkray {

// A layer's channels: their names after the layer's.
struct ExrLayer {
  const char* name;       // "" for the image's R, G, B
  const char* suffixes[3];
  int channels;
};

ExrLayer exr_layer_of(Aov pass);
// "albedo.R", or "R" for the image's layer.
std::string exr_channel_name(const ExrLayer& layer, int c);
size_t exr_bytes_of(Imf::PixelType type);

// The passes a file has: those whose layer's first channel it has.
std::vector<Aov> exr_passes_in(const Imf::ChannelList& channels);
// The channels read_exr reads (R, G, B, and the layers of the passes it has), in the channel list's
// order.
std::vector<std::string> exr_channels_read(const Imf::ChannelList& channels);

// One channel's values as the file stores them, row-major, top row first.
struct StoredPlane {
  std::string name;
  Imf::PixelType type;
  const char* values;
};

// Sorted by name: the channel list's order.
void sort_by_name(std::vector<StoredPlane>& planes);

// ExrFile::pixels_hash of planes of `width` x `height` values, sorted by name (the channel list's
// order): the writer hashes the planes it hands OpenEXR, the reader the ones it reads back in the
// file's own types, so that both see the same bytes.
class StoredPixelsHash {
 public:
  StoredPixelsHash(uint32_t width, uint32_t height, const std::vector<StoredPlane>& planes);
  // Rows [0, rows) of `planes` (the same channels, in the same order), the next rows of the image.
  void add_rows(const std::vector<StoredPlane>& planes, uint32_t rows);
  std::string hex();

 private:
  std::unique_ptr<Hasher> hasher_;
  uint32_t width_;
};

}  // namespace vkray
