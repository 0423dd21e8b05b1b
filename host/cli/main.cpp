// vkray's command line: the subcommands (one file each), and every error turned into one message on
// stderr and the documented exit code (session/failure.h).
#include <cstdlib>
#include <iostream>
#include <vector>

#include <CLI/CLI.hpp>

#include "base/errors.h"
#include "cli/commands.h"
#include "cli/flags.h"
#include "cli/stop_signals.h"
#include "session/failure.h"
#include "session/session.h"
#include "session/version.h"

namespace {

int run(int argc, char** argv) {
  using namespace vkray;
  // Ctrl-C and SIGTERM, for every command alike, from the first moment (before any thread exists).
  cli::StopSignals stop;
  CLI::App app("vkray: a raytracer on Vulkan compute shaders, with a headless renderer for any Vulkan device "
               "(lavapipe included).");
  app.footer(cli::kExitCodes);
  app.set_version_flag("--version", std::string("vkray ") + version_string());
  app.require_subcommand(1);
  const std::vector<cli::Command> commands = {cli::add_render_command(app), cli::add_parity_command(app),
                                              cli::add_watch_command(app), cli::add_bench_command(app),
                                              cli::add_devices_command(app)};
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version are "errors" whose exit code is 0; CLI11's own codes for usage errors
    // become the one documented code.
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  try {
    for (const cli::Command& command : commands)
      if (*command.app) {
        stop.set_forced_exit(command.signal_exit_code, command.signal_message);
        return command.run();
      }
  } catch (...) {
    const Failure failure = describe_failure(std::current_exception());
    std::cerr << "vkray: " << failure.headline;
    if (!failure.message.empty()) std::cerr << (failure.multiline ? ":\n" : ": ") << failure.message;
    std::cerr << "\n";
    return failure.exit_code;
  }
  return kExitUsage;
}

}  // namespace

int main(int argc, char** argv) {
  const int code = run(argc, argv);
  if (vkray::device_work_left_running()) {
    // A timed-out tile may still be running on the device: exit handlers (the driver's own) could
    // wait on it without end, so end the process without them.
    std::cout.flush();
    std::cerr.flush();
    std::_Exit(code);
  }
  return code;
}
