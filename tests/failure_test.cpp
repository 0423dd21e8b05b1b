// Every error reaches a face as one exit code and one message (base/errors.h, session/failure.h):
// vkray's own by their kind, a dependency's classified once.
#include <new>
#include <string>
#include <stdexcept>

#include <gtest/gtest.h>
#include <vulkan/vulkan_raii.hpp>

#include "base/checked.h"
#include "base/errors.h"
#include "session/failure.h"

namespace vkray {
namespace {

template <typename E>
Failure failure_of(const E& error) {
  return describe_failure(std::make_exception_ptr(error));
}

TEST(FailureTest, EachKindHasItsExitCode) {
  EXPECT_EQ(failure_of(SceneError("s.json: /camera: missing")).exit_code, kExitBadInput);
  EXPECT_EQ(failure_of(MeshError("m.obj:3: bad")).exit_code, kExitBadInput);
  EXPECT_EQ(failure_of(OutputError("x.jpg: unknown image type")).exit_code, kExitBadInput);
  EXPECT_EQ(failure_of(LimitError("too many")).exit_code, kExitBadInput);
  EXPECT_EQ(failure_of(UsageError("--width 0")).exit_code, kExitUsage);
  EXPECT_EQ(failure_of(DeviceError("no device")).exit_code, kExitDevice);
  EXPECT_EQ(failure_of(TimeoutError("tile")).exit_code, kExitDevice);
  EXPECT_EQ(failure_of(Cancelled()).exit_code, kExitInterrupted);
  EXPECT_EQ(failure_of(InternalError("x")).exit_code, kExitInternal);
  const Failure shader = failure_of(ShaderError("a.glsl:3: error: x\nb.glsl:4: error: y"));
  EXPECT_EQ(shader.exit_code, kExitBadInput);
  EXPECT_TRUE(shader.multiline);
}

TEST(FailureTest, ALongPathLosesItsMiddleAndKeepsTheFileNameAndTheReason) {
  std::string path = "/home/user";
  for (int i = 0; i < 40; ++i) path += "/folder-" + std::string(60, char('a' + i % 26));
  path += "/the-scene.json";
  const Failure failure = failure_of(SceneError(path + ": File name too long"));
  EXPECT_LE(failure.message.size(), 1000u);
  EXPECT_EQ(failure.message.rfind("/home/user/folder-", 0), 0u) << failure.message;
  EXPECT_NE(failure.message.find(" ... "), std::string::npos) << failure.message;
  const std::string end = "/the-scene.json: File name too long";
  ASSERT_GE(failure.message.size(), end.size());
  EXPECT_EQ(failure.message.substr(failure.message.size() - end.size()), end) << failure.message;
  // A message that fits is left as it is; a cut never splits a UTF-8 character.
  EXPECT_EQ(printable_middle("short: not found", 1000), "short: not found");
  std::string wide;
  for (int i = 0; i < 600; ++i) wide += "\xc3\xa9";  // e acute
  const std::string cut = printable_middle(wide, 100);
  EXPECT_EQ(cut.find('?'), std::string::npos) << cut;
}

TEST(FailureTest, AMeshErrorIsASceneError) {
  // What survives a broken scene (vkray watch, a Python caller) survives a broken mesh.
  EXPECT_THROW(throw MeshError("m.obj"), SceneError);
}

TEST(FailureTest, WhatADependencyThrowsIsClassified) {
  const Failure vulkan = failure_of(vk::OutOfDeviceMemoryError("vk::raii::Device::allocateMemory"));
  EXPECT_EQ(vulkan.exit_code, kExitDevice);
  EXPECT_NE(vulkan.message.find("allocateMemory"), std::string::npos) << vulkan.message;
  EXPECT_EQ(failure_of(std::bad_alloc()).exit_code, kExitBadInput);
  const Failure other = failure_of(std::logic_error("unexpected"));
  EXPECT_EQ(other.exit_code, kExitInternal);
  EXPECT_EQ(other.message, "unexpected");
}

TEST(FailureTest, OversizedArithmeticIsAnInputError) {
  try {
    checked_mul(uint64_t(1) << 40, uint64_t(1) << 40, "output image");
    ADD_FAILURE() << "no error";
  } catch (...) {
    const Failure f = describe_failure(std::current_exception());
    EXPECT_EQ(f.exit_code, kExitBadInput);
    EXPECT_EQ(f.message, "output image: size overflows 64 bits");
  }
}

// User text reaches the terminal printable and short, whatever the file held: escape sequences,
// newlines, bytes that are not UTF-8, megabytes of one line.
TEST(FailureTest, MessagesArePrintableAndBrief) {
  EXPECT_EQ(printable("caf\xc3\xa9 \x1b[31mred\n"), "caf\xc3\xa9 ?[31mred?");
  EXPECT_EQ(printable("bad \xff\xc3 byte"), "bad ?? byte");
  EXPECT_EQ(printable("\xc2\x9b C1 control"), "? C1 control");
  EXPECT_EQ(printable(std::string(100, 'x'), 10), "xxxxxxxxxx...");
  EXPECT_EQ(printable("ab\xc3\xa9", 3), "ab?...");  // never half a character

  const Failure one = failure_of(SceneError("s.json: \x1b]0;title\x07" + std::string(5'000'000, 'x')));
  EXPECT_LT(one.message.size(), 1100u);
  EXPECT_EQ(one.message.find('\x1b'), std::string::npos);
  std::string many_lines;
  for (int i = 0; i < 10000; ++i) many_lines += "a.glsl:" + std::to_string(i) + ": error: \x1b[2J\n";
  const Failure shader = failure_of(ShaderError(many_lines));
  EXPECT_LT(shader.message.size(), 10000u);
  EXPECT_EQ(shader.message.find('\x1b'), std::string::npos);
  EXPECT_NE(shader.message.find("a.glsl:0: error: ?[2J\na.glsl:1: error:"), std::string::npos) << shader.message;
}

}  // namespace
}  // namespace vkray
