// A fingerprint of what a scene renders: every value either renderer reads (the camera, the
// integrator, the background and ambient light, materials, textures, lights, primitives), and none
// of what it does not (the file's name and folder, its description, warnings). Two machines that
// load the same scene from different folders get the same digest; a scene edited in any way that
// can change a pixel gets another. Parts of one render record it (image/part.h) so that `vkray merge`
// never assembles parts of different scenes. The image settings (size, samples, seed) are not in it:
// a part records them beside it.
#pragma once

#include <string>

#include "scene/scene.h"

namespace vkray {

// 32 hex digits: XXH3's 128-bit hash (libxxhash) of the values above, field by field in a fixed
// order, so that neither padding nor the host's layout of a struct enters it.
std::string scene_digest(const Scene& scene);

}  // namespace vkray
