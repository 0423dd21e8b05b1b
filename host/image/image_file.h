// An image file's type by its extension, and the writer for it: the one place that maps ".png",
// ".pfm" and ".exr" to PNG (image.h), PFM (image.h) and OpenEXR (exr.h).
#pragma once

#include <filesystem>
#include <optional>

#include "image/aovs.h"
#include "image/exr.h"
#include "image/image.h"

namespace vkray {

enum class ImageFileType { png, pfm, exr };

// The type of `file` by its extension, in any case; nullopt for any other.
std::optional<ImageFileType> image_file_type(const std::filesystem::path& file);

bool is_supported_image_path(const std::filesystem::path& file);
bool is_pfm(const std::filesystem::path& file);
bool is_exr(const std::filesystem::path& file);

// Writes by extension: ".png" (8-bit sRGB through `display`), ".pfm" (32-bit float linear, rows bottom to top,
// little-endian) or ".exr" (16-bit half float linear RGB; write_exr for more). The file is written
// under a temporary name in the same folder and renamed into place, so a failure never leaves a
// partial image. Throws OutputError.
void write_image(const Image& image, const std::filesystem::path& file, const DisplayTransform& display = {});

// What a face calls to write a render: write_exr with the passes for a ".exr" file, write_image
// otherwise. Throws UsageError when passes or 32-bit floats are asked of another type, OutputError.
void write_render_image(const std::filesystem::path& file, const Image& image, const Aovs* aovs, const OutputContent& content);

// Throws the UsageError write_render_image would, before any work is done.
void check_render_image(const std::filesystem::path& file, const OutputContent& content);

// Throws OutputError, before any work is done, when `file` cannot be an image vkray writes: an
// unknown extension, a folder that does not exist (or is a file) or cannot be written to, or a
// folder in the file's place.
// Every face checks an output here first, so that each refuses it with the same message and exit code.
void check_output_image(const std::filesystem::path& file);
// For a file of any type (a report, a JUnit file, a folder to make): its folder must exist.
void check_output_folder(const std::filesystem::path& file);

}  // namespace vkray
