// vkray._vkray: the Python face on the library (python/vkray/__init__.py is the package around it).
// It binds the library's calls, maps Python's arguments onto its options (python/arguments.h) and its
// results onto numpy arrays, and each kind of error onto one exception class (python/exceptions.h);
// everything else is the library's. Every call runs as python/calls.h says: off the GIL, stopped by
// Ctrl-C on any thread, and never half-done when the interpreter ends or the process forks.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstring>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "base/atomic_file.h"
#include "base/errors.h"
#include "base/json_document.h"
#include "base/timing.h"
#include "compare/parity.h"
#include "compare/parity_report.h"
#include "image/aovs.h"
#include "image/exr.h"
#include "image/image_file.h"
#include "image/merge.h"
#include "python/arguments.h"
#include "python/calls.h"
#include "python/exceptions.h"
#include "python/image_files.h"
#include "session/cpu_render.h"
#include "session/options.h"
#include "session/parts.h"
#include "session/paths.h"
#include "session/regions.h"
#include "session/session.h"
#include "session/version.h"

namespace py = pybind11;

namespace vkray::python {
namespace {

// Copies of the render as numpy arrays: a float32 (height, width, 3) array, or with `passes` a
// dict of it ("color") and the passes asked for.
py::object to_numpy(const RenderResult& result, const std::vector<Aov>& passes) {
  const py::dict arrays = image_arrays(result.image, result.aovs ? &*result.aovs : nullptr, passes);
  if (passes.empty()) return arrays["color"];
  return arrays;
}

// vkray._vkray._check_output: what a render to `output` would raise before any work.
void check_output(const std::filesystem::path& output, const std::vector<std::string>& aovs, bool exr_float, bool part) {
  Request request;
  request.output = output;
  request.aovs = aovs;
  request.exr_float = exr_float;
  if (part) request.region = "0/1";
  const std::vector<Aov> passes = parse_passes(aovs);
  run_interruptibly([&] { return output_content(request, passes); });
}

py::dict stats_dict(const RenderStats& stats, double load_seconds, double upload_seconds, bool geometry_reused) {
  py::dict d;
  d["load_seconds"] = load_seconds;
  d["upload_seconds"] = upload_seconds + stats.upload_seconds;
  d["geometry_reused"] = geometry_reused;
  d["trace_seconds"] = stats.trace_seconds;
  d["readback_seconds"] = stats.readback_seconds;
  d["rays"] = stats.rays;
  return d;
}

// Warnings the scene raised, as Python warnings. Raised after the scene is loaded and before it is
// rendered, so that a warning the filter turns into an exception stops the render before anything
// is written.
void warn_about(const Scene& scene) {
  for (const std::string& warning : scene.warnings)
    if (PyErr_WarnEx(PyExc_UserWarning, warning.c_str(), 2) != 0) throw py::error_already_set();
}

// vkray.Renderer: a device kept open, its pipelines, the mesh files read and the last scene
// uploaded, so that renders of edits re-upload only what changed.
class Renderer {
 public:
  Renderer(const std::optional<std::string>& device, bool validate, const std::optional<std::filesystem::path>& shader_dir) {
    SessionOptions options;
    options.device = device.value_or("");
    options.validation = validate;
    options.shader_dir = shader_dir.value_or("");
    session_ = run_interruptibly([&] { return std::make_unique<Session>(options); });
  }
  ~Renderer() {
    try {
      release();
    } catch (...) {  // a destructor reports nothing; close() does
    }
  }

