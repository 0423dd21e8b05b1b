// Ctrl-C and SIGTERM (docs/limits.md, "Signals"): every command stops within a second, whatever stage the
// signal finds it in (reading the scene and its meshes, compiling, building the BVH, tracing on the
// GPU or the CPU, writing), exits 130, and leaves the output folder as it was: no new file, no
// temporary file, an existing output untouched. `vkray watch` is the exception: Ctrl-C is how it
// ends, with exit 0 (watch_test.cpp).
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "support/child_process.h"
#include "support/slow_shaders.h"
#include "support/temp_dir.h"

namespace vkray::test {
namespace {

const std::string kScenes = VKRAY_SCENE_DIR;
constexpr const char* kOldOutput = "an image from before";

std::string read_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// The folder holds only out.png, as it was before the command ran.
void expect_untouched(const TempDir& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) names.push_back(entry.path().filename().string());
  EXPECT_EQ(names, std::vector<std::string>{"out.png"});
  EXPECT_EQ(read_file(dir / "out.png"), kOldOutput) << "the existing output was overwritten";
}

// Sends `sig` to `child`, which runs in `dir`, and expects it to stop within a second: its last
// line, "interrupted; no image written", within a second of the signal, exit 130, and `dir` as it
// was. The process must also be gone within two seconds: what follows its last line is the
// kernel's teardown, which a loaded machine can slow. When `may_finish`, exit 0 is right for a
// command that had ended before the signal, or ended within 100 ms of it (its last step); one that
// ignored the signal would run on for seconds.
void expect_stopped_in_time(ChildProcess& child, int sig, const TempDir& dir, bool may_finish = false) {
  const bool was_running = child.running();
  child.signal(sig);
  const auto sent = std::chrono::steady_clock::now();
  const auto since_signal = [&] {
    return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - sent).count();
  };
  const bool reported = child.wait_for_line("interrupted; no image written", std::chrono::seconds(30)).has_value();
  const auto reported_ms = since_signal();
  const auto code = child.wait_exit(std::chrono::seconds(30));
  const auto exited_ms = since_signal();
  ASSERT_TRUE(code.has_value()) << "still running 30 s after the signal:\n" << child.all_output();
  if (may_finish && *code == 0 && (!was_running || exited_ms < 100)) return;  // a complete output is right
  EXPECT_EQ(*code, 130) << child.all_output();
  EXPECT_TRUE(reported) << child.all_output();
  EXPECT_LT(reported_ms, 1000) << "stopped " << reported_ms << " ms after the signal:\n" << child.all_output();
  EXPECT_LT(exited_ms, 2000) << "gone " << exited_ms << " ms after the signal:\n" << child.all_output();
  expect_untouched(dir);
}

// A folder that holds an out.png from before.
void add_old_output(const TempDir& dir) { std::ofstream(dir / "out.png") << kOldOutput; }

// Runs `argv` in a folder that already has an out.png and sends `sig` after `delay`.
void expect_stops(const std::vector<std::string>& argv, std::chrono::milliseconds delay, int sig) {
  TempDir dir;
  add_old_output(dir);
  ChildProcess child(argv, dir.path().string());
  std::this_thread::sleep_for(delay);
  expect_stopped_in_time(child, sig, dir, /*may_finish=*/true);
}

// dragon-field.json (2 million triangles) spends about 0.5 s loading, 0.2 s compiling, 3 s building
// its BVH and 0.3 s tracing on lavapipe, so these delays find each command in every stage. On a
// fast device the trace takes milliseconds and the latest delays may find the command done
// (may_finish): there these cases cover the host's stages (loading, compiling, the BVH, the CPU
// renderer, writing) and the GPU trace only by chance; SigintDuringAGpuRender... covers it on any
// device.
const std::vector<int> kDelaysMs = {30, 150, 400, 800, 1500, 3000};

using Case = std::tuple<std::string, int>;  // command, delay in ms

class SignalTest : public ::testing::TestWithParam<Case> {};

std::vector<std::string> command(const std::string& name) {
  const std::string scene = kScenes + "/dragon-field.json";
  if (name == "render_gpu") return {VKRAY_EXECUTABLE, "render", scene, "-o", "out.png"};
  if (name == "render_cpu") return {VKRAY_EXECUTABLE, "render", scene, "--renderer", "cpu", "-o", "out.png"};
  return {VKRAY_EXECUTABLE, "parity", scene, "--diff", "out.png"};
}

