#include "image/exr.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <mutex>
#include <string>
#include <thread>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>

#include "base/atomic_file.h"
#include "base/errors.h"
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

// Where pass `pass`'s channel c lives in `aovs`, and the stride from one pixel to the next.
std::pair<char*, size_t> pass_values(Aovs& aovs, Aov pass, int c) {
  switch (pass) {
    case Aov::albedo: return {reinterpret_cast<char*>(&aovs.albedo[0][c]), sizeof(glm::vec3)};
    case Aov::normal: return {reinterpret_cast<char*>(&aovs.normal[0][c]), sizeof(glm::vec3)};
    case Aov::position: return {reinterpret_cast<char*>(&aovs.position[0][c]), sizeof(glm::vec3)};
    case Aov::depth: return {reinterpret_cast<char*>(aovs.depth.data()), sizeof(float)};
    case Aov::object: return {nullptr, sizeof(float)};  // ids are converted through a float copy
  }
  return {nullptr, 0};
}

}  // namespace

void write_exr(const std::filesystem::path& file, const Image& image, const Aovs* aovs, const ExrContent& content,
               const ExrWindow* window) {
  if (!content.passes.empty() && (!aovs || aovs->width != image.width || aovs->height != image.height))
    throw InternalError(file.string() + ": first-hit passes asked for without passes of the image's size");
  if (image.width == 0 || image.height == 0) throw OutputError(file.string() + ": an EXR image cannot be empty");
  const PixelRegion region = window ? window->region : full_region(image.width, image.height);
  if (window && (region.width() != image.width || region.height() != image.height || !region.within(window->full_width, window->full_height)))
    throw InternalError(file.string() + ": a part's pixels do not fit its region");
  const auto box = [](const PixelRegion& r) {
    return Imath::Box2i(Imath::V2i(int(r.x0), int(r.y0)), Imath::V2i(int(r.x1) - 1, int(r.y1) - 1));
  };
  Imf::Header header(window ? box(full_region(window->full_width, window->full_height)) : box(region), box(region));
  header.compression() = Imf::ZIP_COMPRESSION;
  header.insert("software", Imf::StringAttribute("vkray"));
  if (window && !window->part_record.empty()) header.insert("vkray.part", Imf::StringAttribute(window->part_record));
  // Slices are addressed as if the buffer started at the display window's origin.
  const auto at_origin = [&](char* base, size_t stride) {
    return base - (int64_t(region.x0) + int64_t(region.y0) * int64_t(image.width)) * int64_t(stride);
  };
  // Each channel in a plane of its own, of the type it has in the file (OpenEXR converts types when
  // it reads, not when it writes).
  const size_t pixels = image.pixels.size();
  std::vector<std::vector<float>> floats;
  std::vector<std::vector<Imath::half>> halves;
  floats.reserve(3 + 3 * content.passes.size());  // planes must not move once the frame buffer points at them
  halves.reserve(3 + 3 * content.passes.size());
  Imf::FrameBuffer frame;
  const auto add = [&](const std::string& name, bool full_float, auto value) {
    if (full_float) {
      std::vector<float>& plane = floats.emplace_back(pixels);
      for (size_t i = 0; i < pixels; ++i) plane[i] = value(i);
      header.channels().insert(name, Imf::Channel(Imf::FLOAT));
      frame.insert(name, Imf::Slice(Imf::FLOAT, at_origin(reinterpret_cast<char*>(plane.data()), sizeof(float)), sizeof(float),
                                    sizeof(float) * image.width));
    } else {
      std::vector<Imath::half>& plane = halves.emplace_back(pixels);
      for (size_t i = 0; i < pixels; ++i) plane[i] = Imath::half(value(i));
      header.channels().insert(name, Imf::Channel(Imf::HALF));
      frame.insert(name, Imf::Slice(Imf::HALF, at_origin(reinterpret_cast<char*>(plane.data()), sizeof(Imath::half)),
                                    sizeof(Imath::half), sizeof(Imath::half) * image.width));
    }
  };
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
  } catch (const std::exception& e) {
    throw OutputError(file.string() + ": EXR write failed: " + e.what());
  }
  out.commit();
}

ExrFile read_exr(const std::filesystem::path& file) {
  // OpenEXR allocates line buffers for the data window as it opens a file, before vkray sees the
  // header: a small file claiming a huge width must be refused by OpenEXR's own header check.
  static std::once_flag limits;
  std::call_once(limits, [] {
    Imf::Header::setMaxImageSize(int(kMaxImageSide), int(kMaxImageSide));
    Imf::Header::setMaxTileSize(int(kMaxImageSide), int(kMaxImageSide));
  });
  ExrFile result;
  try {
    Imf::InputFile exr(file.c_str());
    const Imath::Box2i window = exr.header().dataWindow();
    const int64_t w = int64_t(window.max.x) - window.min.x + 1, h = int64_t(window.max.y) - window.min.y + 1;
    // Checked before anything is allocated for it: a small file can claim a huge window.
    if (w <= 0 || h <= 0 || w > kMaxImageSide || h > kMaxImageSide)
      throw InputError(file.string() + ": an EXR data window of " + std::to_string(w) + " x " + std::to_string(h) +
                       " pixels (vkray reads up to " + std::to_string(kMaxImageSide) + " on a side)");
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
    for (const char* name : {"R", "G", "B"})
      if (!channels.findChannel(name)) throw InputError(file.string() + ": no channel " + name);
    result.content.full_float = channels.findChannel("R")->type == Imf::FLOAT;
    result.image = Image(uint32_t(w), uint32_t(h));
    const bool any_pass = std::any_of(kAllAovs.begin(), kAllAovs.end(),
                                      [&](Aov pass) { return channels.findChannel(channel_name(layer_of(pass), 0)); });
    if (any_pass) result.aovs = Aovs(uint32_t(w), uint32_t(h));
    // Slices are addressed as if the buffer started at the data window's origin.
    const auto origin = [&](char* base, size_t stride) { return base - (int64_t(window.min.x) + int64_t(window.min.y) * w) * int64_t(stride); };
    Imf::FrameBuffer frame;
    const size_t row = sizeof(glm::vec3) * size_t(w);
    char* pixels = reinterpret_cast<char*>(result.image.pixels.data());
    for (int c = 0; c < 3; ++c)
      frame.insert(std::string(1, "RGB"[c]), Imf::Slice(Imf::FLOAT, origin(pixels + c * sizeof(float), sizeof(glm::vec3)), sizeof(glm::vec3), row));
    std::vector<float> object_ids(any_pass ? size_t(w * h) : 0, -1.0f);
    for (const Aov pass : kAllAovs) {
      const Layer layer = layer_of(pass);
      if (!channels.findChannel(channel_name(layer, 0))) continue;
      result.content.passes.push_back(pass);
      for (int c = 0; c < layer.channels; ++c) {
        auto [base, stride] = pass_values(result.aovs, pass, c);
        if (pass == Aov::object) base = reinterpret_cast<char*>(object_ids.data());
        frame.insert(channel_name(layer, c), Imf::Slice(Imf::FLOAT, origin(base, stride), stride, stride * size_t(w)));
      }
    }
    exr.setFrameBuffer(frame);
    exr.readPixels(window.min.y, window.max.y);
    for (size_t i = 0; i < object_ids.size(); ++i) {  // ids are whole numbers from -1 up; anything else is no id
      const float id = object_ids[i];
      result.aovs.object[i] = id >= 0.0f && id < 2147483648.0f && id == std::floor(id) ? int32_t(id) : -1;
    }
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(file.string() + ": " + e.what());
  }
  return result;
}

}  // namespace vkray
