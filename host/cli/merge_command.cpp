// `vkray merge OUT PARTS...`: the parts of a render (`vkray render --region`) assembled into the
// whole image (image/merge.h).
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "base/errors.h"
#include "base/timing.h"
#include "cli/commands.h"
#include "cli/flags.h"
#include "cli/report.h"
#include "image/merge.h"

namespace vkray::cli {
namespace {

struct MergeArgs {
  std::filesystem::path output;
  std::vector<std::filesystem::path> parts;
  bool quiet = false;
};

int run_merge(const MergeArgs& args) {
  const auto start = Clock::now();
  const MergeSummary summary = merge_part_files(args.output, args.parts);
  if (summary.passes_dropped)
    std::cerr << "vkray: warning: the parts' first-hit passes are not in " << args.output.string()
              << ": only an .exr output keeps them\n";
  if (summary.mixed_devices)
    std::cerr << "vkray: warning: the parts were rendered on more than one device: the image agrees with a single "
                 "render within parity, not bit for bit\n";
  if (!args.quiet) {
    const PartRecord& r = summary.record;
    std::cerr << "vkray: merged " << summary.parts << (summary.parts == 1 ? " part" : " parts") << " of a " << r.width
              << " x " << r.height << " render (" << r.samples_per_pixel << " spp, seed " << r.seed << ", scene "
              << r.scene_digest.substr(0, 12) << ") in " << format_ms(ms_since(start)) << "\n"
              << "vkray: wrote " << args.output.string() << "\n";
  }
  return kExitOk;
}

}  // namespace

Command add_merge_command(CLI::App& app) {
  auto args = std::make_shared<MergeArgs>();
  CLI::App* command = app.add_subcommand(
      "merge", "Assemble the parts of a render (`vkray render --region`, .exr or .pfm) into the whole image. The parts must "
               "be of one scene, size, sample count, seed and vkray version, and tile the image without overlaps or gaps; "
               "parts of one build and device give exactly the bytes of a single render.");
  command->add_option("output", args->output, "The whole image: .png, .pfm or .exr (with the parts' first-hit passes)")->required();
  command->add_option("parts", args->parts, "The parts: .exr files, or .pfm files with their .pfm.json records")->required();
  command->add_flag("-q,--quiet", args->quiet, "Print only warnings and errors");
  command->footer(kExitCodes);
  return {command, [args] { return run_merge(*args); }, kExitInterrupted, "interrupted; nothing written"};
}

}  // namespace vkray::cli
