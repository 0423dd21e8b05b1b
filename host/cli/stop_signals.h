// SIGINT and SIGTERM, the same for every command. main() creates one StopSignals before any other
// thread exists: the signals are blocked in every thread, and a thread of its own reads them and
// turns them into the library's interrupt request (base/interrupt.h), at which the command unwinds
// at its next check (a row, a tile, a chunk of a file, a node of the BVH) and exits 130, having
// written nothing. A stage that cannot be interrupted (a driver compiling a pipeline, say) is not
// waited for past kGrace: the thread then removes the temporary outputs and ends the process itself,
// with the same exit code and message. SIGPIPE and SIGXFSZ are ignored: a closed stderr or a file
// size limit fails a write, which is reported, instead of killing the process halfway.
#pragma once

#include <atomic>
#include <chrono>
#include <thread>

namespace vkray::cli {

class StopSignals {
 public:
  static constexpr std::chrono::milliseconds kGrace{500};

  StopSignals();
  ~StopSignals();  // stops the thread; the signals stay blocked until the process ends
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // What a forced exit reports: by default exit 130, "interrupted; no image written". `vkray watch`,
  // which Ctrl-C ends normally, exits 0.
  // `message` is a string literal (it is read by the signal thread at any time).
  void set_forced_exit(int exit_code, const char* message);

 private:
  void run();

  int signal_fd_ = -1;
  int done_fd_ = -1;  // readable once the command has ended
  std::atomic<int> exit_code_;
  std::atomic<const char*> message_;
  std::thread thread_;
};

}  // namespace vkray::cli
