// The interrupt request (base/interrupt.h) is polled by every long loop of the library: with a
// request standing, each stage throws Cancelled at once instead of running on. signal_test.cpp
// checks the same end to end, by the clock; these check each stage on its own.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "base/errors.h"
#include "base/interrupt.h"
#include "base/per_process.h"
#include "bvh/bvh.h"
#include "cpu/reference.h"
#include "image/image.h"
#include "image/image_file.h"
#include "load/mesh_file.h"
#include "packing/scene_packing.h"
#include "load/scene_loader.h"
#include "scene/scene.h"
#include "support/temp_dir.h"

namespace vkray {
namespace {

class InterruptTest : public ::testing::Test {
 protected:
  void SetUp() override { cornell_ = load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "cornell.json"); }
  // Each test asks for the stop right before the stage, as the signal thread would.
  void TearDown() override { clear_interrupt(); }
  Scene cornell_;
};

TEST_F(InterruptTest, SceneParsingStops) {
  std::string big = R"({"camera": {"position": [0, 0, 0], "direction": [0, 0, 1], "focal_length": 1}, "x": [0)";
  for (int i = 0; i < 100000; ++i) big += ", 0";
  big += "]}";
  request_interrupt();
  EXPECT_THROW(parse_scene(big, "big.json"), Cancelled);
}

TEST_F(InterruptTest, MeshReadingStops) {
  std::string obj;
  for (int i = 0; i < 10000; ++i) obj += "v 0 0 0\n";
  obj += "f 1 2 3\n";
  std::string ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  request_interrupt();
  EXPECT_THROW(parse_mesh(obj, "m.obj"), Cancelled);
  EXPECT_THROW(parse_mesh(ply, "m.ply"), Cancelled);
}

TEST_F(InterruptTest, BvhBuildAndPackingStop) {
  const SceneBvh bvh = build_scene_bvh(cornell_);
  request_interrupt();
  EXPECT_THROW(build_bvh(primitive_boxes(cornell_)), Cancelled);
  EXPECT_THROW(gpu::pack_scene(cornell_, bvh), Cancelled);
}

TEST_F(InterruptTest, TheCpuReferenceStops) {
  request_interrupt();
  EXPECT_THROW(cpu::render_reference(cornell_, {64, 64, 1}), Cancelled);
}

TEST_F(InterruptTest, ImageWritingStopsAndLeavesNothing) {
  const test::TempDir dir;
  const Image image(64, 64);
  request_interrupt();
  EXPECT_THROW(write_image(image, dir / "out.png"), Cancelled);
  EXPECT_THROW(write_image(image, dir / "out.pfm"), Cancelled);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST_F(InterruptTest, ClearingTheRequestLetsWorkGoOn) {
  request_interrupt();
  clear_interrupt();
  EXPECT_NO_THROW(cpu::render_reference(cornell_, {16, 16, 1}));
}

// ---- Work in flight (a face that runs several at once: a render on each of several threads) ----

TEST_F(InterruptTest, ARequestStandsUntilEveryPieceInFlightHasEnded) {
  auto first = std::make_unique<WorkInFlight>();
  auto second = std::make_unique<WorkInFlight>();
  request_interrupt();
  first.reset();
  EXPECT_TRUE(interrupt_requested()) << "the second piece has not seen the request yet";
  second.reset();
  EXPECT_FALSE(interrupt_requested());
}

TEST_F(InterruptTest, APieceStartedWhileOthersStopWaitsForThemAndThenRuns) {
  auto stopping = std::make_unique<WorkInFlight>();
  request_interrupt();
  std::atomic<bool> started{false}, saw_request{true};
  std::thread later([&] {
    const WorkInFlight piece;
    saw_request = interrupt_requested();
    started = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_FALSE(started) << "a piece started while the request stopped another";
  stopping.reset();
  later.join();
  EXPECT_TRUE(started);
  EXPECT_FALSE(saw_request);
}

TEST_F(InterruptTest, ARequestWithNothingInFlightIsForgottenByTheNextPiece) {
  request_interrupt();
  const WorkInFlight piece;
  EXPECT_FALSE(interrupt_requested());
  EXPECT_NO_THROW(cpu::render_reference(cornell_, {8, 8, 1}));
}

TEST_F(InterruptTest, StoppingWorkInFlightWaitsUntilItHasEnded) {
  std::atomic<bool> registered{false}, stopped{false};
  std::thread piece([&] {
    const WorkInFlight in_flight;
    registered = true;
    while (!interrupt_requested()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    std::this_thread::sleep_for(std::chrono::milliseconds(100));  // unwinding takes a while
    stopped = true;
  });
  while (!registered) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  stop_work_in_flight();
  EXPECT_TRUE(stopped);
  piece.join();
  EXPECT_FALSE(interrupt_requested());
}

// Runs `child` in a process made by fork() and returns its exit status, or -1 when it has not ended
// within 10 s (it is killed then): a child that waits for the parent's threads waits for ever.
int in_forked_child(const std::function<int()>& child) {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(child());
  for (int i = 0; i < 1000; ++i) {
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ::kill(pid, SIGKILL);
  ::waitpid(pid, nullptr, 0);
  return -1;
}

TEST_F(InterruptTest, AForkedChildStartsWithNoWorkInFlightAndNoRequest) {
  const WorkInFlight parents;
  request_interrupt();  // the parent's piece is stopping: a piece of the parent's would wait for it
  EXPECT_EQ(in_forked_child([] {
              if (interrupt_requested()) return 1;
              const WorkInFlight childs;  // the parent's piece is not in this process to end
              request_interrupt();
              return interrupt_requested() ? 0 : 2;
            }),
            0);
  EXPECT_TRUE(interrupt_requested()) << "the child's request is its own";
  uint64_t count = 0;
  EXPECT_EQ(::read(interrupt_fd(), &count, sizeof count), ssize_t(sizeof count));
  EXPECT_EQ(count, 1u) << "the parent's descriptor counted the child's request";
}

TEST_F(InterruptTest, AForkedChildDoesNotRemoveTheParentsTemporaryFiles) {
  const test::TempDir dir;
  std::string pattern = (dir / "out.png.XXXXXX").string();
  const int fd = create_temporary_file(pattern);
  ASSERT_GE(fd, 0);
  EXPECT_EQ(in_forked_child([] {
              remove_temporary_files();  // a forced exit of the child
              return 0;
            }),
            0);
  EXPECT_TRUE(std::filesystem::exists(pattern));
  unregister_temporary_file(pattern);
  ::close(fd);
}

// What a parent's thread could hold in the object: a count, a destructor that must not run in a child.
struct Held {
  int count = 0;
  ~Held() { std::abort(); }  // never destroyed, in the parent or in a child
};

TEST(PerProcessTest, AForkedChildMakesItsOwnObjectAndLeavesTheParentsAsItIs) {
  static PerProcess<Held> held;  // its user registers nothing for fork()
  Held* const parents = &held.get();
  parents->count = 7;
  held.remake();  // in the process that made it: nothing changes
  EXPECT_EQ(&held.get(), parents);
  EXPECT_EQ(in_forked_child([&] {
              if (&held.get() == parents) return 1;  // a new object, at another address
              if (held.get().count != 0) return 2;   // made afresh
              if (parents->count != 7) return 3;     // the parent's, as it was
              held.get().count = 5;
              return 0;
            }),
            0);
  EXPECT_EQ(&held.get(), parents);
  EXPECT_EQ(parents->count, 7);
}

}  // namespace
}  // namespace vkray
