// An object of the process that a child made by fork() makes afresh. The child has only the thread
// that called fork(): what the parent's other threads held in the parent's object (a lock, a count of
// work in flight, a Vulkan instance whose driver threads did not come along) would be held for ever
// there. So in the child the holder points at a new object, and the parent's is left as it is: never
// used there, and never destroyed, since its destructor might wait for those threads or call into the
// driver. No object is destroyed at the process's end either, so that a late user (a forced exit)
// still finds one. Kept in a function-local static:
//   static PerProcess<Registry> registry;
//   registry.get().add(...);
// The holder registers itself for the remaking when it is made; its users register nothing.
#pragma once

#include <pthread.h>
#include <unistd.h>

#include <atomic>

namespace vkray {
namespace per_process {

// Every holder of the process, newest first, linked as it is made; holders are never destroyed.
struct Holder {
  void (*remake)(Holder*);
  Holder* older = nullptr;
};

inline std::atomic<Holder*>& newest() {
  static std::atomic<Holder*> holder{nullptr};
  return holder;
}

// Oldest first, in a child made by fork(), which has one thread.
inline void remake_from(Holder* holder) noexcept {
  if (!holder) return;
  remake_from(holder->older);
  holder->remake(holder);
}
inline void remake_all_in_child() noexcept { remake_from(newest().load(std::memory_order_acquire)); }

// Links `holder` in; the first one registers the one fork handler for all.
inline void add(Holder* holder) {
  [[maybe_unused]] static const int registered = ::pthread_atfork(nullptr, nullptr, remake_all_in_child);
  holder->older = newest().load(std::memory_order_relaxed);
  while (!newest().compare_exchange_weak(holder->older, holder, std::memory_order_release, std::memory_order_relaxed)) {
  }
}

}  // namespace per_process

template <typename T>
class PerProcess : per_process::Holder {
 public:
  PerProcess() : Holder{&remake_holder}, object_(new T()), made_in_(::getpid()) { per_process::add(this); }
  PerProcess(const PerProcess&) = delete;
  PerProcess& operator=(const PerProcess&) = delete;

  T& get() { return *object_; }

  // A new object, unless the one held was made in this process (then nothing changes): the fork
  // handler calls it in a child, and a second call there is harmless.
  void remake() {
    const pid_t process = ::getpid();
    if (process == made_in_) return;
    parents_ = object_;
    object_ = new T();
    made_in_ = process;
  }

 private:
  static void remake_holder(Holder* holder) { static_cast<PerProcess*>(holder)->remake(); }

  T* object_;
  pid_t made_in_;  // the process that made object_
  T* parents_ = nullptr;  // the parent's object, left as it is (and held, for a leak checker)
};

}  // namespace vkray
