// Images as numpy arrays, both ways: a render's colour and first-hit passes out of the library
// (vkray.render), and image files read and written through the library's own readers and writers
// (vkray.read_image, vkray.write_image), with `vkray render -o`'s checks and atomic writes.
#pragma once

#include <filesystem>
#include <vector>

#include <pybind11/pybind11.h>

#include "image/aovs.h"
#include "image/image.h"

namespace vkray::python {

// {"color": float32 (height, width, 3), and each of `passes`: "albedo", "normal", "position"
// float32 (height, width, 3), "depth" float32 (height, width), "object" int32 (height, width)}.
pybind11::dict image_arrays(const Image& image, const Aovs* aovs, const std::vector<Aov>& passes);

// A render's image file: an EXR (with the passes it holds) or a PFM, as image_arrays, and whether its
// colour channels are 32-bit floats. Throws UsageError for a PNG (8-bit display values, not radiance),
// another type, or a part of a render; InputError for a file that cannot be read.
pybind11::tuple read_image_file(const std::filesystem::path& file);

// Writes `arrays` (image_arrays' keys; "color" required, the passes only to an EXR) to `file` as
// `vkray render -o` writes a render: the passes in vkray's order, 32-bit with `exr_float`, under a
// temporary name renamed into place. Throws UsageError for arrays of the wrong shape or type or what
// the file's type cannot hold, OutputError for a file that cannot be written.
void write_image_file(const std::filesystem::path& file, const pybind11::dict& arrays, bool exr_float);

}  // namespace vkray::python
