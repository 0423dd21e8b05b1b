// The subcommands of `vkray`. Each adds itself to the command line with its flags and returns what
// runs it: a function that returns the exit code or throws one of base/errors.h's errors, which
// main() reports.
#pragma once

#include <functional>

#include <CLI/CLI.hpp>

namespace vkray::cli {

struct Command {
  CLI::App* app;
  std::function<int()> run;
  // Ctrl-C and SIGTERM (cli/stop_signals.h): the exit code and message of a command that is stopped
  // by force. A command that unwinds by itself reports Cancelled as main() reports any error.
  int signal_exit_code = 130;
  const char* signal_message = "interrupted; no image written";
};

Command add_render_command(CLI::App& app);
Command add_parity_command(CLI::App& app);
Command add_check_command(CLI::App& app);
Command add_watch_command(CLI::App& app);
Command add_view_command(CLI::App& app);
Command add_bench_command(CLI::App& app);
Command add_devices_command(CLI::App& app);
Command add_merge_command(CLI::App& app);

}  // namespace vkray::cli
