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
};

Command add_render_command(CLI::App& app);
Command add_parity_command(CLI::App& app);
Command add_watch_command(CLI::App& app);
Command add_bench_command(CLI::App& app);
Command add_devices_command(CLI::App& app);

}  // namespace vkray::cli
