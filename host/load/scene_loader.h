// Loading a scene: a scene file (JSON, docs/scene-format.md) or a glTF file as a whole scene, with
// the meshes, material libraries, pictures and glTF files it names, read through their readers
// (mesh/, gltf/) and placed into one Scene (scene/scene.h).
#pragma once

#include <filesystem>
#include <string_view>

#include "load/mesh_cache.h"
#include "scene/scene.h"

namespace vkray {

// Reads and validates a scene file. Throws SceneError naming the file and the key (as a JSON
// pointer, e.g. /objects/2/radius) or the line and column of a syntax error. `meshes`: a cache to
// take mesh files from and keep them in; null reads each file once for this scene. `environment`:
// an environment map (load/environment_file.h) that lights the scene in place of its own
// environment and background (vkray render's --environment); empty: none.
Scene load_scene(const std::filesystem::path& file, MeshCache* meshes = nullptr, const std::filesystem::path& environment = {});

// A glTF file (.gltf or .glb, gltf/gltf.h) as a whole scene: its first camera, or one that frames its
// geometry from the front; its lights, or a point light at the camera when it brings none (emission
// aside) and no environment map lights it; a 512-pixel-high image in its camera's aspect ratio; the
// direct model. load_scene calls it for a file with either extension.
Scene load_gltf_scene(const std::filesystem::path& file, MeshCache* meshes = nullptr, const std::filesystem::path& environment = {});

// The same from text already in memory; `file` is used in messages and to resolve relative paths.
Scene parse_scene(std::string_view json_text, const std::filesystem::path& file, MeshCache* meshes = nullptr,
                  const std::filesystem::path& environment = {});

}  // namespace vkray
