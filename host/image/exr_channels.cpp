#include "image/exr_channels.h"

#include <algorithm>
#include <cstring>

#include <Imath/half.h>

namespace vkray {

ExrLayer exr_layer_of(Aov pass) {
  switch (pass) {
    case Aov::albedo: return {"albedo", {"R", "G", "B"}, 3};
    case Aov::normal: return {"normal", {"X", "Y", "Z"}, 3};
    case Aov::position: return {"position", {"X", "Y", "Z"}, 3};
    case Aov::depth: return {"depth", {"Z", nullptr, nullptr}, 1};
    case Aov::object: return {"object", {"id", nullptr, nullptr}, 1};
  }
  return {"", {}, 0};
}

std::string exr_channel_name(const ExrLayer& layer, int c) {
  return layer.name[0] ? std::string(layer.name) + "." + layer.suffixes[c] : std::string(layer.suffixes[c]);
}

size_t exr_bytes_of(Imf::PixelType type) { return type == Imf::HALF ? sizeof(Imath::half) : sizeof(float); }

std::vector<Aov> exr_passes_in(const Imf::ChannelList& channels) {
  std::vector<Aov> passes;
  for (const Aov pass : kAllAovs)
    if (channels.findChannel(exr_channel_name(exr_layer_of(pass), 0))) passes.push_back(pass);
  return passes;
}

std::vector<std::string> exr_channels_read(const Imf::ChannelList& channels) {
  const std::vector<Aov> passes = exr_passes_in(channels);
  std::vector<std::string> names;
  for (auto c = channels.begin(); c != channels.end(); ++c) {
    const std::string name = c.name();
    bool read = name == "R" || name == "G" || name == "B";
    for (const Aov pass : passes) {
      const ExrLayer layer = exr_layer_of(pass);
      for (int k = 0; k < layer.channels; ++k) read |= name == exr_channel_name(layer, k);
    }
    if (read) names.push_back(name);
  }
  return names;
}

void sort_by_name(std::vector<StoredPlane>& planes) {
  std::sort(planes.begin(), planes.end(), [](const StoredPlane& a, const StoredPlane& b) { return std::strcmp(a.name.c_str(), b.name.c_str()) < 0; });
}

StoredPixelsHash::StoredPixelsHash(uint32_t width, uint32_t height, const std::vector<StoredPlane>& planes)
    : hasher_(std::make_unique<Hasher>()), width_(width) {
  hasher_->add(width);
  hasher_->add(height);
  for (const StoredPlane& plane : planes) {
    hasher_->add(plane.name);
    hasher_->add(int32_t(plane.type));
  }
}

void StoredPixelsHash::add_rows(const std::vector<StoredPlane>& planes, uint32_t rows) {
  for (uint32_t y = 0; y < rows; ++y)
    for (const StoredPlane& plane : planes) {
      const size_t row_bytes = size_t(width_) * exr_bytes_of(plane.type);
      hasher_->bytes(plane.values + y * row_bytes, row_bytes);
    }
}

std::string StoredPixelsHash::hex() { return hasher_->hex(); }

}  // namespace vkray
