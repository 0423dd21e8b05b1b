#include "image/exr_header.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfStdIO.h>
#include <OpenEXR/ImfTileDescriptionAttribute.h>
#include <OpenEXR/ImfVersion.h>

#include "base/errors.h"
#include "image/exr.h"
#include "image/exr_channels.h"

namespace vkray {
namespace {

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
  if (!in.read(start, sizeof start) || !Imf::isImfMagic(start)) refuse_exr(file, "not an OpenEXR file");
  HeaderLayout layout;
  std::memcpy(&layout.version, start + 4, sizeof layout.version);
  if (Imf::getVersion(layout.version) != Imf::EXR_VERSION || !Imf::supportsFlags(Imf::getFlags(layout.version)))
    refuse_exr(file, "an OpenEXR file of a format version vkray does not read");
  if (Imf::isMultiPart(layout.version) || Imf::isNonImage(layout.version))
    refuse_exr(file, "a multi-part or deep OpenEXR file: vkray reads single-part flat images");
  const size_t max_name = layout.version & Imf::LONG_NAMES_FLAG ? 255 : 31;
  uint64_t at = sizeof start;
  const auto name = [&] {
    std::string text;
    for (;;) {
      const int c = in.get();
      ++at;
      if (c == 0) return text;
      if (c == EOF) refuse_exr(file, "its header ends with the file");
      if (text.size() == max_name) refuse_exr(file, "its header holds a name longer than " + std::to_string(max_name) + " bytes");
      text += char(c);
    }
  };
  for (;;) {
    const std::string attribute = name();
    if (attribute.empty()) break;
    const std::string type = name();
    int32_t size = 0;
    if (!in.read(reinterpret_cast<char*>(&size), sizeof size)) refuse_exr(file, "its header ends with the file");
    at += sizeof size;
    if (size < 0 || at > file_bytes || uint64_t(size) > file_bytes - at)  // (a file that shrank since it was measured)
      refuse_exr(file, "its header attribute \"" + printable(attribute) + "\" claims " + bytes_text(uint64_t(uint32_t(size))) +
                       " past byte " + std::to_string(at) + " of a file of " + bytes_text(file_bytes));
    if (type == "preview") {  // a width and a height, then 4 bytes a pixel
      uint32_t side[2] = {0, 0};
      if (size < int32_t(sizeof side) || !in.read(reinterpret_cast<char*>(side), sizeof side) ||
          uint64_t(size) != sizeof side + uint64_t(4) * side[0] * side[1])
        refuse_exr(file, "its preview image claims " + std::to_string(side[0]) + " x " + std::to_string(side[1]) +
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

// The header's windows, channels, blocks and chunk offset table against the file and vkray's limits.
// Returns the scan lines to read at a time: whole blocks, at least 64 lines.
int check_claims(const Imf::Header& header, const HeaderLayout& layout, std::istream& in, const std::filesystem::path& file,
                 uint64_t file_bytes) {
  const Imath::Box2i window = header.dataWindow();
  const int64_t w = int64_t(window.max.x) - window.min.x + 1, h = int64_t(window.max.y) - window.min.y + 1;
  if (w <= 0 || h <= 0 || w > kMaxImageSide || h > kMaxImageSide)
    refuse_exr(file, "an EXR data window of " + std::to_string(w) + " x " + std::to_string(h) + " pixels (vkray reads up to " +
                     std::to_string(kMaxImageSide) + " on a side)");
  const Imf::ChannelList& channels = header.channels();
  uint64_t channel_count = 0, pixel_bytes = 0;
  for (auto c = channels.begin(); c != channels.end(); ++c) {
    ++channel_count;
    pixel_bytes += exr_bytes_of(c.channel().type);
  }
  if (channel_count > kMaxExrChannels)
    refuse_exr(file, "an EXR file of " + std::to_string(channel_count) + " channels (vkray reads up to " +
                     std::to_string(kMaxExrChannels) + ")");
  for (const char* name : {"R", "G", "B"})
    if (!channels.findChannel(name)) refuse_exr(file, std::string("no channel ") + name);
  for (const std::string& name : exr_channels_read(channels)) {
    const Imf::Channel& channel = *channels.findChannel(name);
    if (channel.xSampling != 1 || channel.ySampling != 1)
      refuse_exr(file, "channel " + name + " is subsampled (" + std::to_string(channel.xSampling) + " x " +
                       std::to_string(channel.ySampling) + "): vkray reads a value for every pixel");
  }
  // The blocks the file must hold: one chunk per block of scan lines, or per tile of the first level.
  const bool tiled = Imf::isTiled(layout.version);
  uint64_t chunks = 0, block_pixels = 0, chunk_header_bytes = 0;
  int rows_per_read = 0;
  if (tiled) {
    if (!header.hasTileDescription()) refuse_exr(file, "a tiled EXR file without a tile description");
    const Imf::TileDescription& tiles = header.tileDescription();
    if (tiles.xSize == 0 || tiles.ySize == 0 || tiles.xSize > kMaxImageSide || tiles.ySize > kMaxImageSide)
      refuse_exr(file, "EXR tiles of " + std::to_string(tiles.xSize) + " x " + std::to_string(tiles.ySize) + " pixels");
    chunks = ((uint64_t(w) + tiles.xSize - 1) / tiles.xSize) * ((uint64_t(h) + tiles.ySize - 1) / tiles.ySize);
    // OpenEXR reads a tiled file for scan lines through a row of tiles at a time.
    block_pixels = std::max<uint64_t>(tiles.xSize, uint64_t(w)) * tiles.ySize;
    chunk_header_bytes = 4 * sizeof(int32_t);  // tile x, y, level x, level y
    rows_per_read = int(tiles.ySize);
  } else {
    const int lines = lines_per_chunk(header.compression());
    if (lines == 0) refuse_exr(file, "an unknown EXR compression method (" + std::to_string(int(header.compression())) + ")");
    chunks = (uint64_t(h) + uint64_t(lines) - 1) / uint64_t(lines);
    block_pixels = uint64_t(w) * uint64_t(lines);
    chunk_header_bytes = sizeof(int32_t);  // the first scan line's y
    rows_per_read = lines;
  }
  if (block_pixels * pixel_bytes > kMaxExrBlockBytes)
    refuse_exr(file, "an EXR block of " + std::to_string(block_pixels) + " pixels of " + bytes_text(pixel_bytes) + " each (vkray reads "
                     "blocks of up to " + bytes_text(kMaxExrBlockBytes) + ")");
  // Each chunk: its offset in the table, its header, its data's size (4 bytes) and at least a byte of data.
  const uint64_t chunk_min = chunk_header_bytes + sizeof(int32_t) + 1;
  const uint64_t table_end = layout.end + chunks * sizeof(uint64_t);
  if (table_end + chunks * chunk_min > file_bytes)
    refuse_exr(file, "its header claims " + std::to_string(w) + " x " + std::to_string(h) + " pixels in " + std::to_string(chunks) +
                     " blocks, which need at least " + bytes_text(table_end + chunks * chunk_min) + ", in a file of " +
                     bytes_text(file_bytes));
  // The chunk offset table, a block of it at a time: every offset within the file.
  in.clear();
  in.seekg(std::streamoff(layout.end));
  std::vector<uint64_t> offsets(std::min<uint64_t>(chunks, 8192));
  for (uint64_t first = 0; first < chunks; first += offsets.size()) {
    const size_t count = size_t(std::min<uint64_t>(offsets.size(), chunks - first));
    if (!in.read(reinterpret_cast<char*>(offsets.data()), std::streamsize(count * sizeof(uint64_t))))
      refuse_exr(file, "its chunk offset table ends with the file");
    for (size_t i = 0; i < count; ++i)
      if (offsets[i] < table_end || offsets[i] > file_bytes - chunk_min)
        refuse_exr(file, "its chunk offset table points outside the file: block " + std::to_string(first + i) + " at byte " +
                         std::to_string(offsets[i]) + " of a file of " + bytes_text(file_bytes) + " (the table ends at byte " +
                         std::to_string(table_end) + ")");
  }
  return rows_per_read * std::max(1, (64 + rows_per_read - 1) / rows_per_read);
}

}  // namespace

void refuse_exr(const std::filesystem::path& file, const std::string& why) { throw InputError(file.string() + ": " + why); }

int check_exr_header(std::ifstream& in, const std::filesystem::path& file, uint64_t file_bytes) {
  // OpenEXR's own checks of a header, as a second line: vkray's limits.
  static std::once_flag limits;
  std::call_once(limits, [] {
    Imf::Header::setMaxImageSize(int(kMaxImageSide), int(kMaxImageSide));
    Imf::Header::setMaxTileSize(int(kMaxImageSide), int(kMaxImageSide));
  });
  const HeaderLayout layout = walk_header(in, file, file_bytes);
  Imf::StdIFStream stream(in, file.c_str());
  stream.seekg(8);
  Imf::Header header;
  int version = layout.version;
  header.readFrom(stream, version);
  const int band_rows = check_claims(header, layout, in, file, file_bytes);
  header.sanityCheck(Imf::isTiled(layout.version));
  return band_rows;
}

}  // namespace vkray
