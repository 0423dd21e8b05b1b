// A child process whose stderr a test reads line by line as it runs, to drive long-running
// commands (vkray watch) by what they print instead of by sleeping.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace vkray::test {

class ChildProcess {
 public:
  // Runs `argv` in `cwd` with `env` ("NAME=value") added to this process's environment; stdout is
  // discarded, stderr is captured.
  ChildProcess(const std::vector<std::string>& argv, const std::string& cwd, const std::vector<std::string>& env = {});
  ~ChildProcess();  // kills the process if it is still running
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  // The next stderr line that contains `text`, or nothing if none came within `timeout` or the
  // process closed stderr. Every line read is kept in all_output().
  std::optional<std::string> wait_for_line(const std::string& text, std::chrono::milliseconds timeout);
  // Exit code, or nothing if it did not exit within `timeout`.
  std::optional<int> wait_exit(std::chrono::milliseconds timeout);
  void signal(int sig) const;
  bool running();
  // Resident anonymous memory in KiB (RssAnon in /proc/PID/status): what the process allocated,
  // without the pages of shared libraries it has touched so far.
  long anon_rss_kib() const;
  const std::string& all_output() const { return output_; }

 private:
  pid_t pid_ = -1;
  int stderr_fd_ = -1;
  std::string pending_, output_;
  std::optional<int> exit_code_;
};

}  // namespace vkray::test
