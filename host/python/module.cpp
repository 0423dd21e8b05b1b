// vkray._vkray: the Python face on the library (python/vkray/__init__.py is the package around it).
// It maps Python's arguments onto the library's options, checked against the library's limits as
// the command line checks its flags, and the library's results onto numpy arrays, and each kind of
// error (base/errors.h, session/failure.h) onto one exception class; everything else is the
// library's. Long calls run on a thread of their own with the GIL released, while the calling thread
// polls for signals; Ctrl-C reaches a render on any thread, and the end of the interpreter or a
// fork() finds no render of this module half-done.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "base/errors.h"
#include "base/interrupt.h"
#include "base/json_document.h"
#include "base/threads.h"
#include "base/timing.h"
#include "image/aovs.h"
#include "image/exr.h"
#include "image/image_file.h"
#include "image/merge.h"
#include "session/cpu_render.h"
#include "session/failure.h"
#include "session/options.h"
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

// Sets the Python exception for `error` (a Cancelled as KeyboardInterrupt).
void set_failure(const std::exception_ptr& error) {
  const Failure failure = describe_failure(error);
  py::object type;
  switch (failure.exit_code) {
    case kExitBadInput: type = exceptions().scene_error; break;
    case kExitUsage: type = exceptions().usage_error; break;
    case kExitDevice: type = exceptions().device_error; break;
    case kExitInterrupted: PyErr_SetNone(PyExc_KeyboardInterrupt); return;
    default: type = exceptions().internal_error; break;
  }
  PyErr_SetString(type.ptr(), failure.message.c_str());
}

[[noreturn]] void raise_failure(const std::exception_ptr& error) {
  set_failure(error);
  throw py::error_already_set();
}

// ---- The end of the interpreter --------------------------------------------------------------------
// Work runs on threads of its own while its caller waits without the GIL. Taking the GIL back is where
// the end of the interpreter strikes: once it finalizes, CPython ends (pthread_exit) any other thread
// that asks for the GIL, and that forced unwind through this module's C++ frames calls std::terminate
// (SIGABRT); a render still running would meanwhile use the driver while the process tears it down.
// So at exit (atexit: after the non-daemon threads were joined, before finalization) the module stops
// every piece of work in flight and waits for it, and from then on a thread other than the one ending
// the interpreter that would take the GIL back, or start work, is parked for good instead, as CPython
// 3.14 itself does with such threads. The process then ends around it.
struct InterpreterEnd {
  std::mutex mutex;
  bool ending = false;
  std::thread::id thread;  // the thread ending the interpreter, which goes on
};
InterpreterEnd& interpreter_end() {
  static PerProcess<InterpreterEnd> end;
  [[maybe_unused]] static const int remade = ::pthread_atfork(nullptr, nullptr, [] { end.remake(); });
  return end.get();
}

// The work in flight (base/interrupt.h) of the call from Python this thread is making: from its first
// step to its last, so that Ctrl-C between two steps (loading, then rendering) still stops the call.
thread_local std::shared_ptr<WorkInFlight> call_in_flight;

// The end's lock, held; or, once the interpreter is ending, for any thread but the one ending it,
// never: the thread is parked for good, its call no longer in flight.
std::unique_lock<std::mutex> lock_unless_ending() {
  InterpreterEnd& end = interpreter_end();
  std::unique_lock lock(end.mutex);
  if (!end.ending || std::this_thread::get_id() == end.thread) return lock;
  lock.unlock();
  call_in_flight.reset();  // end_interpreter() waits for it
  for (;;) ::pause();
}

// The GIL given up for the scope and taken back at its end, unless the interpreter is ending.
class WithoutGil {
 public:
  WithoutGil() : state_(PyEval_SaveThread()) {}
  ~WithoutGil() {
    const auto lock = lock_unless_ending();  // held until the GIL is back: the end cannot come between
    PyEval_RestoreThread(state_);
  }
  WithoutGil(const WithoutGil&) = delete;
  WithoutGil& operator=(const WithoutGil&) = delete;

 private:
  PyThreadState* state_;
};

