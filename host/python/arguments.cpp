#include "python/arguments.h"

#include <utility>

#include "base/errors.h"
#include "load/scene_loader.h"
#include "session/parts.h"
#include "session/regions.h"

namespace py = pybind11;

namespace vkray::python {

std::optional<uint32_t> number(const py::handle& value, const ArgumentLimit& limit) {
  static const auto* const numpy_bool = new py::object(py::module_::import("numpy").attr("bool_"));
  if (value.is_none()) return std::nullopt;
  if (PyBool_Check(value.ptr()) || py::isinstance(value, *numpy_bool) || !PyIndex_Check(value.ptr()))
    throw limit.error(std::string(py::repr(value)));
  const auto whole = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
  if (!whole) throw py::error_already_set();
  int overflow = 0;
  const long long n = PyLong_AsLongLongAndOverflow(whole.ptr(), &overflow);
  if (overflow != 0 || !limit.contains(n)) throw limit.error(std::string(py::str(whole)));
  return uint32_t(n);
}

unsigned thread_count_argument(const py::handle& value) {
  if (PyLong_Check(value.ptr()) && !PyBool_Check(value.ptr()) && py::int_(0).equal(value)) return 0;
  return number(value, kThreadsArgument).value_or(0);
}

std::shared_ptr<const Scene> load(const SceneSource& source, MeshCache* meshes) {
  return std::make_shared<const Scene>(source.text ? parse_scene(*source.text, source.file, meshes, source.environment)
                                                   : load_scene(source.file, meshes, source.environment));
}

Request make_request(const py::object& width, const py::object& height, const py::object& spp, const py::object& seed,
                     std::vector<std::string> aovs, std::optional<std::string> region, std::optional<std::filesystem::path> output,
                     bool exr_float) {
  return {number(width, kWidthArgument), number(height, kHeightArgument), number(spp, kSppArgument), number(seed, kSeedArgument),
          std::move(aovs), std::move(region), std::move(output), exr_float};
}

RenderOptions render_options(std::optional<uint32_t> width, std::optional<uint32_t> height, std::optional<uint32_t> spp,
                             std::optional<uint32_t> seed, bool aovs) {
  RenderOptions options;
  options.width = width;
  options.height = height;
  options.samples_per_pixel = spp;
  options.seed = seed;
  options.aovs = aovs;
  return options;
}

RenderOptions options_of(const Request& request, bool aovs) {
  RenderOptions options = render_options(request.width, request.height, request.spp, request.seed, aovs);
  if (request.region) options.region = parse_region(*request.region);
  return options;
}

std::vector<Aov> parse_passes(const std::vector<std::string>& names) {
  std::string list;
  for (const auto& name : names) list += (list.empty() ? "" : ",") + name;
  return list.empty() ? std::vector<Aov>{} : parse_aov_list(list);
}

OutputContent output_content(const Request& request, const std::vector<Aov>& passes) {
  OutputContent content;
  content.passes = passes;
  content.full_float = request.exr_float;
  if (!request.output) {
    if (request.exr_float) throw UsageError("exr_float is for a render to an .exr file");
    return content;
  }
  check_render_output(*request.output, content, request.region.has_value());
  return content;
}

}  // namespace vkray::python
