#include "python/image_files.h"

#include <pybind11/numpy.h>

#include <algorithm>
#include <cstring>
#include <optional>
#include <string>

#include "base/errors.h"
#include "image/exr.h"
#include "image/image_file.h"
#include "python/calls.h"

namespace py = pybind11;

namespace vkray::python {
namespace {

template <typename T>
py::array_t<T> copy_out(const T* data, size_t count, std::vector<py::ssize_t> shape) {
  py::array_t<T> a(shape);
  std::memcpy(a.mutable_data(), data, count * sizeof(T));
  return a;
}

// `value` as a C-contiguous array of T shaped (height, width[, 3]), or a UsageError naming `name`:
// floats for T = float, integers for T = int32_t, nothing converted that would change a value's kind.
template <typename T>
py::array_t<T, py::array::c_style> array_in(const std::string& name, const py::handle& value, std::optional<py::ssize_t> height,
                                             std::optional<py::ssize_t> width, bool rgb) {
  const py::array a = py::array::ensure(value);
  if (!a) throw UsageError(name + ": expected a numpy array");
  const char kind = a.dtype().kind();
  const bool floats = std::is_floating_point_v<T>;
  if (floats ? kind != 'f' : (kind != 'i' && kind != 'u'))
    throw UsageError(name + " is an array of " + std::string(py::str(a.dtype())) + "; it holds " +
                     (floats ? "floats" : "integers"));
  const py::ssize_t dims = rgb ? 3 : 2;
  if (a.ndim() != dims || (rgb && a.shape(2) != 3) || a.shape(0) == 0 || a.shape(1) == 0 ||
      (height && a.shape(0) != *height) || (width && a.shape(1) != *width)) {
    std::string shape;
    for (py::ssize_t i = 0; i < a.ndim(); ++i) shape += (i ? ", " : "") + std::to_string(a.shape(i));
    throw UsageError(name + " has shape (" + shape + "); it must be (" +
                     (height ? std::to_string(*height) : std::string("height")) + ", " +
                     (width ? std::to_string(*width) : std::string("width")) + (rgb ? ", 3)" : ")") +
                     (height ? ", the colour's size" : ""));
  }
  return py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(a);
}

}  // namespace

py::dict image_arrays(const Image& image, const Aovs* aovs, const std::vector<Aov>& passes) {
  const auto h = py::ssize_t(image.height), w = py::ssize_t(image.width);
  const auto rgb = [&](const std::vector<glm::vec3>& pixels) { return copy_out(&pixels[0].x, pixels.size() * 3, {h, w, 3}); };
  py::dict out;
  out["color"] = rgb(image.pixels);
  for (const Aov pass : passes) {
    switch (pass) {
      case Aov::albedo: out["albedo"] = rgb(aovs->albedo); break;
      case Aov::normal: out["normal"] = rgb(aovs->normal); break;
      case Aov::position: out["position"] = rgb(aovs->position); break;
      case Aov::depth: out["depth"] = copy_out(aovs->depth.data(), aovs->depth.size(), {h, w}); break;
      case Aov::object: out["object"] = copy_out(aovs->object.data(), aovs->object.size(), {h, w}); break;
    }
  }
  return out;
}

py::tuple read_image_file(const std::filesystem::path& file) {
  struct Read {
    Image image;
    Aovs aovs;
    std::vector<Aov> passes;
    bool full_float = true;
  };
  const Read read = run_interruptibly([&] {
    const std::optional<ImageFileType> type = image_file_type(file);
    if (type == ImageFileType::pfm) return Read{read_pfm(file), {}, {}, true};
    if (type == ImageFileType::png)
      throw UsageError(file.string() + ": a PNG holds 8-bit display values, not radiance: read a render's .exr or .pfm");
    if (type != ImageFileType::exr) throw UsageError(file.string() + ": not an image file vkray reads (.exr or .pfm)");
    ExrFile exr = read_exr(file);
    const ExrWindow& window = exr.window;
    if (!window.part_record.empty() || window.region.x0 != 0 || window.region.y0 != 0 ||
        window.region.x1 != window.full_width || window.region.y1 != window.full_height)
      throw UsageError(file.string() + ": a part of a render, not a whole image: merge the parts (vkray merge) and read the result");
    return Read{std::move(exr.image), std::move(exr.aovs), exr.content.passes, exr.content.full_float};
  });
  return py::make_tuple(image_arrays(read.image, &read.aovs, read.passes), read.full_float);
}

void write_image_file(const std::filesystem::path& file, const py::dict& arrays, bool exr_float) {
  if (!arrays.contains("color")) throw UsageError("the images to write have no \"color\"");
  const auto color = array_in<float>("color", arrays["color"], std::nullopt, std::nullopt, true);
  const py::ssize_t h = color.shape(0), w = color.shape(1);
  Image image{uint32_t(w), uint32_t(h)};
  std::memcpy(&image.pixels[0].x, color.data(), size_t(h * w * 3) * sizeof(float));
  Aovs aovs{uint32_t(w), uint32_t(h)};
  OutputContent content;
  content.full_float = exr_float;
  for (const Aov pass : kAllAovs) {  // vkray's order, whatever the dict's
    const std::string name = aov_name(pass);
    if (!arrays.contains(name)) continue;
    content.passes.push_back(pass);
    const py::handle value = arrays[name.c_str()];
    const auto copy_rgb = [&](std::vector<glm::vec3>& to) {
      const auto a = array_in<float>(name, value, h, w, true);
      std::memcpy(&to[0].x, a.data(), size_t(h * w * 3) * sizeof(float));
    };
    switch (pass) {
      case Aov::albedo: copy_rgb(aovs.albedo); break;
      case Aov::normal: copy_rgb(aovs.normal); break;
      case Aov::position: copy_rgb(aovs.position); break;
      case Aov::depth: {
        const auto a = array_in<float>(name, value, h, w, false);
        std::memcpy(aovs.depth.data(), a.data(), size_t(h * w) * sizeof(float));
        break;
      }
      case Aov::object: {
        const auto a = array_in<int32_t>(name, value, h, w, false);
        std::memcpy(aovs.object.data(), a.data(), size_t(h * w) * sizeof(int32_t));
        break;
      }
    }
  }
  for (const auto& [key, value] : arrays) {
    const std::string name = py::str(key);
    if (name != "color" && std::none_of(kAllAovs.begin(), kAllAovs.end(), [&](Aov a) { return name == aov_name(a); }))
      throw UsageError("\"" + name + "\" is not an image vkray writes (color, albedo, normal, position, depth, object)");
  }
  run_interruptibly([&] {
    check_output_image(file);
    check_render_image(file, content);
    write_render_image(file, image, content.passes.empty() ? nullptr : &aovs, content);
  });
}

}  // namespace vkray::python
