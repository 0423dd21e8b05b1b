#include "cli/command_line.h"

#include <string>
#include <string_view>

#include "base/errors.h"
#include "cli/flags.h"
#include "session/version.h"

namespace vkray::cli {

std::unique_ptr<CommandLine> make_command_line() {
  auto line = std::make_unique<CommandLine>();
  CLI::App& app = line->app;
  app.description("vkray: a raytracer on Vulkan compute shaders, with a headless renderer for any Vulkan device "
                  "(lavapipe included).");
  app.name("vkray");
  app.footer(kExitCodes);
  app.set_version_flag("--version", std::string("vkray ") + version_string());
  app.require_subcommand(1);
  line->commands = {add_render_command(app), add_merge_command(app), add_parity_command(app), add_check_command(app), add_watch_command(app), add_view_command(app),
                    add_bench_command(app), add_devices_command(app)};
  apply_value_rules(app);
  return line;
}

std::variant<const Command*, int> parse_command_line(CommandLine& line, int argc, const char* const* argv,
                                                     std::ostream& out, std::ostream& err) {
  CLI::App& app = line.app;
  // A first word that is not an option must be a command; CLI11 would only say that one is required.
  std::string names;
  bool known = false;
  for (const Command& command : line.commands) {
    names += (names.empty() ? "" : ", ") + command.app->get_name();
    known = known || (argc > 1 && command.app->get_name() == argv[1]);
  }
  if (argc > 1 && argv[1][0] != '-' && !known) {
    err << "vkray: unknown command \"" << printable(argv[1]) << "\" (commands: " << names << ")\n"
        << "Run with --help for more information.\n";
    return int(kExitUsage);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --version
    app.exit(e, out, err);
    return int(kExitOk);
  } catch (const CLI::ParseError& e) {
    // CLI11's own codes for usage errors become the one documented code; its message quotes the
    // arguments, which may hold anything.
    err << "vkray: " << printable_middle(e.what(), 500) << "\nRun with --help for more information.\n";
    return int(kExitUsage);
  }
  for (const Command& command : line.commands)
    if (*command.app) return &command;
  return int(kExitUsage);
}

}  // namespace vkray::cli