TEST_P(SignalTest, StopsWithinASecondWritingNothing) {
  const auto& [name, delay] = GetParam();
  // SIGINT and SIGTERM take one path: alternate them.
  expect_stops(command(name), std::chrono::milliseconds(delay), delay % 2 ? SIGTERM : SIGINT);
}

std::vector<Case> cases() {
  std::vector<Case> result;
  for (const char* name : {"render_gpu", "render_cpu", "parity"})
    for (const int delay : kDelaysMs) result.emplace_back(name, delay + (result.size() % 2));
  return result;
}

INSTANTIATE_TEST_SUITE_P(Commands, SignalTest, ::testing::ValuesIn(cases()), [](const auto& param) {
  return std::get<0>(param.param) + "_after_" + std::to_string(std::get<1>(param.param)) + "ms";
});

TEST(SignalTest, BenchStopsWithinASecond) {
  for (const int delay : {100, 1000}) expect_stops({VKRAY_EXECUTABLE, "bench", "--repeat", "1"}, std::chrono::milliseconds(delay), SIGINT);
}

TEST(SignalTest, CheckStopsWithinASecondWritingNoReport) {
  // Loading the 2-million-triangle field, building its BVH, then its cases: no JUnit file is left.
  for (const int delay : {300, 2500})
    expect_stops({VKRAY_EXECUTABLE, "check", "--case", "dragon-field", "--junit", "report.xml"},
                 std::chrono::milliseconds(delay), SIGINT);
}

// A stage that polls nothing: glslang compiling a shader of 20000 dependent lines (seconds). The
// signal thread does not wait past StopSignals::kGrace for it and ends the process itself, still
// within a second and still leaving nothing behind.
TEST(SignalTest, AStageThatCannotBeInterruptedIsNotWaitedFor) {
  TempDir shaders;
  copy_shipped_shaders(shaders.path());
  std::string slow = "  load_frame();\n  float slow = float(gl_LocalInvocationID.x);\n";
  for (int i = 0; i < 20000; ++i) slow += "  slow = sin(slow * 1.0001 + " + std::to_string(i) + ".5);\n";
  slow += "  if (slow > 1e30) return;\n";
  replace_in_trace(shaders.path(), "  load_frame();\n", slow);

  TempDir dir;
  add_old_output(dir);
  ChildProcess child({VKRAY_EXECUTABLE, "render", "--shader-dir", shaders.path().string(), "--width", "8", "--height",
                      "8", "-o", "out.png"},
                     dir.path().string());
  ASSERT_TRUE(child.wait_for_line("device ", std::chrono::seconds(30))) << child.all_output();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // past reading the files: in glslang's parser
  expect_stopped_in_time(child, SIGTERM, dir);
}

// Renders the teapot at 16 spp with `options`, sends SIGINT once a progress line with `progress`
// shows it rendering (the first comes after a second), and expects exit 130 with nothing written.
void expect_sigint_stops_the_render(const std::vector<std::string>& options, const std::string& progress) {
  TempDir dir;
  add_old_output(dir);
  std::vector<std::string> argv = {VKRAY_EXECUTABLE, "render", kScenes + "/teapot.json", "--spp", "16", "-o", "out.png"};
  argv.insert(argv.end(), options.begin(), options.end());
  ChildProcess child(argv, dir.path().string());
  ASSERT_TRUE(child.wait_for_line(progress, std::chrono::seconds(60))) << child.all_output();
  expect_stopped_in_time(child, SIGINT, dir);
}

TEST(SignalTest, SigintDuringAGpuRenderExitsCleanlyAndWritesNothing) {
  // 16 tiles (512x512) of about 200 ms each on any device (support/slow_shaders.h): the signal
  // comes with tiles still to run, one of them running.
  const SlowShaders shaders;
  expect_sigint_stops_the_render({"--shader-dir", shaders.path().string(), "--width", "512", "--height", "512"}, "tracing");
}

TEST(SignalTest, SigintDuringACpuRenderExitsCleanlyAndWritesNothing) {
  // The CPU reference stops within a pixel as the GPU path stops within a tile. (2048x2048 lasts
  // seconds on the host's cores; no device takes part.)
  expect_sigint_stops_the_render({"--renderer", "cpu", "--width", "2048", "--height", "2048"}, "rows)");
}

}  // namespace
}  // namespace vkray::test
