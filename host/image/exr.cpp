#include "image/exr.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>
#include <new>
#include <string>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStdIO.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>
#include <OpenEXR/ImfTileDescriptionAttribute.h>
#include <OpenEXR/ImfVersion.h>

#include "base/atomic_file.h"
#include "base/errors.h"
#include "base/hash.h"
#include "base/interrupt.h"
#include "base/threads.h"

namespace vkray {
namespace {

// OpenEXR's output through an AtomicFile's stream, so that a failed write leaves no file.
class FileStream : public Imf::OStream {
 public:
  FileStream(FILE* file, const std::string& name) : Imf::OStream(name.c_str()), file_(file) {}
  void write(const char c[], int n) override {
    if (std::fwrite(c, 1, size_t(n), file_) != size_t(n))
      throw std::runtime_error(std::string("write failed: ") + std::strerror(errno));
  }
  uint64_t tellp() override { return uint64_t(ftello(file_)); }
  void seekp(uint64_t position) override {
    if (fseeko(file_, off_t(position), SEEK_SET) != 0) throw std::runtime_error(std::string("seek failed: ") + std::strerror(errno));
  }

 private:
  FILE* file_;
};

// A layer's channels: their names after the layer's, and where each pixel's values are.
struct Layer {
  const char* name;       // "" for the image's R, G, B
  const char* suffixes[3];
  int channels;
};

Layer layer_of(Aov pass) {
  switch (pass) {
    case Aov::albedo: return {"albedo", {"R", "G", "B"}, 3};
    case Aov::normal: return {"normal", {"X", "Y", "Z"}, 3};
    case Aov::position: return {"position", {"X", "Y", "Z"}, 3};
    case Aov::depth: return {"depth", {"Z", nullptr, nullptr}, 1};
    case Aov::object: return {"object", {"id", nullptr, nullptr}, 1};
  }
  return {"", {}, 0};
}

std::string channel_name(const Layer& layer, int c) {
  return layer.name[0] ? std::string(layer.name) + "." + layer.suffixes[c] : std::string(layer.suffixes[c]);
}

size_t bytes_of(Imf::PixelType type) { return type == Imf::HALF ? sizeof(Imath::half) : sizeof(float); }

// ---- the hash of the pixels as stored --------------------------------------------------------------

// One channel's values as the file stores them, row-major, top row first.
struct StoredPlane {
  std::string name;
  Imf::PixelType type;
  const char* values;
};

// ExrFile::pixels_hash of planes of `width` x `height` values, sorted by name (the channel list's
// order): the writer hashes the planes it hands OpenEXR, the reader the ones it reads back in the
// file's own types, so that both see the same bytes.
class StoredPixelsHash {
 public:
  StoredPixelsHash(uint32_t width, uint32_t height, const std::vector<StoredPlane>& planes)
      : hasher_(std::make_unique<Hasher>()), width_(width) {
    hasher_->add(width);
    hasher_->add(height);
    for (const StoredPlane& plane : planes) {
      hasher_->add(plane.name);
      hasher_->add(int32_t(plane.type));
    }
  }
  // Rows [0, rows) of `planes` (the same channels, in the same order), the next rows of the image.
  void add_rows(const std::vector<StoredPlane>& planes, uint32_t rows) {
    for (uint32_t y = 0; y < rows; ++y)
      for (const StoredPlane& plane : planes) {
        const size_t row_bytes = size_t(width_) * bytes_of(plane.type);
        hasher_->bytes(plane.values + y * row_bytes, row_bytes);
      }
  }
  std::string hex() { return hasher_->hex(); }

