// Runs the vkray command as a user would and captures what it printed and its exit code.
#pragma once

#include <filesystem>
#include <string>

namespace vkray::test {

struct CommandResult {
  int exit_code;  // -1 if it did not exit normally
  std::string out, err;
};

// `vkray ARGS` in `cwd`, with no standard input.
// `limits`: shell commands run first in the same shell, e.g. "ulimit -f 4" (a full disk).
CommandResult run_vkray(const std::string& args, const std::filesystem::path& cwd, const std::string& limits = "");
// Any shell command line in `cwd`, its output captured the same way.
CommandResult run_command(const std::string& command_line, const std::filesystem::path& cwd);

}  // namespace vkray::test
