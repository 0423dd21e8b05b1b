// Meshes placed by instances (scene/scene.h, Instance): stored once, their transforms applied to rays
// on both renderers. An instanced scene renders as the same scene with every instance copied into
// place does, on each renderer; the two renderers agree on it (with instanced emitters and
// see-through surfaces, mirrors and non-uniform scales among the transforms); parity notices a
// shader that forgets to turn an instance's normals or to place its emitters.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "cpu/reference.h"
#include "load/scene_loader.h"
#include "support/error_of.h"
#include "support/parity_run.h"
#include "support/temp_dir.h"
#include "support/test_assets.h"

namespace vkray::test {
namespace {

// A smooth sphere of radius 0.5 standing on y = 0, as an OBJ file with vertex normals.
std::string sphere_obj() {
  std::string obj;
  constexpr int kRings = 8, kSegments = 12;
  for (int r = 0; r <= kRings; ++r)
    for (int s = 0; s < kSegments; ++s) {
      const double theta = M_PI * r / kRings, phi = 2 * M_PI * s / kSegments;
      const double x = std::sin(theta) * std::cos(phi), y = std::cos(theta), z = std::sin(theta) * std::sin(phi);
      obj += "v " + std::to_string(0.5 * x) + " " + std::to_string(0.5 + 0.5 * y) + " " + std::to_string(0.5 * z) + "\n";
      obj += "vn " + std::to_string(x) + " " + std::to_string(y) + " " + std::to_string(z) + "\n";
    }
  const auto at = [](int r, int s) { return std::to_string(r * kSegments + s % kSegments + 1); };
  for (int r = 0; r < kRings; ++r)
    for (int s = 0; s < kSegments; ++s) {
      const std::string a = at(r, s), b = at(r, s + 1), c = at(r + 1, s + 1), d = at(r + 1, s);
      obj += "f " + a + "//" + a + " " + b + "//" + b + " " + c + "//" + c + "\n";
      obj += "f " + a + "//" + a + " " + c + "//" + c + " " + d + "//" + d + "\n";
    }
  return obj;
}

// The placements of the sphere: turned, squashed along a tilted axis, mirrored.
const char* const kPlacements[] = {
    R"({"translate": [-1.2, 0, 0], "rotate": [0, 30, 0], "scale": 1.0})",
    R"({"translate": [0, 0.1, -0.6], "rotate": [20, -40, 10], "scale": [1.4, 0.6, 0.9]})",
    R"({"translate": [1.1, 0, 0.2], "scale": [-0.9, 1.2, 0.9]})",
};
// The lamp (an emissive triangle) and the leaf (a see-through one), each placed twice.
const char* const kLampPlacements[] = {R"({"translate": [-0.8, 1.6, -0.8]})", R"({"translate": [0.9, 1.5, -0.6], "rotate": [0, 0, 25], "scale": [1.5, 1, 1]})"};
const char* const kLeafPlacements[] = {R"({"translate": [-0.3, 0, 0.9]})", R"({"translate": [0.5, 0, 0.7], "scale": [-1, 1.2, 1]})"};

// The scene, its sphere, lamp and leaf placed by "instances" (`instanced`) or as one object each
// time. The floor comes first and the instanced objects in the same order either way, so both
// number their primitives alike (PrimitiveNumbering).
std::string scene_json(bool instanced, bool path) {
  const auto placed = [&](const std::string& object, const char* const* placements, size_t count) {
    std::string out;
    if (instanced) {
      out = object + R"(, "instances": [)";
      for (size_t i = 0; i < count; ++i) out += std::string(i ? ", " : "") + placements[i];
      return out + "]}";
    }
    for (size_t i = 0; i < count; ++i) out += std::string(i ? ", " : "") + object + R"(, "transform": )" + placements[i] + "}";
    return out;
  };
  const std::string integrator = path ? R"({"type": "path", "max_depth": 4})" : R"({"type": "direct"})";
  return R"({"camera": {"position": [0, 1.4, 4], "look_at": [0, 0.5, 0], "vertical_fov": 45},
    "integrator": )" + integrator + R"(, "background": [0.15, 0.18, 0.22],
    "lights": [{"type": "point", "position": [2, 4, 3], "intensity": [20, 20, 20]}],
    "materials": {"floor": {"albedo": [0.6, 0.6, 0.6]}, "red": {"albedo": [0.8, 0.3, 0.2]},
                  "glow": {"albedo": [0, 0, 0], "emission": [6, 5, 4]},
                  "leaf": {"albedo": [0.3, 0.7, 0.2], "alpha_mode": "blend", "opacity": 0.5}},
    "objects": [{"type": "triangles", "material": "floor", "positions": [[-3, 0, -3], [3, 0, -3], [3, 0, 3], [-3, 0, 3]],
                 "indices": [[0, 2, 1], [0, 3, 2]]},
                )" + placed(R"({"type": "mesh", "file": "sphere.obj", "material": "red", "smooth": true)", kPlacements, 3) + ",\n" +
         placed(R"({"type": "triangles", "material": "glow", "positions": [[-0.3, 0, 0], [0.3, 0, 0], [0, 0.4, 0.1]], "indices": [[0, 1, 2]])", kLampPlacements, 2) + ",\n" +
         placed(R"({"type": "triangles", "material": "leaf", "positions": [[-0.4, 0.1, 0], [0.4, 0.1, 0], [0, 0.9, 0]], "indices": [[0, 1, 2]])", kLeafPlacements, 2) +
         "]}";
}

class InstancedScene {
 public:
  InstancedScene() { write_file(dir_ / "sphere.obj", sphere_obj()); }
  Scene load(bool instanced, bool path) {
    const auto file = dir_ / (std::string(instanced ? "instanced" : "copied") + (path ? "-path" : "-direct") + ".json");
    write_file(file, scene_json(instanced, path));
    return load_scene(file);
  }

 private:
  TempDir dir_;
};

// The mean of each channel.
glm::dvec3 mean(const Image& image) {
  glm::dvec3 sum(0.0);
  for (const glm::vec3& p : image.pixels) sum += glm::dvec3(p);
  return sum / double(image.pixels.size());
}

// The share of pixels whose channels differ by more than 2% (of 1 or the brighter value).
double share_different(const Image& a, const Image& b) {
  size_t different = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c)
      if (std::abs(a.pixels[i][c] - b.pixels[i][c]) > 0.02f * std::max({1.0f, a.pixels[i][c], b.pixels[i][c]})) {
        ++different;
        break;
      }
  return double(different) / double(a.pixels.size());
}

TEST(InstancingTest, AMeshPlacedByInstancesIsStoredOnce) {
  InstancedScene s;
  const Scene instanced = s.load(true, false), copied = s.load(false, false);
  ASSERT_EQ(instanced.meshes.size(), 3u);  // the sphere, the lamp, the leaf
  EXPECT_EQ(instanced.instances.size(), 7u);
  EXPECT_EQ(instanced.triangles.size(), 2u);  // the floor
  EXPECT_EQ(instanced.instances[0].object, 1u);
  EXPECT_EQ(instanced.instances[6].object, 3u);
  const PrimitiveNumbering numbering(instanced);
  EXPECT_EQ(numbering.count(), copied.triangles.size());
  EXPECT_EQ(numbering.instance_first(1), 2 + instanced.meshes[0].triangles.size());
}

TEST(InstancingTest, BruteForceFindsWhatTheTwoLevelsFind) {
  InstancedScene s;
  const Scene scene = s.load(true, false);
  cpu::ReferenceOptions brute;
  brute.use_bvh = false;
  const auto a = cpu::render_reference(scene, {48, 36, 1});
  const auto b = cpu::render_reference(scene, {48, 36, 1}, brute);
  EXPECT_EQ(a.signatures, b.signatures);
  EXPECT_EQ(a.image.pixels, b.image.pixels);
}

TEST(InstancingTest, APlacementPastTheCoordinateLimitNamesItsInstance) {
  TempDir dir;
  write_file(dir / "sphere.obj", sphere_obj());
  write_file(dir / "scene.json", R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "vertical_fov": 40}, "materials": {"m": {"albedo": [0.5, 0.5, 0.5]}},
    "objects": [{"type": "mesh", "file": "sphere.obj", "material": "m", "instances": [{"translate": [0, 0, 0]}, {"translate": [2e9, 0, 0]}]}]})");
  const std::string message = error_of([&] { load_scene(dir / "scene.json"); });
  EXPECT_NE(message.find("/objects/0/instances/1"), std::string::npos) << message;
}

