// vkray's command line: the subcommands (one file each), and every error turned into one message on
// stderr and the documented exit code (session/failure.h).
#include <cstdlib>
#include <iostream>
#include <variant>

#include "base/errors.h"
#include "cli/command_line.h"
#include "cli/stop_signals.h"
#include "session/failure.h"
#include "session/session.h"

namespace {

int run(int argc, char** argv) {
  using namespace vkray;
  // Ctrl-C and SIGTERM, for every command alike, from the first moment (before any thread exists).
  cli::StopSignals stop;
  const auto line = cli::make_command_line();
  const auto parsed = cli::parse_command_line(*line, argc, argv, std::cout, std::cerr);
  if (std::holds_alternative<int>(parsed)) return std::get<int>(parsed);
  const cli::Command& command = *std::get<const cli::Command*>(parsed);
  stop.set_forced_exit(command.signal_exit_code, command.signal_message);
  try {
    return command.run();
  } catch (...) {
    const Failure failure = describe_failure(std::current_exception());
    std::cerr << "vkray: " << failure.headline;
    if (!failure.message.empty()) std::cerr << (failure.multiline ? ":\n" : ": ") << failure.message;
    std::cerr << "\n";
    return failure.exit_code;
  }
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
