// write_exr (exr.h): an image and its first-hit passes as the channels of an OpenEXR file, each in
// the type it is stored in, through an AtomicFile so that a failed write leaves no file; a part's
// record is made from the hash of those stored planes (exr_channels.h), the same bytes read_exr
// hashes when it reads the file back.
#include "image/exr.h"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>

#include "base/atomic_file.h"
#include "base/errors.h"
#include "base/interrupt.h"
#include "base/threads.h"
#include "image/exr_channels.h"

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

// Each channel in a plane of its own, of the type it has in the file (OpenEXR converts types when it
// reads, not when it writes).
struct WrittenPlanes {
  std::vector<std::vector<float>> floats;
  std::vector<std::vector<Imath::half>> halves;
  std::vector<StoredPlane> stored;
};

WrittenPlanes written_planes(const Image& image, const Aovs* aovs, const OutputContent& content) {
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
    const ExrLayer layer = exr_layer_of(pass);
    for (int c = 0; c < layer.channels; ++c) {
      const std::string name = exr_channel_name(layer, c);
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

void write_exr(const std::filesystem::path& file, const Image& image, const Aovs* aovs, const OutputContent& content,
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
    const size_t size = exr_bytes_of(plane.type);
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

}  // namespace vkray