// Marks the call in flight for its lifetime, unless it is made from within one on this thread (a
// warning's handler that renders), which it joins. Waits without the GIL while a stop request ends
// the work in flight; parks the thread once the interpreter is ending.
class CallInFlight {
 public:
  CallInFlight() {
    if (call_in_flight) return;
    owner_ = true;
    WithoutGil released;  // its end parks the thread, once the call is registered for end_interpreter() to stop
    call_in_flight = std::make_shared<WorkInFlight>();
  }
  ~CallInFlight() {
    if (owner_) call_in_flight.reset();
  }
  CallInFlight(const CallInFlight&) = delete;
  CallInFlight& operator=(const CallInFlight&) = delete;

 private:
  bool owner_ = false;
};

// Called by atexit on the thread that ends the interpreter, with the GIL.
void end_interpreter() {
  WithoutGil released;  // for a thread that waits to take it back and park
  {
    InterpreterEnd& end = interpreter_end();
    const std::lock_guard lock(end.mutex);
    end.ending = true;
    end.thread = std::this_thread::get_id();
  }
  stop_work_in_flight();
}

// ---- Ctrl-C on any thread ---------------------------------------------------------------------------
// Python runs signal handlers on the main thread only, so a render on another thread would never hear
// of Ctrl-C. While SIGINT means KeyboardInterrupt (Python's default handler), the module wraps
// Python's C-level handler in one that also asks the library to stop: every render in flight stops,
// each raising KeyboardInterrupt, whatever the main thread is doing. signal.signal() removes the
// wrapper as it installs its own handler; each render looks again as it starts.
std::atomic<void (*)(int)> python_sigint_handler{nullptr};

extern "C" void on_sigint(int signal) {
  const int saved = errno;
  request_interrupt();  // async-signal-safe
  errno = saved;
  if (void (*python)(int) = python_sigint_handler.load()) python(signal);
}

// With the GIL (which serializes it with signal.signal()).
void follow_ctrl_c() {
  static const auto* const signal_module = new py::module_(py::module_::import("signal"));
  static const auto* const default_handler = new py::object(signal_module->attr("default_int_handler"));
  struct sigaction now {};
  if (::sigaction(SIGINT, nullptr, &now) != 0) return;
  const bool wrapped = !(now.sa_flags & SA_SIGINFO) && now.sa_handler == on_sigint;
  const bool keyboard_interrupt = signal_module->attr("getsignal")(int(SIGINT)).is(*default_handler);
  if (keyboard_interrupt && !wrapped && !(now.sa_flags & SA_SIGINFO) && now.sa_handler != SIG_DFL && now.sa_handler != SIG_IGN) {
    python_sigint_handler.store(now.sa_handler);
    struct sigaction wrapper = now;
    wrapper.sa_handler = on_sigint;
    ::sigaction(SIGINT, &wrapper, nullptr);
  } else if (!keyboard_interrupt && wrapped) {  // another handler set without signal.signal()
    now.sa_handler = python_sigint_handler.load();
    ::sigaction(SIGINT, &now, nullptr);
  }
}

// Runs `work` on a thread of its own with the GIL released, in flight as part of the call; the
// calling thread runs Python's signal handlers every 50 ms (on the main thread; elsewhere there are
// none to run). A handler's exception (KeyboardInterrupt) asks the library to stop, waits for it (the
// library stops within a fraction of a second) and is raised; a stop that came from elsewhere (Ctrl-C
// while the main thread does something else) raises KeyboardInterrupt.
template <typename Work>
auto run_interruptibly(Work&& work) -> decltype(work()) {
  follow_ctrl_c();
  const CallInFlight call;
  std::future<decltype(work())> done = std::async(std::launch::async, [flight = call_in_flight, &work]() mutable {
    const std::shared_ptr<WorkInFlight> in_flight = std::move(flight);  // until the work ends, not the future
    return work();
  });
  while (true) {
    {
      WithoutGil released;
      if (done.wait_for(std::chrono::milliseconds(50)) == std::future_status::ready) break;
    }
    if (PyErr_CheckSignals() != 0) {
      py::error_already_set raised;  // KeyboardInterrupt, or what a signal handler raised
      request_interrupt();
      {
        WithoutGil released;
        done.wait();
      }
      throw raised;
    }
  }
  try {
    return done.get();
  } catch (const Cancelled&) {
    // Ctrl-C: on the main thread, Python's own KeyboardInterrupt, once, rather than ours and then its.
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    raise_failure(std::current_exception());
  } catch (...) {
    raise_failure(std::current_exception());
  }
}

