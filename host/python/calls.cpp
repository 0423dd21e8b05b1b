#include "python/calls.h"

#include <pthread.h>
#include <signal.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <future>
#include <memory>
#include <string>
#include <thread>

#include "base/errors.h"
#include "base/interrupt.h"
#include "base/per_process.h"
#include "python/exceptions.h"

namespace py = pybind11;

namespace vkray::python {
namespace {

// ---- The end of the interpreter --------------------------------------------------------------------
// Taking the GIL back is where the end of the interpreter strikes: once it finalizes, CPython ends
// (pthread_exit) any other thread that asks for the GIL, and that forced unwind through this module's
// C++ frames calls std::terminate (SIGABRT); a render still running would meanwhile use the driver
// while the process tears it down. Hence the parking (calls.h).
struct InterpreterEnd {
  std::mutex mutex;
  bool ending = false;
  std::thread::id thread;  // the thread ending the interpreter, which goes on
};
InterpreterEnd& interpreter_end() {
  static PerProcess<InterpreterEnd> end;
  return end.get();
}

// Calls from Python in flight: the library's work in flight, counted.
std::atomic<size_t> registered_calls{0};
[[maybe_unused]] const int registered_calls_remade =
    ::pthread_atfork(nullptr, nullptr, [] { registered_calls.store(0); });  // the parent's did not come along

struct RegisteredCall {
  WorkInFlight work;  // first: made (waiting out a stop) before the call counts, ended after it stops counting
  RegisteredCall() { ++registered_calls; }
  ~RegisteredCall() { --registered_calls; }
  RegisteredCall(const RegisteredCall&) = delete;
  RegisteredCall& operator=(const RegisteredCall&) = delete;
};

// The work in flight of the call from Python this thread is making: from its first step to its last,
// so that Ctrl-C between two steps (loading, then rendering) still stops the call.
thread_local std::shared_ptr<RegisteredCall> call_in_flight;

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
// The module wraps Python's C-level SIGINT handler in one that also asks the library to stop.
// signal.signal() removes the wrapper as it installs its own handler; each call looks again as it
// starts.
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

}  // namespace

WithoutGil::WithoutGil() : state_(PyEval_SaveThread()) {}

WithoutGil::~WithoutGil() {
  const auto lock = lock_unless_ending();  // held until the GIL is back: the end cannot come between
  PyEval_RestoreThread(state_);
}

CallInFlight::CallInFlight() {
  if (call_in_flight) return;
  owner_ = true;
  WithoutGil released;  // its end parks the thread, once the call is registered for end_interpreter() to stop
  call_in_flight = std::make_shared<RegisteredCall>();
}

CallInFlight::~CallInFlight() {
  if (owner_) call_in_flight.reset();
}

// A handler's exception (KeyboardInterrupt) asks the library to stop, waits for it (the library stops
// within a fraction of a second) and is raised; a stop that came from elsewhere (Ctrl-C while the main
// thread does something else) raises KeyboardInterrupt.
void run_work_interruptibly(const std::function<void()>& work) {
  follow_ctrl_c();
  const CallInFlight call;
  std::future<void> done = std::async(std::launch::async, [flight = call_in_flight, &work]() mutable {
    const std::shared_ptr<RegisteredCall> in_flight = std::move(flight);  // until the work ends, not the future
    work();
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
    done.get();
  } catch (const Cancelled&) {
    // Ctrl-C: on the main thread, Python's own KeyboardInterrupt, once, rather than ours and then its.
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    raise_failure(std::current_exception());
  } catch (...) {
    raise_failure(std::current_exception());
  }
}

std::unique_lock<std::timed_mutex> lock_without_gil(std::timed_mutex& mutex) {
  std::unique_lock lock(mutex, std::defer_lock);
  WithoutGil released;
  while (!lock.try_lock_for(std::chrono::milliseconds(50))) lock_unless_ending();
  return lock;
}

void stop_calls_at_exit() { py::module_::import("atexit").attr("register")(py::cpp_function(&end_interpreter)); }

size_t calls_in_flight() { return registered_calls.load(); }

void OpenedInProcess::check_not_forked() const {
  if (forked())
    throw UsageError("this vkray.Renderer was opened in process " + std::to_string(pid_) +
                     ", and a process made by fork() cannot use its device: open a Renderer in this process, or start "
                     "processes with multiprocessing's 'spawn' method");
}

}  // namespace vkray::python
