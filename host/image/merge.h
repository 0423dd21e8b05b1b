// `vkray merge`: parts of one render (image/part.h) assembled into the whole image, exactly: each
// pixel is the part's value, so parts rendered by one build on one device give the bytes a single
// render gives. Parts of different renders are refused, as are overlaps and gaps.
#pragma once

#include <optional>
#include <vector>

#include "image/aovs.h"
#include "image/exr.h"
#include "image/image.h"
#include "image/part.h"

namespace vkray {

struct MergedImage {
  Image image;
  std::optional<Aovs> aovs;  // when the parts have passes
  OutputContent content;        // the parts' passes and precision: an EXR output written with it
  PartRecord record;         // the first part's record, region the whole image
  // Parts were rendered on more than one device (the CPU reference counts as one): the image is within parity of a
  // single render, not bit-identical to one (docs/distributed.md).
  bool mixed_devices = false;
};

// Throws InputError naming the part and what differs: no parts; a part of another scene, image
// size, sample count, seed or vkray version than the first; different passes or file type; two
// parts that overlap (both named, with the pixels they share); pixels no part covers (the first
// such row, and its columns).
MergedImage merge_parts(const std::vector<Part>& parts);

struct MergeSummary {
  size_t parts = 0;
  PartRecord record;           // MergedImage::record
  bool mixed_devices = false;  // MergedImage::mixed_devices
  bool passes_dropped = false;  // the parts have first-hit passes, which only an .exr output keeps
};

// What `vkray merge` does: reads the part files (read_part), merges them and writes the whole image
// to `output` (.png, .pfm or .exr, with the parts' passes and precision), which is written only when
// all of this succeeded. Throws OutputError for an output check_output_image refuses or that is one
// of the parts or their records (compared as files: another spelling or a link of one is one),
// InputError (a part given twice, and as merge_parts and read_part), LimitError.
MergeSummary merge_part_files(const std::filesystem::path& output, const std::vector<std::filesystem::path>& parts);

}  // namespace vkray
