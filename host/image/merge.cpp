#include "image/merge.h"

#include <sys/stat.h>

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "base/errors.h"
#include "image/image_file.h"

namespace vkray {
namespace {

std::string size_text(uint32_t width, uint32_t height) { return std::to_string(width) + " x " + std::to_string(height); }

std::string pass_names(const OutputContent& content) {
  std::string names;
  for (const Aov pass : content.passes) {
    if (!names.empty()) names += ',';
    names += aov_name(pass);
  }
  return names.empty() ? "none" : names;
}

// Why `part` cannot join a render whose first part is `first`; empty when it can.
std::string mismatch(const Part& first, const Part& part) {
  const PartRecord &a = first.record, &b = part.record;
  const auto differ = [](const char* what, const std::string& x, const std::string& y) {
    return std::string(what) + " " + y + ", not " + x;
  };
  if (a.scene_digest != b.scene_digest) return differ("is of another scene: digest", a.scene_digest, b.scene_digest);
  if (a.width != b.width || a.height != b.height)
    return differ("is of an image of", size_text(a.width, a.height), size_text(b.width, b.height));
  if (a.samples_per_pixel != b.samples_per_pixel)
    return differ("has samples per pixel", std::to_string(a.samples_per_pixel), std::to_string(b.samples_per_pixel));
  if (a.seed != b.seed) return differ("has seed", std::to_string(a.seed), std::to_string(b.seed));
  if (a.version != b.version) return differ("was rendered by vkray", a.version, b.version);
  if (first.content.passes != part.content.passes)
    return differ("has first-hit passes", pass_names(first.content), pass_names(part.content));
  if (first.exr != part.exr || first.content.full_float != part.content.full_float) {
    const auto kind = [](const Part& p) { return std::string(!p.exr ? "PFM" : p.content.full_float ? "32-bit EXR" : "half-float EXR"); };
    return differ("is a", kind(first), kind(part));
  }
  return "";
}

// Copies a part's pixels (and passes) into the whole image at its region.
void place(const Part& part, MergedImage& merged) {
  const PixelRegion& r = part.record.region;
  const uint32_t w = merged.image.width;
  for (uint32_t y = 0; y < r.height(); ++y) {
    const size_t from = size_t(y) * r.width(), to = size_t(r.y0 + y) * w + r.x0;
    std::copy_n(part.image.pixels.begin() + from, r.width(), merged.image.pixels.begin() + to);
    if (!merged.aovs) continue;
    const Aovs& a = *part.aovs;
    Aovs& m = *merged.aovs;
    std::copy_n(a.albedo.begin() + from, r.width(), m.albedo.begin() + to);
    std::copy_n(a.normal.begin() + from, r.width(), m.normal.begin() + to);
    std::copy_n(a.position.begin() + from, r.width(), m.position.begin() + to);
    std::copy_n(a.depth.begin() + from, r.width(), m.depth.begin() + to);
    std::copy_n(a.object.begin() + from, r.width(), m.object.begin() + to);
  }
}

// Refuses overlaps and gaps. Coverage changes only at rows where a part starts or ends, so those
// rows are the only ones checked: at each, the parts across it, left to right, must abut.
void check_tiling(const std::vector<Part>& parts, uint32_t width, uint32_t height) {
  std::set<uint32_t> rows{0};
  for (const Part& p : parts) rows.insert({p.record.region.y0, p.record.region.y1});
  std::vector<const Part*> across;
  for (const uint32_t y : rows) {
    if (y >= height) break;
    across.clear();
    for (const Part& p : parts)
      if (p.record.region.y0 <= y && y < p.record.region.y1) across.push_back(&p);
    std::sort(across.begin(), across.end(), [](const Part* a, const Part* b) { return a->record.region.x0 < b->record.region.x0; });
    uint32_t x = 0;  // columns left of x are covered on row y
    for (size_t i = 0; i < across.size(); ++i) {
      const PixelRegion& r = across[i]->record.region;
      if (r.x0 < x) {
        const PixelRegion& q = across[i - 1]->record.region;
        const PixelRegion overlap{std::max(r.x0, q.x0), std::max(r.y0, q.y0), std::min(r.x1, q.x1), std::min(r.y1, q.y1)};
        throw InputError(across[i]->file.string() + ": its region " + to_string(r) + " overlaps region " + to_string(q) +
                         " of " + across[i - 1]->file.string() + " (pixels " + to_string(overlap) + ")");
      }
      if (r.x0 > x) break;
      x = r.x1;
    }
    if (x < width) {
      uint32_t end = width;  // the gap runs to the next part on the row, or the edge
      for (const Part* p : across)
        if (p->record.region.x0 > x) end = std::min(end, p->record.region.x0);
      throw InputError("no part covers pixels " + std::to_string(x) + " to " + std::to_string(end - 1) + " of row " +
                       std::to_string(y) + " of the " + size_text(width, height) + " image");
    }
  }
}

// A file as the system knows it, whatever path names it: another spelling, a symbolic link (followed)
// or a hard link names the same file. None when nothing is there.
using FileId = std::pair<dev_t, ino_t>;
std::optional<FileId> file_id(const std::filesystem::path& file) {
  struct stat info {};
  if (::stat(file.c_str(), &info) != 0) return std::nullopt;
  return FileId{info.st_dev, info.st_ino};
}

// Refuses an output that is one of the parts or a PFM part's record (the merge would replace what it
// reads, and a part would be lost), and a part given twice.
void check_files(const std::filesystem::path& output, const std::vector<std::filesystem::path>& parts) {
  std::map<FileId, std::filesystem::path> inputs;  // each part and PFM record, by what it is
  for (const auto& part : parts) {
    const std::optional<FileId> id = file_id(part);
    if (!id) continue;  // read_part says what is wrong with it
    const auto [at, added] = inputs.emplace(*id, part);
    if (!added) throw InputError(part.string() + ": is given twice (also as " + at->second.string() + ")");
    if (!is_pfm(part)) continue;
    const std::filesystem::path record = sidecar_of(part);
    if (const std::optional<FileId> record_id = file_id(record)) inputs.emplace(*record_id, record);
  }
  const std::optional<FileId> out = file_id(output);
  if (!out) return;
  const auto input = inputs.find(*out);
  if (input != inputs.end())
    throw OutputError(output.string() + ": is " + (input->second == output ? std::string("a part being merged")
                                                                           : input->second.string() + ", which is being merged") +
                      " (the same file): the merge would replace it; name another output");
}

}  // namespace

MergedImage merge_parts(const std::vector<Part>& parts) {
  if (parts.empty()) throw InputError("no parts to merge");
  const Part& first = parts.front();
  for (const Part& part : parts) {
    const std::string why = mismatch(first, part);
    if (!why.empty()) throw InputError(part.file.string() + ": " + why + " as " + first.file.string() + " is");
  }
  // Shaders edited between parts (a --shader-dir, `vkray watch`'s edits) make another image. A CPU
  // reference part has none and may join GPU parts (within parity, as the merge then warns), so
  // the GPU parts are held to the first of them.
  const Part* traced = nullptr;
  for (const Part& part : parts) {
    if (part.record.shader.empty()) continue;
    if (!traced) traced = &part;
    if (part.record.shader != traced->record.shader)
      throw InputError(part.file.string() + ": was traced by other shaders: SPIR-V " + part.record.shader + ", not " +
                       traced->record.shader + " as " + traced->file.string() + " was");
  }
  MergedImage merged;
  merged.record = first.record;
  merged.record.region = full_region(first.record.width, first.record.height);
  merged.content = first.content;
  for (const Part& part : parts)
    merged.mixed_devices |= part.record.device != first.record.device;
  check_tiling(parts, first.record.width, first.record.height);
  merged.image = Image(first.record.width, first.record.height);
  if (!first.content.passes.empty()) merged.aovs.emplace(first.record.width, first.record.height);
  for (const Part& part : parts) place(part, merged);
  return merged;
}

MergeSummary merge_part_files(const std::filesystem::path& output, const std::vector<std::filesystem::path>& files) {
  check_output_image(output);
  check_files(output, files);
  std::vector<Part> parts;
  parts.reserve(files.size());
  for (const auto& file : files) parts.push_back(read_part(file));
  const MergedImage merged = merge_parts(parts);
  MergeSummary summary;
  summary.parts = parts.size();
  summary.record = merged.record;
  summary.mixed_devices = merged.mixed_devices;
  if (is_exr(output)) {
    write_exr(output, merged.image, merged.aovs ? &*merged.aovs : nullptr, merged.content);
  } else {
    summary.passes_dropped = !merged.content.passes.empty();
    write_image(merged.image, output);
  }
  return summary;
}

}  // namespace vkray
