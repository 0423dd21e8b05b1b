// glTF 2.0 files: a .gltf with its buffers and pictures, or a .glb. tinygltf (Debian's libtinygltf-dev)
// parses them. Before it does, vkray checks every value of the document against glTF's schema (so that
// nothing tinygltf would read leniently, as absent or as a default, gets through: gltf_schema.h) and
// resolves every URI itself (gltf_uri.h); after it, every accessor range and index value before it
// reads anything through them. It places the meshes of the default scene's node hierarchy in the
// file's world space. The metallic-roughness material's base colour and emission (with their
// textures) become vkray's diffuse materials; what vkray cannot render is named in one warning each.
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scene/scene.h"

namespace vkray {

struct GltfScene {
  std::vector<Triangle> triangles;  // in the file's world space; `material` indexes `materials`, `object` is 0
  // Meshes the file places more than once (nodes that share a mesh, EXT_mesh_gpu_instancing), each
  // read once in its own space, and their placements (`object` 0).
  std::vector<SharedMesh> meshes;
  std::vector<Instance> instances;
  std::vector<Material> materials;  // their TextureRefs index `textures`
  std::vector<std::shared_ptr<const Texture>> textures;
  std::vector<Light> lights;        // KHR_lights_punctual's point, spot and directional lights, in world space
  // The first camera, depth-first from the default scene's root nodes, and its aspect ratio (width
  // over height; 0 when the file gives none).
  std::optional<Camera> camera;
  float aspect_ratio = 0.0f;
  std::vector<std::string> warnings;
  std::vector<std::filesystem::path> files;  // the files read besides the file itself (buffers, pictures)
};

struct GltfLimits {
  // The most triangles a file may place (instancing multiplies a mesh's): more throws LimitError.
  size_t max_triangles = kMaxScenePrimitives;
  // The most texels its pictures may decode to together (each picture's size is read from its
  // header first): more throws LimitError.
  uint64_t max_texels = kMaxSceneTexels;
  // The most morph-target displacements (a corner's attribute moved by one target) the file may take
  // to apply: more throws LimitError. Far past a real file's (a million vertices with a hundred
  // targets), and a few seconds' work.
  uint64_t max_morph_displacements = uint64_t(1) << 31;
  // The most triangles its meshes may place, counted each time they are placed (a mesh the file places
  // more than once is stored once): more throws LimitError.
  uint64_t max_placed_triangles = kMaxPlacedPrimitives;
  // Whether buffers and pictures outside the file are read (the fuzz target reads none).
  bool read_files = true;
};

// Reads a .gltf or .glb file (by its first bytes, not its name). Throws SceneError naming the file and
// the element ("meshes[2].primitives[0]: ...") or LimitError.
GltfScene load_gltf(const std::filesystem::path& file, const GltfLimits& limits = {});

// The same from the file's bytes in memory; `file` names it in messages and locates relative URIs.
GltfScene parse_gltf(std::string_view bytes, const std::filesystem::path& file, const GltfLimits& limits = {});

}  // namespace vkray
