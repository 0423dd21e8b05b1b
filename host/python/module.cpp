// vkray._vkray: the Python face on the library (python/vkray/__init__.py is the package around it).
// It maps Python's arguments onto the library's options and the library's results onto numpy
// arrays, and each kind of error (base/errors.h, session/failure.h) onto one exception class;
// everything else is the library's. Long calls run on a thread of their own with the GIL released,
// while the calling thread polls for Ctrl-C and turns it into the library's interrupt request.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <chrono>
#include <cstring>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "base/errors.h"
#include "base/interrupt.h"
#include "base/timing.h"
#include "image/aovs.h"
#include "image/exr.h"
#include "image/image_file.h"
#include "image/merge.h"
#include "session/cpu_render.h"
#include "session/failure.h"
#include "compare/parity.h"
#include "compare/parity_report.h"
#include "session/parts.h"
#include "session/paths.h"
#include "session/regions.h"
#include "session/session.h"
#include "session/version.h"
#include "load/scene_loader.h"

namespace py = pybind11;

namespace vkray::python {
namespace {

// The exception classes, made in PYBIND11_MODULE.
struct Exceptions {
  py::object error, scene_error, usage_error, device_error, internal_error;
};
Exceptions& exceptions() {
  static Exceptions* e = new Exceptions();  // never destroyed: outlives the interpreter's teardown
  return *e;
}

// Raises the Python exception for the error in flight (a Cancelled as KeyboardInterrupt).
[[noreturn]] void raise_failure(const std::exception_ptr& error) {
  const Failure failure = describe_failure(error);
  py::object type;
  switch (failure.exit_code) {
    case kExitBadInput: type = exceptions().scene_error; break;
    case kExitUsage: type = exceptions().usage_error; break;
    case kExitDevice: type = exceptions().device_error; break;
    case kExitInterrupted: PyErr_SetNone(PyExc_KeyboardInterrupt); throw py::error_already_set();
    default: type = exceptions().internal_error; break;
  }
  PyErr_SetString(type.ptr(), failure.message.c_str());
  throw py::error_already_set();
}

// Runs `work` on a thread of its own with the GIL released; the calling thread checks for signals
// every 50 ms (Python runs its SIGINT handler there), and a KeyboardInterrupt asks the library to
// stop, waits for it (the library stops within a fraction of a second) and is raised.
template <typename Work>
auto run_interruptibly(Work&& work) -> decltype(work()) {
  using Result = decltype(work());
  std::future<Result> done = std::async(std::launch::async, std::forward<Work>(work));
  while (true) {
    {
      py::gil_scoped_release released;
      if (done.wait_for(std::chrono::milliseconds(50)) == std::future_status::ready) break;
    }
    if (PyErr_CheckSignals() != 0) {
      py::error_already_set interrupt;  // KeyboardInterrupt, or what a signal handler raised
      request_interrupt();
      {
        py::gil_scoped_release released;
        done.wait();
      }
      clear_interrupt();
      throw interrupt;
    }
  }
  try {
    return done.get();
  } catch (...) {
    raise_failure(std::current_exception());
  }
}

// A scene as the package hands it over: a file to load, or the text of a scene dict with the file
// name its relative paths resolve against.
struct SceneSource {
  std::filesystem::path file;
  std::optional<std::string> text;
};

std::shared_ptr<const Scene> load(const SceneSource& source, MeshCache* meshes) {
  return std::make_shared<const Scene>(source.text ? parse_scene(*source.text, source.file, meshes) : load_scene(source.file, meshes));
}

// What a render is asked for from Python: the overrides, the passes, a region ("X0,Y0,X1,Y1" or
// "I/N"), and for a render to a file, the file and its precision.
struct Request {
  std::optional<uint32_t> width, height, spp, seed;
  std::vector<std::string> aovs;
  std::optional<std::string> region;
  std::optional<std::filesystem::path> output;
  bool exr_float = false;
};

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

// Copies of the render as numpy arrays: a float32 (height, width, 3) array, or with `passes` a
// dict of it ("color") and the passes asked for.
py::object to_numpy(const RenderResult& result, const std::vector<Aov>& passes) {
  const Image& image = result.image;
  const auto h = py::ssize_t(image.height), w = py::ssize_t(image.width);
  const auto rgb = [&](const std::vector<glm::vec3>& pixels) {
    py::array_t<float> a({h, w, py::ssize_t(3)});
    std::memcpy(a.mutable_data(), pixels.data(), pixels.size() * sizeof(glm::vec3));
    return a;
  };
  py::array_t<float> color = rgb(image.pixels);
  if (passes.empty()) return py::object(color);
  py::dict out;
  out["color"] = color;
  const Aovs& aovs = *result.aovs;
  for (const Aov pass : passes) {
    switch (pass) {
      case Aov::albedo: out["albedo"] = rgb(aovs.albedo); break;
      case Aov::normal: out["normal"] = rgb(aovs.normal); break;
      case Aov::position: out["position"] = rgb(aovs.position); break;
      case Aov::depth: {
        py::array_t<float> a({h, w});
        std::memcpy(a.mutable_data(), aovs.depth.data(), aovs.depth.size() * sizeof(float));
        out["depth"] = a;
        break;
      }
      case Aov::object: {
        py::array_t<int32_t> a({h, w});
        std::memcpy(a.mutable_data(), aovs.object.data(), aovs.object.size() * sizeof(int32_t));
        out["object"] = a;
        break;
      }
    }
  }
  return py::object(out);
}

RenderOptions options_of(const Request& request, bool aovs) {
  RenderOptions options = render_options(request.width, request.height, request.spp, request.seed, aovs);
  if (request.region) options.region = parse_region(*request.region);
  return options;
}

// The file's content, checked before any work: passes and 32-bit floats only in an .exr, a region
// only as a part (.exr or .pfm).
ExrContent output_content(const Request& request, const std::vector<Aov>& passes) {
  ExrContent content;
  content.passes = passes;
  content.full_float = request.exr_float;
  if (!request.output) {
    if (request.exr_float) throw UsageError("exr_float is for a render to an .exr file");
    return content;
  }
  check_render_output(*request.output, content, request.region.has_value());
  return content;
}

std::vector<Aov> parse_passes(const std::vector<std::string>& names) {
  std::string list;
  for (const auto& name : names) list += (list.empty() ? "" : ",") + name;
  if (list.empty()) return {};
  try {
    return parse_aov_list(list);
  } catch (...) {
    raise_failure(std::current_exception());
  }
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

// Warnings the scene raised, as Python warnings (an exception when the filter turns them into one).
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
  // the file as `vkray render -o` does (a region as a part) and returns None.
  py::object render(const SceneSource& source, const Request& request) {
    const std::vector<Aov> passes = parse_passes(request.aovs);
    auto lock = lock_without_gil();
    if (!session_) raise_failure(std::make_exception_ptr(UsageError("the renderer is closed")));
    struct Done {
      RenderResult result;
      std::shared_ptr<const Scene> scene;
      double load_seconds, upload_seconds;
      bool reused;
    };
    Done done = run_interruptibly([&] {
      const ExrContent content = output_content(request, passes);
      const auto start = Clock::now();
      auto scene = load(source, &meshes_);
      meshes_.keep_only(scene->referenced_files);
      const double load_seconds = seconds_since(start);
      RenderOptions options = options_of(request, !passes.empty());
      image_settings(*scene, options);  // a bad override fails before any upload
      // The last scene goes first when this one needs a new upload, so that both are never on the device.
      std::optional<DeviceScene> on_device;
      if (last_ && same_geometry(last_->scene(), *scene)) on_device = session_->upload_changes(*last_, scene);
      last_.reset();
      if (!on_device) on_device = session_->upload(scene);
      last_ = on_device;
      RenderResult result = session_->render(*on_device, options);
      if (request.output) write_render(*request.output, *scene, result, content, session_->device_description());
      return Done{std::move(result), scene, load_seconds, on_device->upload_seconds(), on_device->shares_geometry()};
    });
    last_stats_ = stats_dict(done.result.stats, done.load_seconds, done.upload_seconds, done.reused);
    last_stats_["region"] = py::make_tuple(done.result.region.x0, done.result.region.y0, done.result.region.x1, done.result.region.y1);
    lock.unlock();  // a warning's handler may use this renderer
    warn_about(*done.scene);
    if (request.output) return py::none();
    return to_numpy(done.result, passes);
  }

  void close() {
    const auto lock = lock_without_gil();
    try {
      release();
    } catch (...) {
      raise_failure(std::current_exception());
    }
  }

  std::string device() const {
    if (!session_) return "";
    return session_->device_description();
  }
  py::object last_stats() const { return last_stats_; }

 private:
  // The renderer's lock, waited for without the GIL: the thread that holds it needs the GIL to
  // check for signals.
  std::unique_lock<std::mutex> lock_without_gil() {
    std::unique_lock lock(mutex_, std::defer_lock);
    py::gil_scoped_release released;
    lock.lock();
    return lock;
  }

  // Releases the device, without the GIL: closing may wait for a tile an interrupt left running.
  void release() {
    last_.reset();
    if (!session_) return;
    std::unique_ptr<Session> session = std::move(session_);
    py::gil_scoped_release released;
    session->close();
  }

  std::mutex mutex_;
  std::unique_ptr<Session> session_;
  MeshCache meshes_;
  std::optional<DeviceScene> last_;
  py::object last_stats_ = py::none();
};

py::object render_cpu(const SceneSource& source, const Request& request, unsigned threads) {
  const std::vector<Aov> passes = parse_passes(request.aovs);
  struct Done {
    RenderResult result;
    std::shared_ptr<const Scene> scene;
  };
  Done done = run_interruptibly([&] {
    const ExrContent content = output_content(request, passes);
    auto scene = load(source, nullptr);
    RenderOptions options = options_of(request, !passes.empty());
    options.threads = threads;
    RenderResult result = render_on_cpu(*scene, options);
    if (request.output) write_render(*request.output, *scene, result, content, kCpuReferenceDevice);
    return Done{std::move(result), scene};
  });
  warn_about(*done.scene);
  if (request.output) return py::none();
  return to_numpy(done.result, passes);
}

// The bands `vkray render --region I/N` renders, all of them (session/regions.h).
py::list bands(const SceneSource& source, uint32_t count, std::optional<uint32_t> width, std::optional<uint32_t> height) {
  struct Done {
    std::vector<PixelRegion> bands;
    std::shared_ptr<const Scene> scene;
  };
  Done done = run_interruptibly([&] {
    auto scene = load(source, nullptr);
    const ImageSettings image = image_settings(*scene, render_options(width, height, std::nullopt, std::nullopt, false));
    return Done{work_bands(*scene, image, count), scene};
  });
  warn_about(*done.scene);
  py::list out;
  for (const PixelRegion& r : done.bands) out.append(py::make_tuple(r.x0, r.y0, r.x1, r.y1));
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

std::string parity(const SceneSource& source, std::optional<uint32_t> width, std::optional<uint32_t> height,
                   std::optional<uint32_t> spp, std::optional<uint32_t> seed, const std::optional<std::string>& device,
                   bool validate, unsigned threads) {
  return run_interruptibly([&] {
    auto scene = load(source, nullptr);
    SessionOptions session_options;
    session_options.device = device.value_or("");
    session_options.validation = validate;
    Session session(session_options);
    RenderOptions options = render_options(width, height, spp, seed, false);
    options.threads = threads;
    const ParityResult result = compare_with_reference(session, scene, options);
    const std::string description = session.device_description();
    session.close();
    return parity_json(result, scene->file.string(), description).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  });
}

py::list devices() {
  std::vector<DeviceInfo> found;
  try {
    found = list_devices();
  } catch (...) {
    raise_failure(std::current_exception());
  }
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
  auto& e = exceptions();
  const auto make = [&](const char* name, py::object base, const char* doc) {
    py::object type = py::reinterpret_steal<py::object>(
        PyErr_NewExceptionWithDoc((std::string("vkray.") + name).c_str(), doc, base.ptr(), nullptr));
    if (!type) throw py::error_already_set();
    m.attr(name) = type;
    return type;
  };
  e.error = make("Error", py::reinterpret_borrow<py::object>(PyExc_Exception), "The base of every error vkray raises.");
  e.scene_error = make("SceneError", e.error,
                       "A scene, a mesh, a shader or an output file cannot be used, or an input is past a limit "
                       "(what exits 1 in the command line); the message names the file and the key or line.");
  e.usage_error = make("UsageError", e.error, "An argument is out of range (what exits 2 in the command line).");
  e.device_error = make("DeviceError", e.error,
                        "Vulkan or the device failed: no such device, a failed call, a validation message, a limit of "
                        "the device (what exits 3 in the command line).");
  e.internal_error = make("InternalError", e.error, "An invariant of vkray's own does not hold: a bug in vkray.");

  py::class_<vp::SceneSource>(m, "_SceneSource")
      .def(py::init([](std::filesystem::path file, std::optional<std::string> text) { return vp::SceneSource{std::move(file), std::move(text)}; }),
           py::arg("file"), py::arg("text") = py::none());

  py::class_<vp::Request>(m, "_Request")
      .def(py::init([](std::optional<uint32_t> width, std::optional<uint32_t> height, std::optional<uint32_t> spp,
                       std::optional<uint32_t> seed, std::vector<std::string> aovs, std::optional<std::string> region,
                       std::optional<std::filesystem::path> output, bool exr_float) {
             return vp::Request{width, height, spp, seed, std::move(aovs), std::move(region), std::move(output), exr_float};
           }),
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
        [](const std::filesystem::path& output, const std::vector<std::string>& aovs, bool exr_float, bool part) {
          vp::Request request;
          request.output = output;
          request.aovs = aovs;
          request.exr_float = exr_float;
          if (part) request.region = "0/1";
          try {
            vp::output_content(request, vp::parse_passes(aovs));
          } catch (const py::error_already_set&) {
            throw;
          } catch (...) {
            vp::raise_failure(std::current_exception());
          }
        },
        py::arg("output"), py::arg("aovs"), py::arg("exr_float"), py::arg("part"),
        "Raises what a render to `output` would before any work: SceneError for a path that cannot be written "
        "(exit 1), UsageError for what cannot be asked of its type (exit 2).");
  m.def("parity", &vp::parity, py::arg("source"), py::arg("width"), py::arg("height"), py::arg("spp"), py::arg("seed"),
        py::arg("device"), py::arg("validate"), py::arg("threads"));
  m.def("devices", &vp::devices);
  m.def("_shader_dir", [] { return vkray::default_shader_dir(); }, "Where the shaders are compiled from by default.");
  m.attr("__version__") = vkray::version_string();
}
