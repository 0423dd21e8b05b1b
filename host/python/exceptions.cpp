#include "python/exceptions.h"

#include <string>

#include "base/errors.h"
#include "session/failure.h"

namespace py = pybind11;

namespace vkray::python {
namespace {

// The exception classes, made in add_exceptions().
struct Exceptions {
  py::object error, scene_error, usage_error, device_error, internal_error;
};
Exceptions& exceptions() {
  static Exceptions* e = new Exceptions();  // never destroyed: outlives the interpreter's teardown
  return *e;
}

}  // namespace

void add_exceptions(py::module_& m) {
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
}

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

void raise_failure(const std::exception_ptr& error) {
  set_failure(error);
  throw py::error_already_set();
}

}  // namespace vkray::python
