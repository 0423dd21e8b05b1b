#include "image/image_file.h"

#include <cerrno>
#include <cstring>
#include <string>

#include <unistd.h>

#include "base/errors.h"
#include "base/extension.h"

namespace vkray {

std::optional<ImageFileType> image_file_type(const std::filesystem::path& file) {
  const std::string ext = lower_extension(file);
  if (ext == ".png") return ImageFileType::png;
  if (ext == ".pfm") return ImageFileType::pfm;
  if (ext == ".exr") return ImageFileType::exr;
  return std::nullopt;
}

void check_output_image(const std::filesystem::path& file) {
  if (!is_supported_image_path(file)) throw OutputError(file.string() + ": unknown image type (expected .png, .pfm or .exr)");
  check_output_folder(file);
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) throw OutputError(file.string() + ": is a folder");
}

void check_output_folder(const std::filesystem::path& file) {
  const auto dir = file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) throw OutputError(file.string() + ": folder " + dir.string() + " does not exist");
  // Found now, not after the render: the file is made in this folder (a temporary, then renamed).
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw OutputError(file.string() + ": folder " + dir.string() + " cannot be written to (" + std::strerror(errno) + ")");
}

bool is_supported_image_path(const std::filesystem::path& file) { return image_file_type(file).has_value(); }
bool is_pfm(const std::filesystem::path& file) { return image_file_type(file) == ImageFileType::pfm; }
bool is_exr(const std::filesystem::path& file) { return image_file_type(file) == ImageFileType::exr; }

void write_image(const Image& image, const std::filesystem::path& file, const DisplayTransform& display) {
  const auto type = image_file_type(file);
  if (!type)
    throw OutputError(file.string() + ": unknown image type \"" + lower_extension(file) + "\" (expected .png, .pfm or .exr)");
  switch (*type) {
    case ImageFileType::png: return write_png(image, file, display);
    case ImageFileType::pfm: return write_pfm(image, file);
    case ImageFileType::exr: return write_exr(file, image, nullptr, {});
  }
}

void write_render_image(const std::filesystem::path& file, const Image& image, const Aovs* aovs, const OutputContent& content) {
  check_render_image(file, content);
  if (is_exr(file)) return write_exr(file, image, aovs, content);
  write_image(image, file, content.display);
}

void check_render_image(const std::filesystem::path& file, const OutputContent& content) {
  if (!content.display.is_identity() && image_file_type(file) != ImageFileType::png)
    throw UsageError(file.string() + ": --tonemap and --exposure are for PNG files only (EXR and PFM files hold linear "
                     "radiance): name the output *.png");
  if (is_exr(file)) return;
  if (!content.passes.empty())
    throw UsageError(file.string() + ": first-hit passes (--aov) are written to EXR files only: name the output *.exr");
  if (content.full_float) throw UsageError(file.string() + ": --exr-float is for EXR files only: name the output *.exr");
}

}  // namespace vkray
