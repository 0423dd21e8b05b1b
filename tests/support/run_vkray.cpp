#include "support/run_vkray.h"

#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "support/temp_dir.h"

namespace vkray::test {
namespace {

std::string slurp(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

CommandResult run_vkray(const std::string& args, const std::filesystem::path& cwd, const std::string& limits) {
  return run_command((limits.empty() ? "" : limits + " && ") + "'" VKRAY_EXECUTABLE "' " + args, cwd);
}

CommandResult run_command(const std::string& command_line, const std::filesystem::path& cwd) {
  const TempDir capture;  // outside `cwd`, so tests can check that nothing was left there
  const auto out = capture / "stdout", err = capture / "stderr";
  const std::string command = "cd '" + cwd.string() + "' && { " + command_line + "; } >'" + out.string() + "' 2>'" +
                              err.string() + "' </dev/null";
  const int status = std::system(command.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

}  // namespace vkray::test
