// A part of a render (`vkray render --region`), and what it records about the render it belongs to,
// so that `vkray merge` assembles only parts of one render (image/merge.h). An EXR part keeps the
// record in its header (attribute "vkray.part", the JSON below) and its region as the data window
// within the full image's display window, as pbrt's `imgtool assemble` expects; a PFM part keeps
// the record in a sidecar file, PART.pfm.json. A record is tamper-evident: it holds the hash of its
// pixels and a hash of all its fields, so an edited field, a record beside another part's pixels
// and pixels written again under the record are refused. (The hashes catch mistakes, not forgeries:
// base/hash.h.)
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "image/aovs.h"
#include "image/exr.h"
#include "image/image.h"
#include "image/region.h"

namespace vkray {

struct PartRecord {
  std::string scene_digest;  // scene/digest.h
  uint32_t width = 0, height = 0;  // the full image
  PixelRegion region;               // the part's pixels, within it
  uint32_t samples_per_pixel = 0;
  uint32_t seed = 0;
  std::string version;   // vkray's version_string(): parts of different builds may differ in the last bit
  std::string device;    // "name (driver)", or "CPU reference": only parts of one device are bit-identical
  std::string shader;    // the hash (base/hash.h) of the SPIR-V that traced it; empty: the CPU reference
  // The hash of the part's pixels as its file stores them: a PFM's floats (3 a pixel, top row
  // first), an EXR's channels (ExrFile::pixels_hash).
  std::string pixels;
  // part_record_hash of the fields above: what makes an edit of any of them evident.
  std::string hash;
};

// The hash of every field of `record` but `hash` itself.
std::string part_record_hash(const PartRecord& record);

// The record as one line of JSON, and back. parse_part_record throws InputError naming `file` and
// the key that is missing, unknown or wrong (a record of another build: saying to render the part
// again), or saying that the fields are not those the record's hash was made of.
std::string part_record_json(const PartRecord& record);
PartRecord parse_part_record(const std::string& text, const std::filesystem::path& file);

// Where a PFM part's record lives: "x.pfm" -> "x.pfm.json".
std::filesystem::path sidecar_of(const std::filesystem::path& pfm);

// Writes a part: an EXR (with the record and the data window; `content` as for write_exr) or a PFM
// and its sidecar, both written in full before either replaces a file, then renamed into place
// together (AtomicFile::commit_together): a write that fails leaves an earlier part and its record as
// they were. Completes `record` with its hashes. Throws UsageError for another file type,
// OutputError, LimitError.
void write_part(const std::filesystem::path& file, const Image& image, const Aovs* aovs, const OutputContent& content,
                const PartRecord& record);

struct Part {
  std::filesystem::path file;
  PartRecord record;
  Image image;               // the region's pixels
  std::optional<Aovs> aovs;  // an EXR part's passes (content.passes), of the region's size
  OutputContent content;        // the passes and the precision of an EXR part; PFM: none, 32-bit
  bool exr = false;
};

// Reads a part written by write_part. Throws InputError naming the file: not a part (a PNG, an EXR
// without the record, a PFM without its sidecar), a record edited after it was written, a record
// that does not match the pixels (their region or size; pixels written again after the record, or a
// record beside another part's pixels); LimitError.
Part read_part(const std::filesystem::path& file);

}  // namespace vkray
