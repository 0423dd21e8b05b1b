// The viewer's camera and light moves (host/view/controls.h): each does what its key or drag says,
// and a camera the viewer writes out reads back, through the scene parser, to the same bits.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "load/scene_loader.h"
#include "scene/camera.h"
#include "view/controls.h"

namespace vkray::view {
namespace {

Camera lab_camera() {  // the Cornell box's: at z = -3 looking at the origin, y down
  Camera camera;
  camera.position = {0.0f, 0.0f, -3.0f};
  camera.forward = {0.0f, 0.0f, 1.0f};
  camera.up = {0.0f, -1.0f, 0.0f};
  return camera;
}

TEST(ControlsTest, ArrowsMoveAlongTheViewAndTurnAboutUp) {
  Camera camera = lab_camera();
  move_camera(camera, 0.5f);
  EXPECT_EQ(camera.position, glm::vec3(0.0f, 0.0f, -2.5f));
  const Frame before = camera_frame(camera);
  turn_camera(camera, glm::radians(10.0f));
  // Toward the image's right, by 10 degrees, at the same elevation.
  EXPECT_NEAR(glm::dot(camera.forward, before.right), std::sin(glm::radians(10.0f)), 1e-6f);
  EXPECT_NEAR(glm::dot(camera.forward, glm::normalize(camera.up)), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::length(camera.forward), 1.0f, 1e-6f);
}

TEST(ControlsTest, LightMovesInTheCamerasFrame) {
  const Camera camera = lab_camera();
  const Frame frame = camera_frame(camera);
  Light light;
  light.position = {0.0f, -0.5f, -0.7f};
  ASSERT_TRUE(move_light(light, camera, {0, 0, 1}, 0.1f));  // W: forward, +z here
  EXPECT_NEAR(light.position.z, -0.6f, 1e-6f);
  ASSERT_TRUE(move_light(light, camera, {0, 1, 0}, 0.1f));  // Q: up the image, -y here
  EXPECT_NEAR(light.position.y, -0.6f, 1e-6f);
  ASSERT_TRUE(move_light(light, camera, {1, 0, 0}, 0.1f));  // D: right
  EXPECT_NEAR(glm::dot(light.position, frame.right), 0.1f, 1e-6f);
  Light sun;
  sun.type = Light::Type::directional;
  EXPECT_FALSE(move_light(sun, camera, {1, 0, 0}, 0.1f));
}

TEST(ControlsTest, OrbitKeepsThePivotAhead) {
  Camera camera = lab_camera();
  const glm::vec3 pivot(0.0f);
  orbit(camera, 3.0f, glm::radians(30.0f), glm::radians(20.0f));
  EXPECT_NEAR(glm::distance(camera.position, pivot), 3.0f, 1e-5f);
  EXPECT_NEAR(glm::distance(camera.position + camera.forward * 3.0f, pivot), 0.0f, 1e-5f);
  // Pitch stops short of the pole, where the frame would flip.
  orbit(camera, 3.0f, 0.0f, glm::radians(500.0f));
  EXPECT_LT(std::abs(glm::dot(camera.forward, glm::normalize(camera.up))), std::sin(glm::radians(89.5f)));
  EXPECT_NEAR(glm::distance(camera.position + camera.forward * 3.0f, pivot), 0.0f, 1e-5f);
}

TEST(ControlsTest, PanFollowsTheMouseAndZoomApproaches) {
  Camera camera = lab_camera();
  camera.focal_length = 1.0f;
  const Frame frame = camera_frame(camera);
  // 100 pixels right in a 200-pixel-high image with the pivot 3 ahead: the scene follows the mouse,
  // so the camera moves 1.5 units to the left.
  pan(camera, 3.0f, {100.0f, 0.0f}, 200);
  EXPECT_NEAR(glm::dot(camera.position, frame.right), -1.5f, 1e-5f);
  const float distance = zoom(camera, 3.0f, 1.0f, 0.01f);
  EXPECT_NEAR(distance, 2.7f, 1e-5f);
  EXPECT_NEAR(camera.position.z, -2.7f, 1e-5f);
  // Never past the closest distance, however far the wheel turns.
  EXPECT_EQ(zoom(camera, 2.7f, 1000.0f, 0.01f), 0.01f);
  EXPECT_NEAR(camera.position.z, -0.01f, 1e-5f);
}

TEST(ControlsTest, ASettledCameraReadsBackToTheSameBits) {
  Camera camera = lab_camera();
  orbit(camera, 3.0f, glm::radians(17.3f), glm::radians(-8.1f));
  pan(camera, 3.0f, {13.0f, -7.0f}, 512);
  const glm::vec3 look_at = settle(camera, 2.9f);
  const std::string json = "{" + camera_json(camera, look_at) + ", \"objects\": []}";
  const Scene scene = parse_scene(json, "settled.json");
  EXPECT_EQ(scene.camera.position, camera.position);
  EXPECT_EQ(scene.camera.forward, camera.forward);
  EXPECT_EQ(scene.camera.up, camera.up);
  EXPECT_EQ(scene.camera.focal_length, camera.focal_length);
}

}  // namespace
}  // namespace vkray::view