  // Renders `source`: returns the image (and passes) as numpy arrays, or with request.output writes
  // the file as `vkray render -o` does (a region as a part) and returns None. The scene is loaded and
  // its warnings raised before anything is rendered or written.
  py::object render(const SceneSource& source, const Request& request) {
    const std::vector<Aov> passes = parse_passes(request.aovs);
    const RenderOptions options = options_of(request, !passes.empty());
    struct Loaded {
      std::shared_ptr<const Scene> scene;
      OutputContent content;
      double seconds;
    };
    const CallInFlight call;  // before the lock: a call in flight may be waiting for it
    auto lock = usable_without_gil();
    const Loaded loaded = run_interruptibly([&] {
      const OutputContent content = output_content(request, passes);
      const auto start = Clock::now();
      auto scene = load(source, &meshes_);
      meshes_.keep_only(scene->referenced_files);
      image_settings(*scene, options);  // a bad override fails before any upload
      return Loaded{scene, content, seconds_since(start)};
    });
    lock.unlock();  // a warning's handler may use this renderer
    warn_about(*loaded.scene);

    struct Done {
      RenderResult result;
      double upload_seconds;
      bool reused;
    };
    lock = usable_without_gil();
    Done done = run_interruptibly([&] {
      const std::shared_ptr<const Scene>& scene = loaded.scene;
      // The last scene goes first when this one needs a new upload, so that both are never on the device.
      std::optional<DeviceScene> on_device;
      if (last_ && same_geometry(last_->scene(), *scene)) on_device = session_->upload_changes(*last_, scene);
      last_.reset();
      if (!on_device) on_device = session_->upload(scene);
      last_ = on_device;
      RenderResult result = session_->render(*on_device, options);
      if (request.output) write_render(*request.output, *scene, result, loaded.content, session_->device_description());
      return Done{std::move(result), on_device->upload_seconds(), on_device->shares_geometry()};
    });
    last_stats_ = stats_dict(done.result.stats, loaded.seconds, done.upload_seconds, done.reused);
    last_stats_["region"] = py::make_tuple(done.result.region.x0, done.result.region.y0, done.result.region.x1, done.result.region.y1);
    if (request.output) return py::none();
    return to_numpy(done.result, passes);
  }

  void close() {
    if (opened_in_.forked()) return abandon();
    const CallInFlight call;  // before the lock: a call in flight may be waiting for it
    const auto lock = lock_without_gil(mutex_);
    release();
  }

  std::string device() const {
    if (!session_) return "";
    return session_->device_description();
  }
  py::object last_stats() const { return last_stats_; }

 private:
  // In a child made by fork(), the device is the parent's: using it would wait for ever, and
  // destroying it would wait for driver threads that did not come along. It is left as it is.
  void abandon() {
    new std::optional<DeviceScene>(std::exchange(last_, std::nullopt));
    static_cast<void>(session_.release());
  }

  // The lock, once the renderer is known to be usable in this process and open.
  std::unique_lock<std::timed_mutex> usable_without_gil() {
    opened_in_.check_not_forked();
    auto lock = lock_without_gil(mutex_);
    if (!session_) throw UsageError("the renderer is closed");
    return lock;
  }

  // Releases the device, without the GIL: closing may wait for a tile an interrupt left running.
  void release() {
    if (opened_in_.forked()) return abandon();
    last_.reset();
    if (!session_) return;
    std::unique_ptr<Session> session = std::move(session_);
    const CallInFlight call;  // the end of the interpreter waits for it
    WithoutGil released;
    session->close();
  }

