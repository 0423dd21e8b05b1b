// vkray's exception classes in Python: each kind of failure (base/errors.h, session/failure.h) is
// one class, raised with the library's message, and an interrupt (Cancelled) is KeyboardInterrupt.
// Whatever leaves the library, on a call's own thread or on the calling one, is raised this way.
#pragma once

#include <pybind11/pybind11.h>

#include <exception>

namespace vkray::python {

// Makes vkray.Error and its subclasses (SceneError, UsageError, DeviceError, InternalError) in `m`,
// and raises what the library throws from a binding as the matching class.
void add_exceptions(pybind11::module_& m);

// Sets the Python exception for `error` (a Cancelled as KeyboardInterrupt).
void set_failure(const std::exception_ptr& error);
// Sets it and throws pybind11's error_already_set, which raises it.
[[noreturn]] void raise_failure(const std::exception_ptr& error);

}  // namespace vkray::python
