// SIGINT and SIGTERM delivered through a file descriptor instead of killing the process, so a
// command can stop between units of work, release the device and exit cleanly.
#pragma once

#include <poll.h>
#include <signal.h>
#include <sys/signalfd.h>
#include <unistd.h>

namespace vkray {

// Blocks SIGINT and SIGTERM while it exists; restores the signal mask when destroyed.
class StopSignals {
 public:
  StopSignals() {
    sigemptyset(&set_);
    sigaddset(&set_, SIGINT);
    sigaddset(&set_, SIGTERM);
    sigprocmask(SIG_BLOCK, &set_, &previous_);
    fd_ = signalfd(-1, &set_, SFD_CLOEXEC | SFD_NONBLOCK);
  }
  ~StopSignals() {
    // Consume the signals that stopped us: left pending, they would be delivered (and kill the
    // process) the moment the mask is restored.
    signalfd_siginfo info;
    while (::read(fd_, &info, sizeof info) == sizeof info) {
    }
    ::close(fd_);
    sigprocmask(SIG_SETMASK, &previous_, nullptr);
  }
  int fd() const { return fd_; }
  bool pending() const {
    pollfd p{fd_, POLLIN, 0};
    return ::poll(&p, 1, 0) > 0;
  }

 private:
  sigset_t set_{}, previous_{};
  int fd_ = -1;
};

}  // namespace vkray
