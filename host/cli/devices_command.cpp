// `vkray devices`: every Vulkan device the loader reports, with the properties that matter to vkray.
#include <iostream>

#include "base/errors.h"
#include "cli/commands.h"
#include "session/session.h"

namespace vkray::cli {
namespace {

int run_devices() {
  const auto found = list_devices();
  if (found.empty()) {
    std::cout << "no Vulkan devices found\n";
    return kExitDevice;
  }
  for (const auto& d : found) {
    std::cout << d.index << ": " << d.name << "\n"
              << "   type " << d.type << ", Vulkan " << d.api_version << ", driver " << d.driver << "\n"
              << "   compute queue " << (d.has_compute_queue ? "yes" : "NO") << ", max workgroup invocations "
              << d.max_workgroup_invocations << "\n"
              << "   max texel buffer elements " << d.max_texel_buffer_elements << ", max storage buffer range "
              << d.max_storage_buffer_range << " bytes, device-local memory " << (d.device_local_bytes >> 20) << " MiB\n";
  }
  return kExitOk;
}

}  // namespace

Command add_devices_command(CLI::App& app) {
  CLI::App* command = app.add_subcommand("devices", "List Vulkan devices with the properties that matter to vkray.");
  return {command, [] { return run_devices(); }};
}

}  // namespace vkray::cli
