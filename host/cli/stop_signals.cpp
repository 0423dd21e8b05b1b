#include "cli/stop_signals.h"

#include <poll.h>
#include <signal.h>
#include <sys/eventfd.h>
#include <sys/signalfd.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "base/errors.h"
#include "base/interrupt.h"

namespace vkray::cli {

StopSignals::StopSignals() : exit_code_(kExitInterrupted), message_("interrupted; no image written") {
  // Two signals would end the process halfway through writing its image, leaving the temporary
  // file: a reader that closes its end of stderr (`vkray render ... 2>&1 | head -1`; the write
  // fails with EPIPE instead) and a file past the size limit (`ulimit -f`; EFBIG, an OutputError).
  ::signal(SIGPIPE, SIG_IGN);
  ::signal(SIGXFSZ, SIG_IGN);
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  done_fd_ = eventfd(0, EFD_CLOEXEC);
  signal_fd_ = done_fd_ < 0 ? -1 : signalfd(-1, &set, SFD_CLOEXEC);
  if (signal_fd_ < 0) {
    // No descriptors left (`ulimit -n`): the signals keep their default action, which ends the
    // process at once, rather than being blocked with nobody to read them.
    if (done_fd_ >= 0) ::close(done_fd_);
    done_fd_ = -1;
    return;
  }
  // Every thread created after this (the driver's, the CPU reference's) inherits the mask.
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  thread_ = std::thread([this] { run(); });
}

StopSignals::~StopSignals() {
  if (!thread_.joinable()) return;
  const uint64_t one = 1;
  [[maybe_unused]] const ssize_t written = ::write(done_fd_, &one, sizeof one);
  thread_.join();
  ::close(signal_fd_);
  ::close(done_fd_);
}

void StopSignals::set_forced_exit(int exit_code, const char* message) {
  exit_code_ = exit_code;
  message_ = message;
}

void StopSignals::run() {
  pollfd fds[] = {{signal_fd_, POLLIN, 0}, {done_fd_, POLLIN, 0}};
  while (::poll(fds, 2, -1) < 0) {
  }
  if (fds[1].revents != 0) return;  // the command ended without a signal
  signalfd_siginfo info;
  [[maybe_unused]] const ssize_t got = ::read(signal_fd_, &info, sizeof info);
  request_interrupt();
  // The command now unwinds; give it kGrace to do so.
  pollfd done{done_fd_, POLLIN, 0};
  int ready;
  while ((ready = ::poll(&done, 1, int(kGrace.count()))) < 0) {
  }
  if (ready > 0) return;
  remove_temporary_files();
  char line[128];  // no allocation here: nothing may throw on this thread
  const int length = std::snprintf(line, sizeof line, "vkray: %s\n", message_.load());
  [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, line, size_t(std::min(length, int(sizeof line) - 1)));
  std::_Exit(exit_code_);
}

}  // namespace vkray::cli
