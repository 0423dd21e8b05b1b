// What a face reports of a comparison (`vkray parity`, `vkray check`, vkray.parity() in Python): its JSON
// keys and its difference image.
#pragma once

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "compare/parity.h"

namespace vkray {

// The metrics as `vkray parity --json` prints them and vkray.parity() returns them (scripts read the
// keys: docs/parity.md).
nlohmann::json parity_json(const ParityResult& r, const std::string& scene, const std::string& device);

// Writes the difference of the GPU image from the reference to `file`: a PNG heatmap of 8-bit steps
// (what a person can see), or a PFM of the raw linear differences. Returns the PNG's steps at its
// brightest colour (0 for a PFM). Throws OutputError.
int write_difference(const ParityResult& r, const std::filesystem::path& file);

}  // namespace vkray
