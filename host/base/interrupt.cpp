#include "base/interrupt.h"

#include <pthread.h>
#include <sys/eventfd.h>
#include <stdlib.h>
#include <unistd.h>

#include <cstdint>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <vector>

#include "base/errors.h"
#include "base/per_process.h"

namespace vkray {
namespace {

std::atomic<bool> requested{false};
static_assert(std::atomic<bool>::is_always_lock_free, "request_interrupt() must be async-signal-safe");
// Created before main(), so that request_interrupt() never has to create it.
int event_fd = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);

struct TemporaryFiles {
  std::mutex mutex;
  std::vector<std::filesystem::path> files;
  bool closed = false;  // set by remove_temporary_files(): the process is about to end
};
TemporaryFiles& temporary_files() {
  static PerProcess<TemporaryFiles> files;  // a forced exit may use it late
  return files.get();
}

struct Flight {
  std::mutex mutex;
  std::condition_variable ended;  // notified when the count falls to 0
  size_t count = 0;
};
Flight& flight() {
  static PerProcess<Flight> flight;
  return flight.get();
}

// A forked child has one thread, the one that called fork(): the parent's request stays the parent's,
// and the parent's descriptor would share its counter. (Its work in flight and its temporary files,
// which the child must not remove, stay the parent's too: PerProcess.)
void in_forked_child() noexcept {
  requested.store(false, std::memory_order_relaxed);
  ::close(event_fd);
  event_fd = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
}
[[maybe_unused]] const int fork_handler = ::pthread_atfork(nullptr, nullptr, in_forked_child);

}  // namespace

void request_interrupt() noexcept {
  requested.store(true, std::memory_order_relaxed);
  const uint64_t one = 1;
  [[maybe_unused]] const ssize_t written = ::write(event_fd, &one, sizeof one);  // write(2) is async-signal-safe
}
bool interrupt_requested() noexcept { return requested.load(std::memory_order_relaxed); }
void clear_interrupt() noexcept {
  requested.store(false, std::memory_order_relaxed);
  uint64_t count = 0;
  [[maybe_unused]] const ssize_t read = ::read(event_fd, &count, sizeof count);  // resets the counter
}
int interrupt_fd() noexcept { return event_fd; }
void throw_if_interrupted() {
  if (interrupt_requested()) throw Cancelled();
}

WorkInFlight::WorkInFlight() {
  Flight& f = flight();
  std::unique_lock lock(f.mutex);
  f.ended.wait(lock, [&] { return f.count == 0 || !interrupt_requested(); });
  if (f.count == 0 && interrupt_requested()) clear_interrupt();  // nothing was in flight to stop
  ++f.count;
}

WorkInFlight::~WorkInFlight() {
  Flight& f = flight();
  const std::lock_guard lock(f.mutex);
  if (--f.count > 0) return;
  if (interrupt_requested()) clear_interrupt();
  f.ended.notify_all();
}

void stop_work_in_flight() noexcept {
  Flight& f = flight();
  std::unique_lock lock(f.mutex);
  if (f.count == 0) return;
  request_interrupt();
  f.ended.wait(lock, [&] { return f.count == 0; });
}

int create_temporary_file(std::string& pattern) {
  TemporaryFiles& t = temporary_files();
  const std::lock_guard lock(t.mutex);
  if (t.closed || interrupt_requested()) throw Cancelled();
  const int fd = ::mkstemp(pattern.data());
  if (fd >= 0) t.files.push_back(pattern);
  return fd;
}

void unregister_temporary_file(const std::filesystem::path& file) {
  TemporaryFiles& t = temporary_files();
  const std::lock_guard lock(t.mutex);
  t.files.erase(std::remove(t.files.begin(), t.files.end(), file), t.files.end());
}

void commit_unless_interrupted(const std::filesystem::path& file, const std::function<void()>& commit) {
  TemporaryFiles& t = temporary_files();
  const std::lock_guard lock(t.mutex);
  if (t.closed || interrupt_requested()) throw Cancelled();
  commit();
  t.files.erase(std::remove(t.files.begin(), t.files.end(), file), t.files.end());
}

void remove_temporary_files() noexcept {
  TemporaryFiles& t = temporary_files();
  // Held for good: no file may be created or committed after this, and the process ends right
  // after (a thread that asks for the lock waits for that end).
  t.mutex.lock();
  t.closed = true;
  for (const auto& file : t.files) ::unlink(file.c_str());
  t.files.clear();
}

}  // namespace vkray
