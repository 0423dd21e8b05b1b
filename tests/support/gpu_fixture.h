// A GoogleTest fixture for tests that use the device: a session with the validation layer on, where
// any validation message (during the test or while the device is torn down) fails the test.
#pragma once

#include <filesystem>
#include <memory>

#include <gtest/gtest.h>

#include "session/session.h"

namespace vkray::test {

class GpuTest : public ::testing::Test {
 protected:
  void SetUp() override;
  void TearDown() override;
  // The shaders the session compiles: the shipped ones unless a test's fixture says otherwise.
  virtual std::filesystem::path shader_dir() const;
  Session& session() { return *session_; }
  // The scene's image at `image`, rendered on the device or with the CPU reference.
  Image render(const Scene& scene, const ImageSettings& image, RenderOptions options = {}, bool cpu = false);

 private:
  std::unique_ptr<Session> session_;
};

// The image's mean radiance per channel, in double.
glm::dvec3 image_mean(const Image& image);

// `options` with the image settings overridden by `image`.
RenderOptions with_image(RenderOptions options, const ImageSettings& image);

}  // namespace vkray::test
