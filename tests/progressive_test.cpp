// Progressive renders (session/progressive.h): however a viewer's frames cut the work into steps,
// the image at the last sample is, bit for bit, the one Session::render returns.
#include <chrono>
#include <cstring>
#include <filesystem>
#include <memory>

#include <gtest/gtest.h>

#include "base/errors.h"
#include "load/scene_loader.h"
#include "session/progressive.h"
#include "session/session.h"
#include "support/gpu_fixture.h"

namespace vkray::test {
namespace {

std::shared_ptr<const Scene> shipped(const char* name) {
  return std::make_shared<const Scene>(load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / name));
}

bool same_bits(const Image& a, const Image& b) {
  return a.width == b.width && a.height == b.height &&
         std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(glm::vec3)) == 0;
}

class ProgressiveTest : public GpuTest {
 protected:
  // Advances `render` to the end with the budget (seconds) `budget(step, render)` gives, checking the
  // bookkeeping after each step; returns the number of steps.
  template <typename Budget>
  static int run_to_end(ProgressiveRender& render, Budget budget) {
    int steps = 0;
    uint32_t last_samples = 0, last_rows = 0;
    while (!render.done()) {
      EXPECT_TRUE(render.advance(std::chrono::duration<double>(budget(steps, render))));
      ++steps;
      // Progress only ever goes forwards.
      EXPECT_TRUE(render.samples() > last_samples || (render.samples() == last_samples && render.rows_ahead() > last_rows));
      last_samples = render.samples();
      last_rows = render.rows_ahead();
    }
    EXPECT_FALSE(render.advance(std::chrono::duration<double>(1.0)));
    return steps;
  }
  // Bands of 8 rows (a budget of nothing) for the first `banded` steps, then one step of about two
  // whole samples, then bands again to the end: every kind of step, each continuing the last.
  static auto bands_then_two_samples_then_bands(int banded) {
    return [banded](int step, const ProgressiveRender& render) {
      if (step != banded) return 0.0;
      const double pixels = double(render.settings().width) * render.settings().height;
      return 2.5 * pixels / render.rate();
    };
  }
};

TEST_F(ProgressiveTest, DirectModelEndsAtTheRendersImageBitForBit) {
  const auto scene = shipped("cornell.json");
  const DeviceScene on_device = session().upload(scene);
  const RenderOptions options = with_image({}, {72, 40, 5});
  const Image rendered = session().render(on_device, options).image;
  // Samples 0 and 1 in bands of 8 rows (5 a sample), 2 and 3 whole, 4 in bands.
  auto progressive = session().start_progressive(on_device, options);
  const int steps = run_to_end(*progressive, bands_then_two_samples_then_bands(10));
  EXPECT_EQ(steps, 16);
  Image shown;
  progressive->image(shown);
  EXPECT_TRUE(same_bits(shown, rendered));
  EXPECT_GT(progressive->rays(), 0u);
}

TEST_F(ProgressiveTest, PathTracerEndsAtTheRendersImageBitForBit) {
  for (const char* name : {"cornell-path.json", "cornell-glass.json"}) {
    const auto scene = shipped(name);
    const DeviceScene on_device = session().upload(scene);
    RenderOptions options = with_image({}, {48, 36, 6});
    options.inline_scene = InlineScene::never;
    const Image rendered = session().render(on_device, options).image;
    auto progressive = session().start_progressive(on_device, options);
    run_to_end(*progressive, bands_then_two_samples_then_bands(5));
    Image shown;
    progressive->image(shown);
    EXPECT_TRUE(same_bits(shown, rendered)) << name;
    // And with the scene compiled into the shader, whose image is the same.
    options.inline_scene = InlineScene::always;
    auto inlined = session().start_progressive(on_device, options);
    run_to_end(*inlined, [](int, const ProgressiveRender&) { return 1e3; });
    inlined->image(shown);
    EXPECT_TRUE(same_bits(shown, rendered)) << name << " compiled in";
  }
}

TEST_F(ProgressiveTest, ImageSoFarIsEachPixelsMeanOfItsSamples) {
  // After one whole sample and a band of the second, the rows of the band show the mean of two
  // samples and the others one sample's value: a render of 1 spp is not that (its pattern is the
  // pixel centre), but the mean of a 2-sample render's samples is what a finished progressive
  // render of 2 samples shows; so check the finished halves against each other.
  const auto scene = shipped("cornell.json");
  const DeviceScene on_device = session().upload(scene);
  const RenderOptions options = with_image({}, {32, 32, 2});
  auto progressive = session().start_progressive(on_device, options);
  Image before(32, 32);
  for (auto& p : before.pixels) p = glm::vec3(-1.0f);
  progressive->advance(std::chrono::duration<double>(0.0));  // rows 0..8 of sample 0
  ASSERT_EQ(progressive->rows_ahead(), 8u);
  Image shown = before;
  progressive->image(shown);
  for (uint32_t y = 0; y < 32; ++y)
    for (uint32_t x = 0; x < 32; ++x) {
      if (y < 8) EXPECT_GE(shown.at(x, y).r, 0.0f) << x << "," << y;
      else EXPECT_EQ(shown.at(x, y).r, -1.0f) << "a row without samples is left as it was";
    }
}

TEST_F(ProgressiveTest, FirstHitPassesEndAtTheRendersBitForBit) {
  const auto scene = shipped("depth-of-field.json");
  const DeviceScene on_device = session().upload(scene);
  RenderOptions options = with_image({}, {40, 32, 4});
  options.aovs = true;
  const RenderResult rendered = session().render(on_device, options);
  auto progressive = session().start_progressive(on_device, options);
  ASSERT_TRUE(progressive->has_aovs());
  run_to_end(*progressive, bands_then_two_samples_then_bands(4));
  Image shown;
  progressive->image(shown);
  EXPECT_TRUE(same_bits(shown, rendered.image));
  Aovs passes;
  progressive->aovs(passes);
  const Aovs& want = *rendered.aovs;
  EXPECT_TRUE(passes.albedo == want.albedo && passes.normal == want.normal && passes.position == want.position);
  EXPECT_EQ(std::memcmp(passes.depth.data(), want.depth.data(), want.depth.size() * sizeof(float)), 0);
  EXPECT_TRUE(passes.object == want.object);
}

TEST_F(ProgressiveTest, RefusesRegions) {
  const auto scene = shipped("cornell.json");
  const DeviceScene on_device = session().upload(scene);
  RenderOptions options = with_image({}, {16, 16, 1});
  options.region = PixelRegion{0, 0, 8, 8};
  EXPECT_THROW(session().start_progressive(on_device, options), UsageError);
}

}  // namespace
}  // namespace vkray::test
