// Radiance RGBE files (.hdr, "#?RADIANCE" or "#?RGBE"), as HDR environment maps are most often
// shipped, read through stb_image (Debian's libstb-dev).
#pragma once

#include <filesystem>

#include "image/image.h"

namespace vkray {

// The file's pixels as linear radiance, top row first. Its size is checked against kMaxImageSide
// before anything is allocated for it. Throws InputError naming the file (with stb_image's reason),
// LimitError when pixels the file holds do not fit in memory, Cancelled.
Image read_hdr(const std::filesystem::path& file);

}  // namespace vkray
