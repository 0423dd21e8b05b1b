// A render written to its file, whichever face asked for it: the whole image as it is, a region
// (RenderOptions::region) as a part of the whole (image/part.h) that records what it was rendered
// from, for `vkray merge`.
#pragma once

#include <filesystem>
#include <string>

#include "image/exr.h"
#include "image/part.h"
#include "scene/scene.h"
#include "session/options.h"

namespace vkray {

// The device a part rendered by the CPU reference records.
constexpr const char* kCpuReferenceDevice = "CPU reference";

// Throws the UsageError write_render would for a part, before any work is done.
void check_part_file(const std::filesystem::path& file);

// Everything write_render would refuse of `file`, checked before any work is done, in the order
// every face reports it: the path (OutputError, image_file.h's check_output_image), then what is
// asked of it (UsageError: passes or 32-bit floats outside an .exr, a `part` outside .exr/.pfm).
void check_render_output(const std::filesystem::path& file, const OutputContent& content, bool part);

// What `result`, a render of `scene`, was rendered from. `device`: Session::device_description(), or
// kCpuReferenceDevice.
PartRecord part_record(const Scene& scene, const RenderResult& result, const std::string& device);

// Throws InternalError, naming how many and the first, when pixels of `result` are not finite: both
// renderers hold every value within the float range (docs/limits.md, "Floats on the GPU"), so one
// that is not is a fault of the shaders or the driver, never an image to deliver. Every face checks
// what it hands over here (write_render does).
void check_finite(const RenderResult& result);

// Writes `result` to `file` (.png, .pfm or .exr; `content`: the passes and precision of an .exr); a
// region of the image as a part (write_part: .exr or .pfm, else UsageError; a part and its record
// replace an earlier pair together or not at all). Throws OutputError, LimitError, and check_finite's
// InternalError before anything is written.
void write_render(const std::filesystem::path& file, const Scene& scene, const RenderResult& result, const OutputContent& content,
                  const std::string& device);

// Whether `result` is a part of a render (RenderOptions::region), written with its record.
inline bool is_part(const RenderResult& result) { return result.part; }

}  // namespace vkray
