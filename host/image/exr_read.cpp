// read_exr (exr.h): a single-part flat EXR file's R, G, B and first-hit passes, read after its header
// has been checked against the file (exr_header.h), in bands of scan lines so that an interrupt
// request is seen within a band, each channel in the type the file stores it in so that the hash
// of the pixels as stored (exr_channels.h) can be compared with the one a part's record holds.
#include "image/exr.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <new>
#include <string>
#include <vector>

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfStdIO.h>
#include <OpenEXR/ImfStringAttribute.h>

#include "base/errors.h"
#include "base/interrupt.h"
#include "image/exr_channels.h"
#include "image/exr_header.h"

namespace vkray {
namespace {

// Where a channel's values go: `values` every `stride` floats; object ids are whole numbers instead.
struct Destination {
  float* values = nullptr;
  size_t stride = 0;
  bool object_id = false;
};

Destination destination_of(ExrFile& result, const std::string& name) {
  for (int c = 0; c < 3; ++c)
    if (name == std::string(1, "RGB"[c])) return {&result.image.pixels[0][c], 3, false};
  for (const Aov pass : kAllAovs) {
    const ExrLayer layer = exr_layer_of(pass);
    for (int c = 0; c < layer.channels; ++c) {
      if (name != exr_channel_name(layer, c)) continue;
      Aovs& aovs = result.aovs;
      switch (pass) {
        case Aov::albedo: return {&aovs.albedo[0][c], 3, false};
        case Aov::normal: return {&aovs.normal[0][c], 3, false};
        case Aov::position: return {&aovs.position[0][c], 3, false};
        case Aov::depth: return {aovs.depth.data(), 1, false};
        case Aov::object: return {nullptr, 1, true};
      }
    }
  }
  return {};
}

// The `count` values of a plane as floats, as OpenEXR converts them, to `store(i, value)`.
template <typename Store>
void convert(const StoredPlane& plane, size_t count, Store store) {
  const auto each = [&](auto stored, auto to_float) {
    for (size_t i = 0; i < count; ++i) {
      std::memcpy(&stored, plane.values + i * sizeof stored, sizeof stored);
      store(i, to_float(stored));
    }
  };
  switch (plane.type) {
    case Imf::HALF: return each(uint16_t(0), [](uint16_t bits) { return float(Imath::half(Imath::half::FromBits, bits)); });
    case Imf::UINT: return each(uint32_t(0), [](uint32_t value) { return float(value); });
    default: return each(0.0f, [](float value) { return value; });
  }
}

// Reads the pixels in bands of `band_rows`, each channel in its file type, hashing them as stored and
// converting them into `result` (sized already).
void read_pixels(Imf::InputFile& exr, const std::vector<std::string>& names, int band_rows, ExrFile& result) {
  const Imath::Box2i window = exr.header().dataWindow();
  const uint32_t w = result.image.width, h = result.image.height;
  std::vector<std::vector<char>> buffers;
  std::vector<StoredPlane> planes;
  std::vector<Destination> destinations;
  for (const std::string& name : names) {
    const Imf::PixelType type = exr.header().channels().findChannel(name)->type;
    buffers.emplace_back(size_t(band_rows) * w * exr_bytes_of(type));
    planes.push_back({name, type, buffers.back().data()});
    destinations.push_back(destination_of(result, name));
  }
  StoredPixelsHash hash(w, h, planes);
  for (uint32_t top = 0; top < h; top += uint32_t(band_rows)) {
    throw_if_interrupted();
    const uint32_t rows = std::min(uint32_t(band_rows), h - top);
    // Slices are addressed as if the buffer started at the origin of the file's coordinates.
    Imf::FrameBuffer frame;
    for (const StoredPlane& plane : planes) {
      const size_t size = exr_bytes_of(plane.type);
      char* origin = const_cast<char*>(plane.values) - (int64_t(window.min.x) + (int64_t(window.min.y) + top) * int64_t(w)) * int64_t(size);
      frame.insert(plane.name, Imf::Slice(plane.type, origin, size, size * w));
    }
    exr.setFrameBuffer(frame);
    exr.readPixels(window.min.y + int(top), window.min.y + int(top + rows) - 1);
    hash.add_rows(planes, rows);
    const size_t first = size_t(top) * w, count = size_t(rows) * w;
    for (size_t k = 0; k < planes.size(); ++k) {
      const Destination& to = destinations[k];
      if (to.object_id) {
        convert(planes[k], count, [&](size_t i, float value) {  // ids are whole numbers from -1 up; anything else is no id
          const bool id = value >= 0.0f && value < 2147483648.0f && value == std::floor(value);
          result.aovs.object[first + i] = id ? int32_t(value) : -1;
        });
      } else {
        convert(planes[k], count, [&](size_t i, float value) { to.values[(first + i) * to.stride] = value; });
      }
    }
  }
  result.pixels_hash = hash.hex();
}

}  // namespace

ExrFile read_exr(const std::filesystem::path& file) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) refuse_exr(file, "not found, or not a regular file");
  const uint64_t file_bytes = std::filesystem::file_size(file, error);
  std::ifstream in(file, std::ios::binary);
  if (!in || error) refuse_exr(file, "cannot open");
  ExrFile result;
  uint32_t w = 0, h = 0;
  try {
    // Every claim is checked on the bytes of this one open file, before OpenEXR opens it for pixels.
    const int band_rows = check_exr_header(in, file, file_bytes);
    in.clear();
    Imf::StdIFStream stream(in, file.c_str());
    stream.seekg(0);
    Imf::InputFile exr(stream);
    const Imath::Box2i window = exr.header().dataWindow();
    w = uint32_t(window.max.x - window.min.x + 1);
    h = uint32_t(window.max.y - window.min.y + 1);
    const Imath::Box2i display = exr.header().displayWindow();
    if (display.min.x == 0 && display.min.y == 0 && window.min.x >= 0 && window.min.y >= 0 && display.max.x < int(kMaxImageSide) &&
        display.max.y < int(kMaxImageSide) && window.max.x <= display.max.x && window.max.y <= display.max.y) {
      result.window.full_width = uint32_t(display.max.x + 1);
      result.window.full_height = uint32_t(display.max.y + 1);
      result.window.region = {uint32_t(window.min.x), uint32_t(window.min.y), uint32_t(window.max.x + 1), uint32_t(window.max.y + 1)};
    }
    if (const auto* record = exr.header().findTypedAttribute<Imf::StringAttribute>("vkray.part"))
      result.window.part_record = record->value();
    const Imf::ChannelList& channels = exr.header().channels();
    result.content.full_float = channels.findChannel("R")->type == Imf::FLOAT;
    result.content.passes = exr_passes_in(channels);
    result.image = Image(w, h);
    if (!result.content.passes.empty()) result.aovs = Aovs(w, h);
    read_pixels(exr, exr_channels_read(channels), band_rows, result);
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw out_of_host_memory(file, w, h);
  } catch (const std::exception& e) {
    // OpenEXR's worker threads pass a failed allocation on as a message.
    if (std::strstr(e.what(), "bad_alloc")) throw out_of_host_memory(file, w, h);
    refuse_exr(file, e.what());
  }
  return result;
}

}  // namespace vkray
