// Python's arguments as the library's requests, checked as the command line checks its flags: the
// numbers against session/options.h's table of limits with the same messages (a UsageError naming
// the argument), a region as `--region` reads it, passes as `--aovs` reads them, an output file by
// the library's own check (session/parts.h). The package (python/vkray/__init__.py) has already made
// paths into text and a scene dict into JSON text, naming the key of any value JSON cannot hold.
#pragma once

#include <pybind11/pybind11.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "image/aovs.h"
#include "image/exr.h"
#include "load/mesh_cache.h"
#include "scene/scene.h"
#include "session/options.h"

namespace vkray::python {

// None is "not given"; an int (numpy's too, but not a bool) within `limit` is taken; anything else is
// a UsageError naming the argument.
std::optional<uint32_t> number(const pybind11::handle& value, const ArgumentLimit& limit);

// A thread count: 0 (the default) or None is one per hardware thread, as the library's 0.
unsigned thread_count_argument(const pybind11::handle& value);

// A scene as the package hands it over: a file to load, or the text of a scene dict with the file
// name its relative paths resolve against.
struct SceneSource {
  std::filesystem::path file;
  std::optional<std::string> text;
  std::filesystem::path environment;  // an environment map in place of the scene's (load_scene); empty: none
};

std::shared_ptr<const Scene> load(const SceneSource& source, MeshCache* meshes);

// What a render is asked for from Python: the overrides, the passes, a region ("X0,Y0,X1,Y1" or
// "I/N"), and for a render to a file, the file and its precision.
struct Request {
  std::optional<uint32_t> width, height, spp, seed;
  std::vector<std::string> aovs;
  std::optional<std::string> region;
  std::optional<std::filesystem::path> output;
  bool exr_float = false;
};

Request make_request(const pybind11::object& width, const pybind11::object& height, const pybind11::object& spp,
                     const pybind11::object& seed, std::vector<std::string> aovs, std::optional<std::string> region,
                     std::optional<std::filesystem::path> output, bool exr_float);

RenderOptions render_options(std::optional<uint32_t> width, std::optional<uint32_t> height, std::optional<uint32_t> spp,
                             std::optional<uint32_t> seed, bool aovs);
RenderOptions options_of(const Request& request, bool aovs);

std::vector<Aov> parse_passes(const std::vector<std::string>& names);

// The file's content, checked before any work: passes and 32-bit floats only in an .exr, a region
// only as a part (.exr or .pfm).
OutputContent output_content(const Request& request, const std::vector<Aov>& passes);

}  // namespace vkray::python
