// libFuzzer target: the command line. The input is an argument list, NUL-separated (the seeds in
// seeds-command_line/); it is parsed by the same code as `vkray`'s (cli/command_line.h), and
// never run.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "cli/command_line.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<std::string> args{"vkray"};
  std::string arg;
  for (size_t i = 0; i < size && args.size() < 64; ++i) {
    if (data[i] == 0) {
      args.push_back(arg);
      arg.clear();
    } else {
      arg += char(data[i]);
    }
  }
  if (!arg.empty()) args.push_back(arg);
  std::vector<const char*> argv;
  for (const std::string& a : args) argv.push_back(a.c_str());

  const auto line = vkray::cli::make_command_line();
  std::ostringstream out, err;
  vkray::cli::parse_command_line(*line, int(argv.size()), argv.data(), out, err);
  return 0;
}
