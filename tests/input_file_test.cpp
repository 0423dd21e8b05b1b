// Reading input files: only regular files, at most a limit, and an interrupt honoured while reading.
// Each case here hung or read without end before base/input_file.h (a FIFO, /dev/zero).
#include <sys/stat.h>

#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "base/errors.h"
#include "base/input_file.h"
#include "base/interrupt.h"
#include "load/mesh_file.h"
#include "load/scene_loader.h"
#include "scene/scene.h"
#include "support/temp_dir.h"

namespace vkray {
namespace {

TEST(InputFileTest, ReadsARegularFileWhole) {
  test::TempDir dir;
  std::ofstream(dir / "a.txt") << "hello";
  const InputFile input = read_input_file(dir / "a.txt", 100);
  EXPECT_EQ(input.error, "");
  EXPECT_EQ(input.text, "hello");
}

TEST(InputFileTest, RefusesWhatIsNotARegularFile) {
  test::TempDir dir;
  ASSERT_EQ(::mkfifo((dir / "fifo.json").c_str(), 0600), 0);
  EXPECT_EQ(read_input_file(dir / "fifo.json", 100).error, "is a FIFO (named pipe), not a regular file");
  EXPECT_EQ(read_input_file("/dev/zero", 100).error, "is a character device, not a regular file");
  EXPECT_EQ(read_input_file(dir.path(), 100).error, "is a directory, not a regular file");
  EXPECT_EQ(read_input_file(dir / "missing.json", 100).error, "not found");
}

TEST(InputFileTest, RefusesAFilePastTheLimit) {
  test::TempDir dir;
  std::ofstream(dir / "big.json") << std::string(101, ' ');
  EXPECT_EQ(read_input_file(dir / "big.json", 101).error, "");
  EXPECT_EQ(read_input_file(dir / "big.json", 100).error, "is 101 bytes; vkray reads files of at most 100 bytes");
}

TEST(InputFileTest, AnInterruptStopsTheRead) {
  test::TempDir dir;
  std::ofstream(dir / "a.json") << "{}";
  request_interrupt();
  EXPECT_THROW(read_input_file(dir / "a.json", 100), Cancelled);
  clear_interrupt();
}

// The scene and mesh loaders name the file and say why, as a SceneError (exit 1).
TEST(InputFileTest, ScenesAndMeshesNameTheFile) {
  test::TempDir dir;
  ASSERT_EQ(::mkfifo((dir / "fifo.obj").c_str(), 0600), 0);
  try {
    load_scene("/dev/zero");
    ADD_FAILURE() << "/dev/zero loaded";
  } catch (const SceneError& e) {
    EXPECT_STREQ(e.what(), "/dev/zero: is a character device, not a regular file");
  }
  try {
    load_mesh(dir / "fifo.obj");
    ADD_FAILURE() << "a FIFO loaded";
  } catch (const MeshError& e) {
    EXPECT_EQ(std::string(e.what()), (dir / "fifo.obj").string() + ": is a FIFO (named pipe), not a regular file");
  }
  EXPECT_THROW(load_scene(""), SceneError);
}

}  // namespace
}  // namespace vkray
