#include "image/part.h"

#include <algorithm>
#include <memory>

#include <nlohmann/json.hpp>

#include "base/atomic_file.h"
#include "base/errors.h"
#include "base/hash.h"
#include "base/input_file.h"
#include "image/image_file.h"

namespace vkray {
namespace {

// A record is a few hundred bytes; anything much larger is not one.
constexpr uint64_t kMaxRecordBytes = 64 << 10;

// Every key of a record, in the order written. A record of an older build lacks the later ones.
const char* const kRecordKeys[] = {"scene_digest", "width", "height", "region", "spp", "seed", "vkray_version", "device",
                                   "shader", "pixels", "hash"};

std::string pfm_pixels_hash(const Image& image) {
  return hash_hex(image.pixels.data(), image.pixels.size() * sizeof(glm::vec3));
}

}  // namespace

std::string part_record_hash(const PartRecord& r) {
  const auto hasher = std::make_unique<Hasher>();
  hasher->add(std::string("vkray part record"));  // not the hash of anything else with these fields
  hasher->add(r.scene_digest);
  for (const uint32_t number : {r.width, r.height, r.region.x0, r.region.y0, r.region.x1, r.region.y1, r.samples_per_pixel, r.seed})
    hasher->add(number);
  for (const std::string* text : {&r.version, &r.device, &r.shader, &r.pixels}) hasher->add(*text);
  return hasher->hex();
}

std::string part_record_json(const PartRecord& r) {
  const nlohmann::ordered_json json = {
      {"scene_digest", r.scene_digest},
      {"width", r.width},
      {"height", r.height},
      {"region", {r.region.x0, r.region.y0, r.region.x1, r.region.y1}},
      {"spp", r.samples_per_pixel},
      {"seed", r.seed},
      {"vkray_version", r.version},
      {"device", r.device},
      {"shader", r.shader},
      {"pixels", r.pixels},
      {"hash", r.hash},
  };
  return json.dump();
}

PartRecord parse_part_record(const std::string& text, const std::filesystem::path& file) {
  const std::string where = file.string() + ": the part's record";
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (json.is_discarded() || !json.is_object()) throw InputError(where + " is not a JSON object");
  // A part of another build records other things: say so, rather than only what is missing.
  const std::string version = json.contains("vkray_version") && json["vkray_version"].is_string()
                                  ? json["vkray_version"].get<std::string>()
                                  : "";
  const std::string other_build =
      version.empty() ? "" : " (it was written by vkray " + printable(version) + ": render the part again with this build)";
  for (const char* key : kRecordKeys)
    if (!json.contains(key)) throw InputError(where + " has no \"" + key + "\"" + other_build);
  for (const auto& [key, value] : json.items())
    if (std::find(std::begin(kRecordKeys), std::end(kRecordKeys), key) == std::end(kRecordKeys))
      throw InputError(where + " has a key \"" + printable(key) + "\" that this build does not record" + other_build);
  const auto text_of = [&](const char* key) {
    if (!json[key].is_string()) throw InputError(where + ": \"" + key + "\" is not a string");
    return json[key].get<std::string>();
  };
  const auto number_of = [&](const nlohmann::json& value, const std::string& key) {
    if (!value.is_number_unsigned() || value.get<uint64_t>() > UINT32_MAX)
      throw InputError(where + ": \"" + key + "\" is not a whole number from 0 to 2^32 - 1");
    return value.get<uint32_t>();
  };
  PartRecord r;
  r.scene_digest = text_of("scene_digest");
  r.width = number_of(json["width"], "width");
  r.height = number_of(json["height"], "height");
  const nlohmann::json& region = json["region"];
  if (!region.is_array() || region.size() != 4) throw InputError(where + ": \"region\" is not [x0, y0, x1, y1]");
  r.region = {number_of(region[0], "region"), number_of(region[1], "region"), number_of(region[2], "region"),
              number_of(region[3], "region")};
  r.samples_per_pixel = number_of(json["spp"], "spp");
  r.seed = number_of(json["seed"], "seed");
  r.version = text_of("vkray_version");
  r.device = text_of("device");
  r.shader = text_of("shader");
  r.pixels = text_of("pixels");
  r.hash = text_of("hash");
  if (r.width == 0 || r.height == 0 || r.width > kMaxImageSide || r.height > kMaxImageSide)
    throw InputError(where + ": an image of " + std::to_string(r.width) + " x " + std::to_string(r.height) + " pixels");
  if (!r.region.within(r.width, r.height))
    throw InputError(where + ": region " + to_string(r.region) + " does not lie within the " + std::to_string(r.width) +
                     " x " + std::to_string(r.height) + " image");
  if (part_record_hash(r) != r.hash)
    throw InputError(where + " is not as vkray " + printable(r.version) + " wrote it: its fields do not match its \"hash\" "
                     "(a field was changed; render the part again)");
  return r;
}

std::filesystem::path sidecar_of(const std::filesystem::path& pfm) {
  std::filesystem::path sidecar = pfm;
  sidecar += ".json";
  return sidecar;
}

void write_part(const std::filesystem::path& file, const Image& image, const Aovs* aovs, const OutputContent& content,
                const PartRecord& record) {
  if (image.width != record.region.width() || image.height != record.region.height())
    throw InternalError(file.string() + ": a part's pixels do not fit its region");
  const auto sealed = [&](const std::string& pixels_hash) {
    PartRecord r = record;
    r.pixels = pixels_hash;
    r.hash = part_record_hash(r);
    return part_record_json(r);
  };
  if (is_exr(file)) {
    const ExrPartHeader part{record.width, record.height, record.region, sealed};
    return write_exr(file, image, aovs, content, &part);
  }
  if (!is_pfm(file))
    throw UsageError(file.string() + ": a part of a render is an .exr or a .pfm file, so that `vkray merge` can assemble it");
  check_render_image(file, content);
  // Both written in full, then both renamed: the old pair stays whole until the new one is.
  AtomicFile pixels(file), sidecar(sidecar_of(file));
  write_pfm(image, pixels);
  const std::string json = sealed(pfm_pixels_hash(image)) + "\n";
  std::fwrite(json.data(), 1, json.size(), sidecar.get());
  AtomicFile::commit_together({&pixels, &sidecar});
}

namespace {

// The checks every part passes, whatever its file type: its pixels are of its region's size and are
// those its record (named `record_name`) was written with.
void check_pixels(const Part& part, const std::string& pixels_hash, const std::string& record_name) {
  const PixelRegion& region = part.record.region;
  if (part.image.width != region.width() || part.image.height != region.height())
    throw InputError(part.file.string() + ": " + std::to_string(part.image.width) + " x " + std::to_string(part.image.height) +
                     " pixels, but its record names region " + to_string(region));
  if (pixels_hash != part.record.pixels)
    throw InputError(part.file.string() + ": its pixels are not the ones its record " + record_name +
                     " was written with (the image was written again or changed after the record, or the record is another "
                     "part's)");
}

}  // namespace

Part read_part(const std::filesystem::path& file) {
  Part part;
  part.file = file;
  if (is_exr(file)) {
    ExrFile exr = read_exr(file);
    if (exr.window.part_record.empty())
      throw InputError(file.string() + ": not a part of a render (no \"vkray.part\" attribute): render parts with "
                                       "`vkray render --region`");
    part.record = parse_part_record(exr.window.part_record, file);
    if (exr.window.full_width == 0)
      throw InputError(file.string() + ": its display window does not start at 0,0 or does not hold its data window, "
                                       "as a part's does");
    if (exr.window.full_width != part.record.width || exr.window.full_height != part.record.height ||
        exr.window.region != part.record.region)
      throw InputError(file.string() + ": the data window " + to_string(exr.window.region) + " of a " +
                       std::to_string(exr.window.full_width) + " x " + std::to_string(exr.window.full_height) +
                       " display window is not the region its record names");
    part.exr = true;
    part.image = std::move(exr.image);
    if (!exr.content.passes.empty()) part.aovs = std::move(exr.aovs);
    part.content = exr.content;
    check_pixels(part, exr.pixels_hash, "(attribute \"vkray.part\")");
    return part;
  }
  if (!is_pfm(file))
    throw InputError(file.string() + ": not a part of a render: parts are the .exr or .pfm files `vkray render --region` writes");
  const std::filesystem::path sidecar = sidecar_of(file);
  const InputFile record = read_input_file(sidecar, kMaxRecordBytes);
  if (!record.error.empty())
    throw InputError(sidecar.string() + ": " + record.error + " (a PFM part's record, which `vkray render --region` writes beside it)");
  part.record = parse_part_record(record.text, sidecar);
  part.image = read_pfm(file);
  check_pixels(part, pfm_pixels_hash(part.image), sidecar.filename().string());
  return part;
}

}  // namespace vkray
