// An environment map's file (Scene::environment): a Radiance .hdr or an OpenEXR .exr picture of the
// radiance around the scene, equirectangular.
#pragma once

#include <filesystem>
#include <memory>

#include "image/image.h"
#include "scene/scene.h"

namespace vkray {

// The map in `file` (.hdr or .exr, by its extension) times `scale`. Throws SceneError naming the
// file: unreadable, not twice as wide as high, or a texel (named by its column and row) that is not
// finite or is negative, before or after the scale; LimitError when it does not fit in memory.
// `brightest`, when given: the brightest channel of any texel, scaled.
std::shared_ptr<const Image> read_environment_map(const std::filesystem::path& file, float scale, float* brightest = nullptr);

// Lights `scene` by the map in `file`, as vkray render's --environment does: it replaces the
// scene's environment and background, unrotated and unscaled, and the file is watched with the
// scene's own. Throws as read_environment_map.
void set_environment(Scene& scene, const std::filesystem::path& file);

}  // namespace vkray