  const OpenedInProcess opened_in_;
  std::timed_mutex mutex_;
  std::unique_ptr<Session> session_;
  MeshCache meshes_;
  std::optional<DeviceScene> last_;
  py::object last_stats_ = py::none();
};

py::object render_cpu(const SceneSource& source, const Request& request, const py::object& threads) {
  const std::vector<Aov> passes = parse_passes(request.aovs);
  RenderOptions options = options_of(request, !passes.empty());
  options.threads = thread_count_argument(threads);
  struct Loaded {
    std::shared_ptr<const Scene> scene;
    OutputContent content;
  };
  const CallInFlight call;
  const Loaded loaded = run_interruptibly([&] {
    const OutputContent content = output_content(request, passes);
    auto scene = load(source, nullptr);
    image_settings(*scene, options);
    return Loaded{scene, content};
  });
  warn_about(*loaded.scene);
  const RenderResult result = run_interruptibly([&] {
    RenderResult rendered = render_on_cpu(*loaded.scene, options);
    if (request.output) write_render(*request.output, *loaded.scene, rendered, loaded.content, kCpuReferenceDevice);
    return rendered;
  });
  if (request.output) return py::none();
  return to_numpy(result, passes);
}

// The bands `vkray render --region I/N` renders, all of them (session/regions.h).
py::list bands(const SceneSource& source, const py::object& count, const py::object& width, const py::object& height) {
  const std::optional<uint32_t> bands = number(count, kBandCountArgument);
  if (!bands) throw kBandCountArgument.error("None");
  const RenderOptions options =
      render_options(number(width, kWidthArgument), number(height, kHeightArgument), std::nullopt, std::nullopt, false);
  const CallInFlight call;
  const auto scene = run_interruptibly([&] { return load(source, nullptr); });
  warn_about(*scene);
  const std::vector<PixelRegion> found =
      run_interruptibly([&] { return work_bands(*scene, image_settings(*scene, options), *bands); });
  py::list out;
  for (const PixelRegion& r : found) out.append(py::make_tuple(r.x0, r.y0, r.x1, r.y1));
  return out;
}

py::dict merge(const std::filesystem::path& output, const std::vector<std::filesystem::path>& parts) {
  const MergeSummary summary = run_interruptibly([&] { return merge_part_files(output, parts); });
  py::dict out;
  out["parts"] = summary.parts;
  out["width"] = summary.record.width;
  out["height"] = summary.record.height;
  out["spp"] = summary.record.samples_per_pixel;
  out["seed"] = summary.record.seed;
  out["scene_digest"] = summary.record.scene_digest;
  out["mixed_devices"] = summary.mixed_devices;
  out["passes_dropped"] = summary.passes_dropped;
  return out;
}

std::string parity(const SceneSource& source, const py::object& width, const py::object& height, const py::object& spp,
                   const py::object& seed, const std::optional<std::string>& device, bool validate, const py::object& threads) {
  RenderOptions options = render_options(number(width, kWidthArgument), number(height, kHeightArgument), number(spp, kSppArgument),
                                         number(seed, kSeedArgument), false);
  options.threads = thread_count_argument(threads);
  const CallInFlight call;
  const auto scene = run_interruptibly([&] {
    auto loaded = load(source, nullptr);
    image_settings(*loaded, options);
    return loaded;
  });
  warn_about(*scene);
  return run_interruptibly([&] {
    SessionOptions session_options;
    session_options.device = device.value_or("");
    session_options.validation = validate;
    Session session(session_options);
    const ParityResult result = compare_with_reference(session, scene, options);
    const std::string description = session.device_description();
    session.close();
    return parity_json(result, scene->file.string(), description).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  });
}

py::list devices() {
  const std::vector<DeviceInfo> found = run_interruptibly([] { return list_devices(); });
  py::list out;
  for (const DeviceInfo& d : found) {
    py::dict entry;
    entry["index"] = d.index;
    entry["name"] = d.name;
    entry["type"] = d.type;
    entry["driver"] = d.driver;
    entry["api_version"] = d.api_version;
    entry["compute"] = d.has_compute_queue;
    entry["device_local_bytes"] = d.device_local_bytes;
    out.append(entry);
  }
  return out;
}

}  // namespace
}  // namespace vkray::python