// ---- Arguments --------------------------------------------------------------------------------------
// Numbers as the command line checks its flags (session/options.h's limits, the same messages): None
// is "not given"; an int (numpy's too, but not a bool) within the limit is taken; anything else is a
// UsageError naming the argument.
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

// A thread count: 0 (the default) or None is one per hardware thread, as the library's 0.
unsigned thread_count_argument(const py::handle& value) {
  if (PyLong_Check(value.ptr()) && !PyBool_Check(value.ptr()) && py::int_(0).equal(value)) return 0;
  return number(value, kThreadsArgument).value_or(0);
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
  return list.empty() ? std::vector<Aov>{} : parse_aov_list(list);
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
      ExrContent content;
      double seconds;
    };
    const CallInFlight call;  // before the lock: a call in flight may be waiting for it
    auto lock = usable_without_gil();
    const Loaded loaded = run_interruptibly([&] {
      const ExrContent content = output_content(request, passes);
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
    if (forked()) return abandon();
    const CallInFlight call;  // before the lock: a call in flight may be waiting for it
    const auto lock = lock_without_gil();
    release();
  }

  std::string device() const {
    if (!session_) return "";
    return session_->device_description();
  }
  py::object last_stats() const { return last_stats_; }

 private:
  bool forked() const { return ::getpid() != opened_in_; }

  // In a child made by fork(), the device is the parent's: using it would wait for ever, and
  // destroying it would wait for driver threads that did not come along. It is left as it is.
  void abandon() {
    new std::optional<DeviceScene>(std::exchange(last_, std::nullopt));
    static_cast<void>(session_.release());
  }

  // The renderer's lock, waited for without the GIL: the thread that holds it needs the GIL to
  // check for signals. A thread that holds it may be parked at the end of the interpreter, so a
  // waiter looks for that end between tries.
  std::unique_lock<std::timed_mutex> lock_without_gil() {
    std::unique_lock lock(mutex_, std::defer_lock);
    WithoutGil released;
    while (!lock.try_lock_for(std::chrono::milliseconds(50))) lock_unless_ending();
    return lock;
  }

  // The lock, once the renderer is known to be usable in this process and open.
  std::unique_lock<std::timed_mutex> usable_without_gil() {
    if (forked())
      throw UsageError("this vkray.Renderer was opened in process " + std::to_string(opened_in_) +
                       ", and a process made by fork() cannot use its device: open a Renderer in this process, or start "
                       "processes with multiprocessing's 'spawn' method");
    auto lock = lock_without_gil();
    if (!session_) throw UsageError("the renderer is closed");
    return lock;
  }

  // Releases the device, without the GIL: closing may wait for a tile an interrupt left running.
  void release() {
    if (forked()) return abandon();
    last_.reset();
    if (!session_) return;
    std::unique_ptr<Session> session = std::move(session_);
    const CallInFlight call;  // the end of the interpreter waits for it
    WithoutGil released;
    session->close();
  }

  const pid_t opened_in_ = ::getpid();
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
    ExrContent content;
  };
  const CallInFlight call;
  const Loaded loaded = run_interruptibly([&] {
    const ExrContent content = output_content(request, passes);
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
  // What the library throws outside run_interruptibly() (an argument checked on the calling thread, a
  // device closed), as it would be raised from a render.
  py::register_exception_translator([](std::exception_ptr error) {
    try {
      if (error) std::rethrow_exception(error);
    } catch (const py::builtin_exception&) {
      throw;  // pybind11's own, for its own translator
    } catch (const std::exception&) {
      set_failure(error);
    }
  });
  py::module_::import("atexit").attr("register")(py::cpp_function(&end_interpreter));

  py::class_<vp::SceneSource>(m, "_SceneSource")
      .def(py::init([](std::filesystem::path file, std::optional<std::string> text) { return vp::SceneSource{std::move(file), std::move(text)}; }),
           py::arg("file"), py::arg("text") = py::none());

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
  m.def("_shader_dir", [] { return vkray::default_shader_dir(); }, "Where the shaders are compiled from by default.");
  m.attr("_MAX_JSON_DEPTH") = vkray::kMaxJsonDepth;
  m.attr("__version__") = vkray::version_string();
}
