// A call from Python into the library, as every binding of the module makes it. What it guarantees:
//
// - Off the GIL: the library's work runs on a thread of its own with the GIL released, so other
//   Python threads run meanwhile, while the calling thread runs Python's signal handlers every 50 ms
//   (on the main thread; elsewhere there are none to run).
// - Ctrl-C on any thread: Python runs signal handlers on the main thread only, so a render on another
//   thread would never hear of Ctrl-C. While SIGINT means KeyboardInterrupt (Python's default
//   handler), a SIGINT also asks the library to stop (base/interrupt.h): every call in flight stops
//   within a fraction of a second and raises KeyboardInterrupt, whatever the main thread is doing.
//   Any exception a signal handler raises while the main thread waits for its call also asks the
//   library to stop, and is raised once the call's work has ended: the library has one request to
//   stop for the whole process, so that stops every call in flight, each other one raising
//   KeyboardInterrupt.
// - In flight from first step to last: a call is registered as work in flight (base/interrupt.h)
//   for all its steps (loading, then rendering), so that a stop between two steps still stops it,
//   and one that came while nothing was in flight does not stop it.
// - The end of the interpreter: at exit (atexit: after the non-daemon threads were joined, before
//   finalization) every call in flight is stopped and waited for; from then on a thread other than
//   the one ending the interpreter that would take the GIL back, or start a call, is parked for good
//   (as CPython 3.14 itself does with such threads), rather than be ended by CPython with a forced
//   unwind through C++ frames, which calls std::terminate (SIGABRT). The process ends around it.
// - fork(): what was opened in the parent (a Renderer's device) is neither used nor released in a
//   child, where the driver's threads did not come along.
#pragma once

#include <pybind11/pybind11.h>
#include <unistd.h>

#include <cstddef>
#include <functional>
#include <mutex>
#include <optional>
#include <type_traits>
#include <utility>

namespace vkray::python {

// The GIL given up for the scope and taken back at its end, unless the interpreter is ending: then
// the thread is parked for good (unless it is the one ending it).
class WithoutGil {
 public:
  WithoutGil();
  ~WithoutGil();
  WithoutGil(const WithoutGil&) = delete;
  WithoutGil& operator=(const WithoutGil&) = delete;

 private:
  PyThreadState* state_;
};

// Marks a call from Python in flight for its lifetime, unless it is made from within one on this
// thread (a warning's handler that renders), which it joins. Made with the GIL; waits without it
// while a stop request ends the work in flight, and parks the thread once the interpreter is ending.
class CallInFlight {
 public:
  CallInFlight();
  ~CallInFlight();
  CallInFlight(const CallInFlight&) = delete;
  CallInFlight& operator=(const CallInFlight&) = delete;

 private:
  bool owner_ = false;
};

// Runs `work` as part of this thread's call (one of its own if there is none), on a thread of its own
// with the GIL released, and returns its result; raises its failure as vkray's exception
// (python/exceptions.h), an interrupt as KeyboardInterrupt, and a signal handler's exception as
// itself once `work` has stopped.
void run_work_interruptibly(const std::function<void()>& work);
template <typename Work>
auto run_interruptibly(Work&& work) -> decltype(work()) {
  using Result = decltype(work());
  if constexpr (std::is_void_v<Result>) {
    run_work_interruptibly(work);
  } else {
    std::optional<Result> result;
    run_work_interruptibly([&] { result.emplace(work()); });
    return std::move(*result);
  }
}

// Locks `mutex`, waiting for it without the GIL: the thread that holds it needs the GIL to check for
// signals. A thread that holds it may be parked at the end of the interpreter, so a waiter looks for
// that end between tries (and is parked too).
std::unique_lock<std::timed_mutex> lock_without_gil(std::timed_mutex& mutex);

// Registers the stop of every call at the end of the interpreter with atexit; once, as the module loads.
void stop_calls_at_exit();

// How many calls from Python are in flight in this process now (a test waits for its renders to start).
size_t calls_in_flight();

// The process that opened a Renderer, whose device a child made by fork() can neither use (it would
// wait for ever) nor release (that would wait for driver threads that did not come along).
class OpenedInProcess {
 public:
  bool forked() const { return ::getpid() != pid_; }
  // Raises UsageError in a child made by fork(), saying what to do instead.
  void check_not_forked() const;

 private:
  const pid_t pid_ = ::getpid();
};

}  // namespace vkray::python
