#include "support/gpu_fixture.h"

#include "base/errors.h"
#include "session/cpu_render.h"

namespace vkray::test {

RenderOptions with_image(RenderOptions options, const ImageSettings& image) {
  options.width = image.width;
  options.height = image.height;
  options.samples_per_pixel = image.samples_per_pixel;
  return options;
}

void GpuTest::SetUp() {
  SessionOptions options;
  options.validation = true;
  options.shader_dir = shader_dir();
  session_ = std::make_unique<Session>(options);  // no device is a failure, never a skip
}

std::filesystem::path GpuTest::shader_dir() const { return VKRAY_SHADER_DIR; }

void GpuTest::TearDown() {
  try {
    session_->close();
  } catch (const Error& e) {
    ADD_FAILURE() << e.what();
  }
  session_.reset();
}

Image GpuTest::render(const Scene& scene, const ImageSettings& image, RenderOptions options, bool cpu) {
  options = with_image(std::move(options), image);
  if (cpu) return render_on_cpu(scene, options).image;
  return session().render(session().upload(std::make_shared<const Scene>(scene)), options).image;
}

glm::dvec3 image_mean(const Image& image) {
  glm::dvec3 sum(0.0);
  for (const glm::vec3& p : image.pixels) sum += glm::dvec3(p);
  return sum / double(image.pixels.size());
}

}  // namespace vkray::test