 private:
  std::unique_ptr<Hasher> hasher_;
  uint32_t width_;
};

void sort_by_name(std::vector<StoredPlane>& planes) {
  std::sort(planes.begin(), planes.end(), [](const StoredPlane& a, const StoredPlane& b) { return std::strcmp(a.name.c_str(), b.name.c_str()) < 0; });
}

// ---- the writer's planes ---------------------------------------------------------------------------

// Each channel in a plane of its own, of the type it has in the file (OpenEXR converts types when it
// reads, not when it writes).
struct WrittenPlanes {
  std::vector<std::vector<float>> floats;
  std::vector<std::vector<Imath::half>> halves;
  std::vector<StoredPlane> stored;
};

WrittenPlanes written_planes(const Image& image, const Aovs* aovs, const ExrContent& content) {
  const size_t pixels = image.pixels.size();
  WrittenPlanes planes;
  const auto add = [&](const std::string& name, bool full_float, auto value) {
    if (full_float) {
      std::vector<float>& plane = planes.floats.emplace_back(pixels);
      for (size_t i = 0; i < pixels; ++i) plane[i] = value(i);
      planes.stored.push_back({name, Imf::FLOAT, reinterpret_cast<const char*>(plane.data())});
    } else {
      std::vector<Imath::half>& plane = planes.halves.emplace_back(pixels);
      for (size_t i = 0; i < pixels; ++i) plane[i] = Imath::half(value(i));
      planes.stored.push_back({name, Imf::HALF, reinterpret_cast<const char*>(plane.data())});
    }
  };
  planes.floats.reserve(3 + 3 * content.passes.size());  // planes must not move once pointed at
  planes.halves.reserve(3 + 3 * content.passes.size());
  for (int c = 0; c < 3; ++c) add(std::string(1, "RGB"[c]), content.full_float, [&](size_t i) { return image.pixels[i][c]; });
  for (const Aov pass : content.passes) {
    const Layer layer = layer_of(pass);
    for (int c = 0; c < layer.channels; ++c) {
      const std::string name = channel_name(layer, c);
      switch (pass) {
        case Aov::albedo: add(name, content.full_float, [&](size_t i) { return aovs->albedo[i][c]; }); break;
        case Aov::normal: add(name, content.full_float, [&](size_t i) { return aovs->normal[i][c]; }); break;
        // Lengths are always 32-bit: half floats step by 1/32 past 2048, and round depths past 65504
        // to infinity, which means "nothing hit".
        case Aov::position: add(name, true, [&](size_t i) { return aovs->position[i][c]; }); break;
        case Aov::depth: add(name, true, [&](size_t i) { return aovs->depth[i]; }); break;
        case Aov::object: add(name, true, [&](size_t i) { return float(aovs->object[i]); }); break;
      }
    }
  }
  sort_by_name(planes.stored);
  return planes;
}

}  // namespace

void write_exr(const std::filesystem::path& file, const Image& image, const Aovs* aovs, const ExrContent& content,
               const ExrPartHeader* part) {
  if (!content.passes.empty() && (!aovs || aovs->width != image.width || aovs->height != image.height))
    throw InternalError(file.string() + ": first-hit passes asked for without passes of the image's size");
  if (image.width == 0 || image.height == 0) throw OutputError(file.string() + ": an EXR image cannot be empty");
  const PixelRegion region = part ? part->region : full_region(image.width, image.height);
  if (part && (region.width() != image.width || region.height() != image.height || !region.within(part->full_width, part->full_height)))
    throw InternalError(file.string() + ": a part's pixels do not fit its region");
  const auto box = [](const PixelRegion& r) {
    return Imath::Box2i(Imath::V2i(int(r.x0), int(r.y0)), Imath::V2i(int(r.x1) - 1, int(r.y1) - 1));
  };
  Imf::Header header(part ? box(full_region(part->full_width, part->full_height)) : box(region), box(region));
  header.compression() = Imf::ZIP_COMPRESSION;
  header.insert("software", Imf::StringAttribute("vkray"));
  WrittenPlanes planes;
  try {
    planes = written_planes(image, aovs, content);
  } catch (const std::bad_alloc&) {
    throw out_of_host_memory(file, image.width, image.height);
  }
  if (part && part->record) {
    StoredPixelsHash hash(image.width, image.height, planes.stored);
    hash.add_rows(planes.stored, image.height);
    header.insert("vkray.part", Imf::StringAttribute(part->record(hash.hex())));
  }
  // Slices are addressed as if the buffer started at the display window's origin.
  Imf::FrameBuffer frame;
  for (const StoredPlane& plane : planes.stored) {
    const size_t size = bytes_of(plane.type);
    char* origin = const_cast<char*>(plane.values) - (int64_t(region.x0) + int64_t(region.y0) * int64_t(image.width)) * int64_t(size);
    header.channels().insert(plane.name, Imf::Channel(plane.type));
    frame.insert(plane.name, Imf::Slice(plane.type, origin, size, size * image.width));
  }
  // OpenEXR compresses blocks of lines on its own thread pool: every core, set once.
  static const bool threads_set = [] {
    Imf::setGlobalThreadCount(int(thread_count()));
    return true;
  }();
  static_cast<void>(threads_set);
  AtomicFile out(file);
  try {
    FileStream stream(out.get(), file.string());
    Imf::OutputFile exr(stream, header);
    exr.setFrameBuffer(frame);
    // In bands, so that an interrupt request is seen within a fraction of a second.
    for (uint32_t written = 0; written < image.height;) {
      throw_if_interrupted();
      const uint32_t rows = std::min<uint32_t>(256, image.height - written);
      exr.writePixels(int(rows));
      written += rows;
    }
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw out_of_host_memory(file, image.width, image.height);
  } catch (const std::exception& e) {
    throw OutputError(file.string() + ": EXR write failed: " + e.what());
  }
  out.commit();
}

namespace {

// ---- the header's claims, checked before anything is allocated for them ----------------------------

// The largest block of scan lines (or tile) OpenEXR may be asked to decode at once: a
// highly-compressed file may claim much more than it holds, and OpenEXR keeps a buffer of a block
// per thread. vkray's own parts need at most 16 lines x 16384 pixels x 56 bytes, 14 MiB.
constexpr uint64_t kMaxExrBlockBytes = uint64_t(256) << 20;

// The scan lines OpenEXR compresses together with each method (the file layout's "lines per block").
int lines_per_chunk(Imf::Compression compression) {
  switch (compression) {
    case Imf::NO_COMPRESSION:
    case Imf::RLE_COMPRESSION:
    case Imf::ZIPS_COMPRESSION: return 1;
    case Imf::ZIP_COMPRESSION:
    case Imf::PXR24_COMPRESSION: return 16;
    case Imf::PIZ_COMPRESSION:
    case Imf::B44_COMPRESSION:
    case Imf::B44A_COMPRESSION:
    case Imf::DWAA_COMPRESSION: return 32;
    case Imf::DWAB_COMPRESSION: return 256;
    default: return 0;
  }
}

[[noreturn]] void refuse(const std::filesystem::path& file, const std::string& why) { throw InputError(file.string() + ": " + why); }

std::string bytes_text(uint64_t bytes) { return std::to_string(bytes) + (bytes == 1 ? " byte" : " bytes"); }

// The header as the file lays it out (the magic number, the version field, then attributes of a
// name, a type name, a size and a value, up to an empty name), walked without reading a value: every
// size it claims must lie within the file, before OpenEXR allocates that much to read it.
struct HeaderLayout {
  int version = 0;
  uint64_t end = 0;  // where the header ends: the chunk offset table starts
};

HeaderLayout walk_header(std::istream& in, const std::filesystem::path& file, uint64_t file_bytes) {
  char start[8];
  if (!in.read(start, sizeof start) || !Imf::isImfMagic(start)) refuse(file, "not an OpenEXR file");
  HeaderLayout layout;
  std::memcpy(&layout.version, start + 4, sizeof layout.version);
  if (Imf::getVersion(layout.version) != Imf::EXR_VERSION || !Imf::supportsFlags(Imf::getFlags(layout.version)))
    refuse(file, "an OpenEXR file of a format version vkray does not read");
  if (Imf::isMultiPart(layout.version) || Imf::isNonImage(layout.version))
    refuse(file, "a multi-part or deep OpenEXR file: vkray reads single-part flat images");
  const size_t max_name = layout.version & Imf::LONG_NAMES_FLAG ? 255 : 31;
  uint64_t at = sizeof start;
  const auto name = [&] {
    std::string text;
    for (;;) {
      const int c = in.get();
      ++at;
      if (c == 0) return text;
      if (c == EOF) refuse(file, "its header ends with the file");
      if (text.size() == max_name) refuse(file, "its header holds a name longer than " + std::to_string(max_name) + " bytes");
      text += char(c);
    }
  };
  for (;;) {
    const std::string attribute = name();
    if (attribute.empty()) break;
    const std::string type = name();
    int32_t size = 0;
    if (!in.read(reinterpret_cast<char*>(&size), sizeof size)) refuse(file, "its header ends with the file");
    at += sizeof size;
    if (size < 0 || at > file_bytes || uint64_t(size) > file_bytes - at)  // (a file that shrank since it was measured)
      refuse(file, "its header attribute \"" + printable(attribute) + "\" claims " + bytes_text(uint64_t(uint32_t(size))) +
                       " past byte " + std::to_string(at) + " of a file of " + bytes_text(file_bytes));
    if (type == "preview") {  // a width and a height, then 4 bytes a pixel
      uint32_t side[2] = {0, 0};
      if (size < int32_t(sizeof side) || !in.read(reinterpret_cast<char*>(side), sizeof side) ||
          uint64_t(size) != sizeof side + uint64_t(4) * side[0] * side[1])
        refuse(file, "its preview image claims " + std::to_string(side[0]) + " x " + std::to_string(side[1]) +
                         " pixels in an attribute of " + bytes_text(uint64_t(size)));
      in.seekg(size - int32_t(sizeof side), std::ios::cur);
    } else {
      in.seekg(size, std::ios::cur);
    }
    at += uint64_t(size);
  }
  layout.end = at;
  return layout;
}

// The passes a file has: those whose layer's first channel it has.
std::vector<Aov> passes_in(const Imf::ChannelList& channels) {
  std::vector<Aov> passes;
  for (const Aov pass : kAllAovs)
    if (channels.findChannel(channel_name(layer_of(pass), 0))) passes.push_back(pass);
  return passes;
}

// The channels read_exr reads (R, G, B, and the layers of the passes it has), in the channel list's
// order.
std::vector<std::string> channels_read(const Imf::ChannelList& channels) {
  const std::vector<Aov> passes = passes_in(channels);
  std::vector<std::string> names;
  for (auto c = channels.begin(); c != channels.end(); ++c) {
    const std::string name = c.name();
    bool read = name == "R" || name == "G" || name == "B";
    for (const Aov pass : passes) {
      const Layer layer = layer_of(pass);
      for (int k = 0; k < layer.channels; ++k) read |= name == channel_name(layer, k);
    }
    if (read) names.push_back(name);
  }
  return names;
}

// The header's windows, channels, blocks and chunk offset table against the file and vkray's limits.
// Returns the scan lines to read at a time: whole blocks, at least 64 lines.
int check_claims(const Imf::Header& header, const HeaderLayout& layout, std::istream& in, const std::filesystem::path& file,
                 uint64_t file_bytes) {
  const Imath::Box2i window = header.dataWindow();
  const int64_t w = int64_t(window.max.x) - window.min.x + 1, h = int64_t(window.max.y) - window.min.y + 1;
  if (w <= 0 || h <= 0 || w > kMaxImageSide || h > kMaxImageSide)
    refuse(file, "an EXR data window of " + std::to_string(w) + " x " + std::to_string(h) + " pixels (vkray reads up to " +
                     std::to_string(kMaxImageSide) + " on a side)");
  const Imf::ChannelList& channels = header.channels();
  uint64_t channel_count = 0, pixel_bytes = 0;
  for (auto c = channels.begin(); c != channels.end(); ++c) {
    ++channel_count;
    pixel_bytes += bytes_of(c.channel().type);
  }
  if (channel_count > kMaxExrChannels)
    refuse(file, "an EXR file of " + std::to_string(channel_count) + " channels (vkray reads up to " +
                     std::to_string(kMaxExrChannels) + ")");
  for (const char* name : {"R", "G", "B"})
    if (!channels.findChannel(name)) refuse(file, std::string("no channel ") + name);
  for (const std::string& name : channels_read(channels)) {
    const Imf::Channel& channel = *channels.findChannel(name);
    if (channel.xSampling != 1 || channel.ySampling != 1)
      refuse(file, "channel " + name + " is subsampled (" + std::to_string(channel.xSampling) + " x " +
                       std::to_string(channel.ySampling) + "): vkray reads a value for every pixel");
  }
  // The blocks the file must hold: one chunk per block of scan lines, or per tile of the first level.
  const bool tiled = Imf::isTiled(layout.version);
  uint64_t chunks = 0, block_pixels = 0, chunk_header_bytes = 0;
  int rows_per_read = 0;
  if (tiled) {
    if (!header.hasTileDescription()) refuse(file, "a tiled EXR file without a tile description");
    const Imf::TileDescription& tiles = header.tileDescription();
    if (tiles.xSize == 0 || tiles.ySize == 0 || tiles.xSize > kMaxImageSide || tiles.ySize > kMaxImageSide)
      refuse(file, "EXR tiles of " + std::to_string(tiles.xSize) + " x " + std::to_string(tiles.ySize) + " pixels");
    chunks = ((uint64_t(w) + tiles.xSize - 1) / tiles.xSize) * ((uint64_t(h) + tiles.ySize - 1) / tiles.ySize);
    // OpenEXR reads a tiled file for scan lines through a row of tiles at a time.
    block_pixels = std::max<uint64_t>(tiles.xSize, uint64_t(w)) * tiles.ySize;
    chunk_header_bytes = 4 * sizeof(int32_t);  // tile x, y, level x, level y
    rows_per_read = int(tiles.ySize);
  } else {
    const int lines = lines_per_chunk(header.compression());
    if (lines == 0) refuse(file, "an unknown EXR compression method (" + std::to_string(int(header.compression())) + ")");
    chunks = (uint64_t(h) + uint64_t(lines) - 1) / uint64_t(lines);
    block_pixels = uint64_t(w) * uint64_t(lines);
    chunk_header_bytes = sizeof(int32_t);  // the first scan line's y
    rows_per_read = lines;
  }
  if (block_pixels * pixel_bytes > kMaxExrBlockBytes)
    refuse(file, "an EXR block of " + std::to_string(block_pixels) + " pixels of " + bytes_text(pixel_bytes) + " each (vkray reads "
                     "blocks of up to " + bytes_text(kMaxExrBlockBytes) + ")");
  // Each chunk: its offset in the table, its header, its data's size (4 bytes) and at least a byte of data.
  const uint64_t chunk_min = chunk_header_bytes + sizeof(int32_t) + 1;
  const uint64_t table_end = layout.end + chunks * sizeof(uint64_t);
  if (table_end + chunks * chunk_min > file_bytes)
    refuse(file, "its header claims " + std::to_string(w) + " x " + std::to_string(h) + " pixels in " + std::to_string(chunks) +
                     " blocks, which need at least " + bytes_text(table_end + chunks * chunk_min) + ", in a file of " +
                     bytes_text(file_bytes));
  // The chunk offset table, a block of it at a time: every offset within the file.
  in.clear();
  in.seekg(std::streamoff(layout.end));
  std::vector<uint64_t> offsets(std::min<uint64_t>(chunks, 8192));
  for (uint64_t first = 0; first < chunks; first += offsets.size()) {
    const size_t count = size_t(std::min<uint64_t>(offsets.size(), chunks - first));
    if (!in.read(reinterpret_cast<char*>(offsets.data()), std::streamsize(count * sizeof(uint64_t))))
      refuse(file, "its chunk offset table ends with the file");
    for (size_t i = 0; i < count; ++i)
      if (offsets[i] < table_end || offsets[i] > file_bytes - chunk_min)
        refuse(file, "its chunk offset table points outside the file: block " + std::to_string(first + i) + " at byte " +
                         std::to_string(offsets[i]) + " of a file of " + bytes_text(file_bytes) + " (the table ends at byte " +
                         std::to_string(table_end) + ")");
  }
  return rows_per_read * std::max(1, (64 + rows_per_read - 1) / rows_per_read);
}

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
    const Layer layer = layer_of(pass);
    for (int c = 0; c < layer.channels; ++c) {
      if (name != channel_name(layer, c)) continue;
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
    buffers.emplace_back(size_t(band_rows) * w * bytes_of(type));
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
      const size_t size = bytes_of(plane.type);
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
  // OpenEXR's own checks of a header, as a second line: vkray's limits.
  static std::once_flag limits;
  std::call_once(limits, [] {
    Imf::Header::setMaxImageSize(int(kMaxImageSide), int(kMaxImageSide));
    Imf::Header::setMaxTileSize(int(kMaxImageSide), int(kMaxImageSide));
  });
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) refuse(file, "not found, or not a regular file");
  const uint64_t file_bytes = std::filesystem::file_size(file, error);
  std::ifstream in(file, std::ios::binary);
  if (!in || error) refuse(file, "cannot open");
  ExrFile result;
  uint32_t w = 0, h = 0;
  try {
    // Every claim is checked on the bytes of this one open file, before OpenEXR opens it for pixels.
    const HeaderLayout layout = walk_header(in, file, file_bytes);
    Imf::StdIFStream stream(in, file.c_str());
    stream.seekg(8);
    Imf::Header header;
    int version = layout.version;
    header.readFrom(stream, version);
    const int band_rows = check_claims(header, layout, in, file, file_bytes);
    header.sanityCheck(Imf::isTiled(layout.version));
    in.clear();
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
    result.content.passes = passes_in(channels);
    result.image = Image(w, h);
    if (!result.content.passes.empty()) result.aovs = Aovs(w, h);
    read_pixels(exr, channels_read(channels), band_rows, result);
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw out_of_host_memory(file, w, h);
  } catch (const std::exception& e) {
    // OpenEXR's worker threads pass a failed allocation on as a message.
    if (std::strstr(e.what(), "bad_alloc")) throw out_of_host_memory(file, w, h);
    refuse(file, e.what());
  }
  return result;
}

}  // namespace vkray
