#include "support/slow_shaders.h"

#include <fstream>
#include <iterator>
#include <stdexcept>

namespace vkray::test {
namespace {

// How long the spin lasts, in ticks of the device clock, whose unit Vulkan leaves to the device:
// nanoseconds on NVIDIA (PTX %globaltimer) and on lavapipe (Mesa 22.3.6 here, measured 2026-11-23:
// a one-tile 8x8 render spinning 1e8 ticks traced in 116-121 ms, spinning 1e9 in 1021-1063 ms,
// 1.02 ns a tick), so 200 ms there; longer where the clock is slower (AMD's 100 MHz: 2 s), but
// always bounded, since the device is shared and never reset.
constexpr unsigned kSpinTicks = 200'000'000;

// Clock reads per pass of the spin. llvmpipe ends the loops of an invocation after 65535
// iterations in all (measured: a loop that only read the clock stopped after 65535 passes, 2.5 ms;
// nested loops stopped after 65535 together), so a pass must last longer: 256 reads take about
// 8 us there, and 200 ms takes some 24000 passes.
constexpr int kReadsPerPass = 256;

std::string read_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

}  // namespace

void copy_shipped_shaders(const std::filesystem::path& to) {
  std::filesystem::copy(VKRAY_SHADER_DIR, to, std::filesystem::copy_options::recursive);
}

void replace_in_trace(const std::filesystem::path& shader_dir, const std::string& text, const std::string& with) {
  const std::filesystem::path file = shader_dir / "trace.comp";
  std::string source = read_file(file);
  const size_t at = source.find(text);
  if (at == std::string::npos) throw std::runtime_error(file.string() + " has no \"" + text + "\" any more");
  source.replace(at, text.size(), with);
  std::ofstream(file, std::ios::binary) << source;
}

void make_tiles_slow(const std::filesystem::path& shader_dir) {
  replace_in_trace(shader_dir, "#version 460\n", "#version 460\n#extension GL_EXT_shader_realtime_clock : require\n");
  // The invocation at the tile's (0, 0) spins, after its pixel's own loops (which on llvmpipe
  // would otherwise get what the spin left of the 65535 iterations) and before its store, which
  // depends on the clock so that no compiler drops the loop (Mesa's NIR drops a loop whose
  // results go unused). Only the low word of the clock: wrap-around is uint arithmetic.
  std::string spin =
      "  if (local == uvec2(0u)) {\n"
      "    uint start = clockRealtime2x32EXT().x, elapsed = 0u;\n"
      "    do {\n";
  for (int i = 0; i < kReadsPerPass; ++i) spin += "      elapsed = max(elapsed, clockRealtime2x32EXT().x - start);\n";
  spin += "    } while (elapsed < " + std::to_string(kSpinTicks) + "u);\n" +
          "    if (elapsed == ~0u) return;  // in practice never: a read one tick short of a full turn\n"
          "  }\n";
  replace_in_trace(shader_dir, "  radiance[index] = ", spin + "  radiance[index] = ");
}

SlowShaders::SlowShaders() {
  copy_shipped_shaders(dir_.path());
  make_tiles_slow(dir_.path());
}

}  // namespace vkray::test
