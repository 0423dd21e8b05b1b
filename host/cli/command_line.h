// The whole command line: every command with its flags, the rules all option values follow
// (cli/flags.h), and parsing, which turns help, version and usage errors into their output and
// exit code. main() runs what it returns; the CLI fuzz target parses without running.
#pragma once

#include <memory>
#include <ostream>
#include <variant>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/commands.h"

namespace vkray::cli {

struct CommandLine {
  CLI::App app;
  std::vector<Command> commands;
};

std::unique_ptr<CommandLine> make_command_line();

// The command the arguments select, or the exit code of a parse that ends here (0 after --help or
// --version, 2 after a usage error), its text written to `out` or `err`. Messages quote the
// arguments printably.
std::variant<const Command*, int> parse_command_line(CommandLine& line, int argc, const char* const* argv,
                                                     std::ostream& out, std::ostream& err);

}  // namespace vkray::cli
