// The library API's promises to a caller: what it may hold and for how long, what it may not do,
// and what a render that timed out leaves behind.
#include <chrono>
#include <filesystem>
#include <memory>

#include <gtest/gtest.h>

#include "base/errors.h"
#include "session/session.h"
#include "support/gpu_fixture.h"

namespace vkray::test {
namespace {

std::shared_ptr<const Scene> shipped(const char* name) {
  return std::make_shared<const Scene>(load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / name));
}

SessionOptions validated() {
  SessionOptions options;
  options.validation = true;
  return options;
}

using SessionTest = GpuTest;

TEST_F(SessionTest, ATimedOutRenderKeepsWhatItUsesAndTheNextRenderWaitsForIt) {
  // 1 ms a tile is far too little for the teapot at 16 spp on lavapipe: the render times out with
  // its tile still running. What that tile uses must stay alive (the validation layer reports an
  // object destroyed while in use), an upload is refused at once rather than queued behind it, and
  // a render with time to spare waits for it and then gives the image an undisturbed render gives.
  const auto teapot = shipped("teapot.json");
  const DeviceScene on_device = session().upload(teapot);
  RenderOptions hurried = with_image({}, {256, 256, 16});
  hurried.tile_timeout = std::chrono::milliseconds(1);
  EXPECT_THROW(session().render(on_device, hurried), TimeoutError);
  EXPECT_THROW(session().upload(teapot), TimeoutError);
  const Image after = session().render(on_device, with_image({}, {256, 256, 16})).image;
  const Image undisturbed = session().render(on_device, with_image({}, {256, 256, 16})).image;
  EXPECT_TRUE(after.pixels == undisturbed.pixels);
}

TEST(SessionUseTest, AClosedSessionRefusesWorkWithAUsageError) {
  Session session(validated());
  session.close();
  EXPECT_THROW(session.device_name(), UsageError);
  EXPECT_THROW(session.compile_shaders(), UsageError);
  EXPECT_THROW(session.upload(shipped("cornell.json")), UsageError);
  EXPECT_FALSE(session.has_shaders());
  EXPECT_NO_THROW(session.close());  // twice is fine
}

TEST(SessionUseTest, ASceneFromAnotherSessionIsRefused) {
  Session first(validated()), second(validated());
  {
    const DeviceScene scene = first.upload(shipped("cornell.json"));
    EXPECT_THROW(second.render(scene, with_image({}, {16, 16, 1})), UsageError);
    EXPECT_THROW(second.prepare(scene, {}), UsageError);
    EXPECT_NO_THROW(first.render(scene, with_image({}, {16, 16, 1})));
  }
  first.close();
  second.close();
}

TEST(SessionUseTest, ClosingWhileASceneIsHeldIsAnInternalError) {
  // The device would outlive the session, and the validation layer's report of what was left
  // alive with it would come after the check that should fail on it.
  Session session(validated());
  const DeviceScene scene = session.upload(shipped("cornell.json"));
  EXPECT_THROW(session.close(), InternalError);
}

}  // namespace
}  // namespace vkray::test
