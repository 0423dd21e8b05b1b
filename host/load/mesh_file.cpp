#include "load/mesh_file.h"

#include <algorithm>
#include <cctype>
#include <string>

#include "base/errors.h"
#include "base/extension.h"
#include "base/input_file.h"
#include "mesh/obj.h"
#include "mesh/ply.h"

namespace vkray {
namespace {

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
  throw MeshError(file.string() + ": " + what);
}

}  // namespace

Mesh parse_mesh(std::string_view bytes, const std::filesystem::path& name) {
  const std::string ext = lower_extension(name);
  Mesh mesh;
  if (ext == ".obj") {
    mesh = parse_obj(bytes, name);
  } else if (ext == ".ply") {
    mesh = parse_ply(bytes, name);
  } else {
    fail(name, "unknown mesh format \"" + ext + "\" (expected .obj or .ply)");
  }
  if (mesh.triangles.empty()) fail(name, "the mesh has no faces");
  return mesh;
}

Mesh load_mesh(const std::filesystem::path& file) {
  const InputFile input = read_input_file(file, kMaxMeshFileBytes);
  if (!input.error.empty()) fail(file, input.error == "not found" ? "mesh file not found" : input.error);
  return parse_mesh(input.text, file);
}

}  // namespace vkray
