#include "image/part.h"

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

const char* const kRecordKeys[] = {"scene_digest", "width", "height", "region", "spp", "seed", "vkray_version", "device", "shader"};

std::string pixels_hash(const Image& image) {
  return hash_hex(image.pixels.data(), image.pixels.size() * sizeof(glm::vec3));
}

}  // namespace

std::string part_record_json(const PartRecord& r) {
  nlohmann::ordered_json json = {
      {"scene_digest", r.scene_digest},
      {"width", r.width},
      {"height", r.height},
      {"region", {r.region.x0, r.region.y0, r.region.x1, r.region.y1}},
      {"spp", r.samples_per_pixel},
      {"seed", r.seed},
      {"vkray_version", r.version},
      {"device", r.device},
      {"shader", r.shader},
  };
  if (!r.pixels.empty()) json["pixels"] = r.pixels;
  return json.dump();
}

PartRecord parse_part_record(const std::string& text, const std::filesystem::path& file) {
  const std::string where = file.string() + ": the part's record";
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (json.is_discarded() || !json.is_object()) throw InputError(where + " is not a JSON object");
  // A part of an older build lacks what later builds record: say so, rather than only what is missing.
  const std::string older = json.contains("vkray_version") && json["vkray_version"].is_string()
                                ? " (it was written by vkray " + json["vkray_version"].get<std::string>() +
                                      ": render the part again with this build)"
                                : "";
  for (const char* key : kRecordKeys)
    if (!json.contains(key)) throw InputError(where + " has no \"" + key + "\"" + older);
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
  if (json.contains("pixels")) r.pixels = text_of("pixels");
  if (r.width == 0 || r.height == 0 || r.width > kMaxImageSide || r.height > kMaxImageSide)
    throw InputError(where + ": an image of " + std::to_string(r.width) + " x " + std::to_string(r.height) + " pixels");
  if (!r.region.within(r.width, r.height))
    throw InputError(where + ": region " + to_string(r.region) + " does not lie within the " + std::to_string(r.width) +
                     " x " + std::to_string(r.height) + " image");
  return r;
}

std::filesystem::path sidecar_of(const std::filesystem::path& pfm) {
  std::filesystem::path sidecar = pfm;
  sidecar += ".json";
  return sidecar;
}

void write_part(const std::filesystem::path& file, const Image& image, const Aovs* aovs, const ExrContent& content,
                const PartRecord& record) {
  if (is_exr(file)) {
    const ExrWindow window{record.width, record.height, record.region, part_record_json(record)};
    return write_exr(file, image, aovs, content, &window);
  }
  if (!is_pfm(file))
    throw UsageError(file.string() + ": a part of a render is an .exr or a .pfm file, so that `vkray merge` can assemble it");
  check_render_image(file, content);
  PartRecord pfm_record = record;
  pfm_record.pixels = pixels_hash(image);
  const std::filesystem::path sidecar = sidecar_of(file);
  write_file_atomically(sidecar, part_record_json(pfm_record) + "\n");
  try {
    write_image(image, file);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(sidecar, ignored);
    throw;
  }
}

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
    return part;
  }
  if (!is_pfm(file))
    throw InputError(file.string() + ": not a part of a render: parts are the .exr or .pfm files `vkray render --region` writes");
  const std::filesystem::path sidecar = sidecar_of(file);
  const InputFile record = read_input_file(sidecar, kMaxRecordBytes);
  if (!record.error.empty())
    throw InputError(sidecar.string() + ": " + record.error + " (a PFM part's record, which `vkray render --region` writes beside it)");
  part.record = parse_part_record(record.text, sidecar);
  if (part.record.pixels.empty())
    throw InputError(sidecar.string() + ": the part's record has no \"pixels\", which a PFM part's record has (it was "
                     "written by vkray " + part.record.version + ": render the part again with this build)");
  part.image = read_pfm(file);
  if (part.image.width != part.record.region.width() || part.image.height != part.record.region.height())
    throw InputError(file.string() + ": " + std::to_string(part.image.width) + " x " + std::to_string(part.image.height) +
                     " pixels, but its record names region " + to_string(part.record.region));
  if (pixels_hash(part.image) != part.record.pixels)
    throw InputError(file.string() + ": its pixels are not the ones its record " + sidecar.filename().string() +
                     " was written with (the image was written again, or changed, after the record)");
  return part;
}

}  // namespace vkray
