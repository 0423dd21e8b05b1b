// How many threads vkray's CPU work uses when the user names no number (one per hardware thread),
// and the most a user may name; and state that a child made by fork(), which has one thread, makes
// afresh.
#pragma once

#include <algorithm>
#include <new>
#include <thread>

namespace vkray {

// The most threads a caller may ask for (`--threads`, threads=): more is a mistake, not a machine,
// and each is a thread started.
constexpr unsigned kMaxThreads = 256;

// `requested`, or one per hardware thread (at least one) when it is 0.
inline unsigned thread_count(unsigned requested = 0) {
  return requested ? requested : std::max(1u, std::thread::hardware_concurrency());
}

// An object of the process, made afresh in a child made by fork(): the child has only the thread that
// forked, and what the parent's other threads held in the old one (a lock, work in flight) would be
// held for ever there. The old one is left as it is; none is ever destroyed (a late user at the
// process's end finds it). Kept in a function-local static, with the remaking registered beside it:
//   static PerProcess<Registry> registry;
//   static const int remade = pthread_atfork(nullptr, nullptr, [] { registry.remake(); });
template <typename T>
class PerProcess {
 public:
  PerProcess() { remake(); }
  T& get() { return *std::launder(reinterpret_cast<T*>(storage_)); }
  void remake() { new (storage_) T(); }

 private:
  alignas(T) unsigned char storage_[sizeof(T)];
};

}  // namespace vkray