class InstancingParityTest : public ParityTest, public ::testing::WithParamInterface<bool> {};

// Each renderer draws the instanced scene as it draws the copies; and the two agree on it.
TEST_P(InstancingParityTest, InstancesRenderAsTheirCopies) {
  const bool path = GetParam();
  InstancedScene s;
  const ImageSettings image{96, 72, path ? 16u : 4u};
  const ParityResult instanced = run(s.load(true, path), image), copied = run(s.load(false, path), image);
  expect_parity(instanced, std::string("instances-") + (path ? "path" : "direct"));
  for (const auto& [a, b, what] : {std::tuple{&instanced.gpu.image, &copied.gpu.image, "GPU"}, std::tuple{&instanced.cpu.image, &copied.cpu.image, "CPU"}}) {
    const glm::dvec3 ma = mean(*a), mb = mean(*b);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(ma[c], mb[c], 2e-3 * mb[c]) << what << " channel " << c;
    EXPECT_LT(share_different(*a, *b), 0.01) << what;
  }
}

INSTANTIATE_TEST_SUITE_P(Integrators, InstancingParityTest, ::testing::Bool(), [](const auto& p) { return p.param ? "Path" : "Direct"; });

// A shader that shades an instance with its mesh-space normals must fail parity.
class InstanceNormalsNotTurnedTest : public BrokenShaderParityTest {
 protected:
  InstanceNormalsNotTurnedTest()
      : BrokenShaderParityTest("instances.glsl", "return normalize(n.x * r0.xyz + n.y * r1.xyz + n.z * r2.xyz);", "return normalize(n);") {}
};

TEST_F(InstanceNormalsNotTurnedTest, FailsParity) {
  InstancedScene s;
  EXPECT_FALSE(run(s.load(true, false), {96, 72, 4}).metrics.pass);
}

// So must one whose light sampling leaves an instanced emitter where its mesh has it.
class InstanceEmittersNotPlacedTest : public BrokenShaderParityTest {
 protected:
  InstanceEmittersNotPlacedTest()
      : BrokenShaderParityTest("emitters.glsl", "      light.position = point_to_world(entry_plus_one - 1u, light.position);", "") {}
};

TEST_F(InstanceEmittersNotPlacedTest, FailsParity) {
  InstancedScene s;
  EXPECT_FALSE(run(s.load(true, false), {96, 72, 4}).metrics.pass);
}

}  // namespace
}  // namespace vkray::test