PYBIND11_MODULE(_vkray, m) {
  using namespace vkray::python;
  namespace vp = vkray::python;
  m.doc() = "vkray's C++ library; use the vkray package, which wraps it.";
  add_exceptions(m);
  stop_calls_at_exit();

  py::class_<vp::SceneSource>(m, "_SceneSource")
      .def(py::init([](std::filesystem::path file, std::optional<std::string> text, std::optional<std::filesystem::path> environment) {
             return vp::SceneSource{std::move(file), std::move(text), environment.value_or(std::filesystem::path())};
           }),
           py::arg("file"), py::arg("text") = py::none(), py::arg("environment") = py::none());

  py::class_<vp::Request>(m, "_Request")
      .def(py::init(&vp::make_request),
           py::arg("width") = py::none(), py::arg("height") = py::none(), py::arg("spp") = py::none(), py::arg("seed") = py::none(),
           py::arg("aovs") = std::vector<std::string>{}, py::arg("region") = py::none(), py::arg("output") = py::none(),
           py::arg("exr_float") = false);

  py::class_<vp::Renderer>(m, "_Renderer")
      .def(py::init<const std::optional<std::string>&, bool, const std::optional<std::filesystem::path>&>(), py::arg("device"),
           py::arg("validate"), py::arg("shader_dir"))
      .def("render", &vp::Renderer::render, py::arg("source"), py::arg("request"))
      .def("close", &vp::Renderer::close)
      .def_property_readonly("device", &vp::Renderer::device)
      .def_property_readonly("last_stats", &vp::Renderer::last_stats);
  m.def("render_cpu", &vp::render_cpu, py::arg("source"), py::arg("request"), py::arg("threads"));
  m.def("bands", &vp::bands, py::arg("source"), py::arg("count"), py::arg("width"), py::arg("height"));
  m.def("merge", &vp::merge, py::arg("output"), py::arg("parts"));
  m.def("_check_passes", [](const std::vector<std::string>& names) { vp::parse_passes(names); },
        "Raises UsageError unless `names` are first-hit passes, each once.");
  m.def("_check_output",
        &vp::check_output,
        py::arg("output"), py::arg("aovs"), py::arg("exr_float"), py::arg("part"),
        "Raises what a render to `output` would before any work: SceneError for a path that cannot be written "
        "(exit 1), UsageError for what cannot be asked of its type (exit 2).");
  m.def("parity", &vp::parity, py::arg("source"), py::arg("width"), py::arg("height"), py::arg("spp"), py::arg("seed"),
        py::arg("device"), py::arg("validate"), py::arg("threads"));
  m.def("devices", &vp::devices);
  m.def("_read_image", &vp::read_image_file, py::arg("file"),
        "A render's .exr (with its passes) or .pfm: ({\"color\": ..., pass: ...}, whether the colour is 32-bit).");
  m.def("_write_image", &vp::write_image_file, py::arg("file"), py::arg("arrays"), py::arg("exr_float"),
        "Writes {\"color\": ..., pass: ...} as `vkray render -o` writes a render.");
  m.def("_read_integer",
        [](const std::string& name, const std::string& text, uint32_t min, uint32_t max) {
          return vkray::ArgumentLimit{name, min, max}.read(text);
        },
        py::arg("name"), py::arg("text"), py::arg("min"), py::arg("max"),
        "An integer given as text, read as the command line reads its flags (session/options.h); raises "
        "UsageError \"NAME: expected ...\" in the command line's words.");
  m.def("_rename_together",
        [](const std::vector<std::tuple<std::filesystem::path, std::filesystem::path, std::filesystem::path>>& renames) {
          std::vector<vkray::Rename> all;
          for (const auto& [from, to, keep_as] : renames) all.push_back({from, to, keep_as});
          vkray::rename_together(all);
        },
        py::arg("renames"),
        "Renames each (from, to, keep_as) all or none, as the library commits files that belong together "
        "(base/atomic_file.h); raises SceneError.");
  py::dict limits;
  for (const vkray::ArgumentLimit& limit : {vkray::kWidthArgument, vkray::kHeightArgument, vkray::kSppArgument, vkray::kSeedArgument,
                                            vkray::kThreadsArgument, vkray::kTileTimeoutArgument, vkray::kBandCountArgument})
    limits[py::str(std::string(limit.name))] = py::make_tuple(limit.min, limit.max);
  m.attr("_ARGUMENT_LIMITS") = limits;  // the library's table of limits, by name: (min, max)
  m.def("_calls_in_flight", &vp::calls_in_flight, "How many calls into the library are in flight in this process.");
  m.def("_shader_dir", [] { return vkray::default_shader_dir(); }, "Where the shaders are compiled from by default.");
  m.attr("_MAX_JSON_DEPTH") = vkray::kMaxJsonDepth;
  m.attr("__version__") = vkray::version_string();
}
