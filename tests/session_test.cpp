// The library API's promises to a caller: what it may hold and for how long, what it may not do,
// and what a render that timed out leaves behind.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <memory>

#include <gtest/gtest.h>

#include "base/errors.h"
#include "gpu/context.h"
#include "mesh/mesh.h"
#include "session/session.h"
#include "support/gpu_fixture.h"
#include "support/slow_shaders.h"
#include "support/temp_dir.h"
#include "load/scene_loader.h"

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

// A session whose every tile lasts about 200 ms on any device (support/slow_shaders.h).
class SessionTest : public GpuTest {
 protected:
  std::filesystem::path shader_dir() const override { return shaders_.path(); }

 private:
  SlowShaders shaders_;
};

TEST_F(SessionTest, ATimedOutRenderKeepsWhatItUsesAndTheNextRenderWaitsForIt) {
  // 1 ms is far too little for a tile of these shaders: the render times out with its tile still
  // running. What that tile uses must stay alive (the validation layer reports an object destroyed
  // while in use), an upload is refused at once rather than queued behind it, and a render with
  // time to spare waits for it and then gives the image an undisturbed render gives. (128x128 at
  // 16 spp is one tile of the teapot.)
  const auto teapot = shipped("teapot.json");
  const DeviceScene on_device = session().upload(teapot);
  RenderOptions hurried = with_image({}, {128, 128, 16});
  hurried.tile_timeout = std::chrono::milliseconds(1);
  EXPECT_THROW(session().render(on_device, hurried), TimeoutError);
  EXPECT_THROW(session().upload(teapot), TimeoutError);
  const Image after = session().render(on_device, with_image({}, {128, 128, 16})).image;
  const Image undisturbed = session().render(on_device, with_image({}, {128, 128, 16})).image;
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

// The shared libraries this process has mapped now.
std::set<std::string> mapped_libraries() {
  std::set<std::string> result;
  std::ifstream maps("/proc/self/maps");
  for (std::string line; std::getline(maps, line);) {
    const size_t path = line.find('/');
    if (path != std::string::npos && line.find(".so", path) != std::string::npos) result.insert(line.substr(path));
  }
  return result;
}

TEST(SessionUseTest, SessionsShareTheProcesssInstanceAndTheDriverStaysLoaded) {
  // gpu/instance.h: the driver is loaded once per process, not once per session (NVIDIA's driver
  // failed vkCreateInstance after about 60 load and unload cycles in one process).
  std::set<std::string> with_a_session;
  {
    Session first(validated()), second(validated());
    EXPECT_EQ(*first.context().instance(), *second.context().instance());
    EXPECT_NO_THROW(second.render(second.upload(shipped("cornell.json")), with_image({}, {16, 16, 1})));
    with_a_session = mapped_libraries();
    first.close();
    second.close();
  }
  const std::set<std::string> after = mapped_libraries();
  for (const auto& library : with_a_session) EXPECT_TRUE(after.count(library)) << library << " was unloaded";
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

namespace vkray::test {
namespace {

// A scene whose camera, lights and materials change keeps its geometry on the device; the render
// is bit for bit what a fresh upload gives.
class SceneEditTest : public GpuTest {};

TEST_F(SceneEditTest, ACameraOrLightingEditSharesTheGeometryAndRendersAsAFreshUpload) {
  const auto first = shipped("cornell-spheres.json");
  auto edited = std::make_shared<Scene>(*first);
  edited->camera.position += glm::vec3(20.0f, -10.0f, 5.0f);
  edited->lights.at(0).intensity *= 0.5f;
  edited->materials.at(0).albedo = glm::vec3(0.9f, 0.2f, 0.1f);
  edited->materials.at(0).emission = glm::vec3(0.5f);  // an area light now: the emitter table changes too
  RenderOptions options = with_image({}, {48, 48, 2});
  const DeviceScene uploaded = session().upload(first);
  const DeviceScene changed = session().upload_changes(uploaded, edited);
  EXPECT_FALSE(uploaded.shares_geometry());
  EXPECT_TRUE(changed.shares_geometry());
  const Image reused = session().render(changed, options).image;
  const Image fresh = session().render(session().upload(edited), options).image;
  EXPECT_EQ(reused.pixels, fresh.pixels);
  // The first scene renders as before beside it.
  EXPECT_EQ(session().render(uploaded, options).image.pixels, session().render(session().upload(first), options).image.pixels);
}

TEST_F(SceneEditTest, AGeometryEditUploadsEverything) {
  const auto first = shipped("cornell-spheres.json");
  auto moved = std::make_shared<Scene>(*first);
  moved->spheres.at(0).center.x += 1.0f;
  EXPECT_FALSE(session().upload_changes(session().upload(first), moved).shares_geometry());
  auto reassigned = std::make_shared<Scene>(*first);
  reassigned->triangles.at(0).material = (reassigned->triangles.at(0).material + 1) % uint32_t(reassigned->materials.size());
  EXPECT_FALSE(same_geometry(*first, *reassigned));
}

TEST(MeshCacheTest, KeepsAFileUntilItChanges) {
  TempDir dir;
  const auto file = dir / "tri.obj";
  std::ofstream(file) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  MeshCache cache;
  const auto a = cache.get(file);
  EXPECT_EQ(cache.get(file), a);
  std::ofstream(file) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";
  const auto b = cache.get(file);
  EXPECT_NE(b, a);
  EXPECT_EQ(b->triangles.size(), 2u);
}

}  // namespace
}  // namespace vkray::test
