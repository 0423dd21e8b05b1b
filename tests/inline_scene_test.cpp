// The GLSL that compiles a small scene into the shader (packing/inline_scene.h): every primitive tested
// once, in the scene's order, with its place in the primitive buffer; every coordinate written so
// that it reads back as exactly the same float; each distinct vertex sheared once.
#include <bit>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "packing/inline_scene.h"
#include "packing/scene_packing.h"
#include "load/scene_loader.h"

namespace vkray::gpu {
namespace {

Scene cornell() { return load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "cornell.json"); }

PackedScene packed(const Scene& scene) { return pack_scene(scene, build_scene_bvh(scene)); }

// What the generated code says, read back.
struct Generated {
  std::map<std::string, glm::vec3> vertices;  // name -> the point given to shear_point
  size_t shear_calls = 0;
  struct Test {
    std::vector<glm::vec3> points;  // a triangle's vertices, or a sphere's center
    float radius = 0;               // spheres
    uint32_t prim = 0;              // place in the primitive buffer
  };
  std::vector<Test> tests;
};

float read_float(const std::string& text) {
  char* end = nullptr;
  const float value = std::strtof(text.c_str(), &end);
  EXPECT_EQ(*end, '\0') << "not a number: " << text;
  return value;
}

glm::vec3 read_vec3(const std::string& x, const std::string& y, const std::string& z) {
  return {read_float(x), read_float(y), read_float(z)};
}

Generated read_back(const std::string& code) {
  static const std::string number = R"(([-+0-9.eE]+))";
  static const std::string vec3 = "vec3\\(" + number + ", " + number + ", " + number + "\\)";
  static const std::regex shear("^  vec3 (p\\d+) = shear_point\\(" + vec3 + " - o, k, s\\);$");
  static const std::regex triangle(R"(^  t = sheared_triangle\((p\d+), (p\d+), (p\d+), t_min, bound\);$)");
  static const std::regex sphere("^  t = intersect_sphere\\(ray, " + vec3 + ", " + number + ", t_min, bound\\);$");
  static const std::regex keep(R"(^  if \(t > 0\.0\) \{ best_t = t; best = (\d+)u; .*\}$)");
  Generated g;
  std::istringstream in(code);
  std::string line;
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_match(line, m, shear)) {
      ++g.shear_calls;
      g.vertices[m[1]] = read_vec3(m[2], m[3], m[4]);
    } else if (std::regex_match(line, m, triangle)) {
      g.tests.push_back({{g.vertices.at(m[1]), g.vertices.at(m[2]), g.vertices.at(m[3])}});
    } else if (std::regex_match(line, m, sphere)) {
      g.tests.push_back({{read_vec3(m[1], m[2], m[3])}, read_float(m[4])});
    } else if (std::regex_match(line, m, keep)) {
      EXPECT_FALSE(g.tests.empty());
      g.tests.back().prim = uint32_t(std::stoul(m[1]));
    }
  }
  return g;
}

bool same_bits(glm::vec3 a, glm::vec3 b) {
  return std::bit_cast<uint32_t>(a.x) == std::bit_cast<uint32_t>(b.x) &&
         std::bit_cast<uint32_t>(a.y) == std::bit_cast<uint32_t>(b.y) &&
         std::bit_cast<uint32_t>(a.z) == std::bit_cast<uint32_t>(b.z);
}

uint32_t scene_index(const PackedScene& p, uint32_t prim) {
  return std::bit_cast<uint32_t>(p.primitives[size_t(prim) * VKRAY_TEXELS_PER_PRIMITIVE + 1].w);
}

TEST(InlineSceneTest, EmptySceneHasNoCode) {
  Scene scene = cornell();
  scene.triangles.clear();
  EXPECT_EQ(inline_scene_glsl(packed(scene)), "");
}

TEST(InlineSceneTest, EveryPrimitiveOnceInTheScenesOrderWithItsExactCoordinates) {
  Scene scene = cornell();
  scene.spheres.push_back({{0.25f, 0.5f, 0.3f}, 0.2f, 0});
  const PackedScene p = packed(scene);
  const std::string code = inline_scene_glsl(p);
  ASSERT_NE(code.find("#define VKRAY_INLINE_SCENE"), std::string::npos);
  const Generated g = read_back(code);

  const size_t count = scene.triangles.size() + scene.spheres.size();
  ASSERT_EQ(g.tests.size(), count);
  std::set<uint32_t> prims;
  for (size_t i = 0; i < g.tests.size(); ++i) {
    const auto& test = g.tests[i];
    ASSERT_LT(test.prim, count);
    prims.insert(test.prim);
    // The scene's order: the tie rule in the shader relies on it.
    EXPECT_EQ(scene_index(p, test.prim), i) << "test " << i;
    // The primitive at that place in the buffer, to the bit.
    const glm::vec4* t = &p.primitives[size_t(test.prim) * VKRAY_TEXELS_PER_PRIMITIVE];
    if (test.points.size() == 1) {
      EXPECT_TRUE(std::bit_cast<uint32_t>(t[0].w) & VKRAY_PRIM_SPHERE);
      EXPECT_TRUE(same_bits(test.points[0], glm::vec3(t[0])));
      EXPECT_EQ(std::bit_cast<uint32_t>(test.radius), std::bit_cast<uint32_t>(t[1].x));
    } else {
      for (int v = 0; v < 3; ++v) EXPECT_TRUE(same_bits(test.points[v], glm::vec3(t[v]))) << "test " << i << " vertex " << v;
    }
  }
  EXPECT_EQ(prims.size(), count) << "a primitive tested twice, another never";
}

TEST(InlineSceneTest, EachDistinctVertexShearedOnce) {
  const Scene scene = cornell();
  std::set<std::array<uint32_t, 3>> distinct;
  for (const auto& t : scene.triangles)
    for (const auto& v : t.v)
      distinct.insert({std::bit_cast<uint32_t>(v.x), std::bit_cast<uint32_t>(v.y), std::bit_cast<uint32_t>(v.z)});
  const Generated g = read_back(inline_scene_glsl(packed(scene)));
  EXPECT_EQ(g.shear_calls, distinct.size());
  EXPECT_LT(distinct.size(), 3 * scene.triangles.size());  // the box's triangles share corners
}

TEST(InlineSceneTest, AwkwardFloatsReadBackExactly) {
  // Literals glslang reads as doubles and rounds to float: 17 significant digits make that exact.
  Scene scene = cornell();
  scene.triangles.resize(1);
  scene.triangles[0].v = {glm::vec3(0.1f, -1e-30f, std::nextafter(kMaxCoordinate, 0.0f)), glm::vec3(1.0f / 3.0f, 16777217.0f, -0.0f),
                          glm::vec3(1e-40f, 2.5f, std::nextafter(1.0f, 2.0f))};
  const Generated g = read_back(inline_scene_glsl(packed(scene)));
  ASSERT_EQ(g.tests.size(), 1u);
  for (int v = 0; v < 3; ++v) EXPECT_TRUE(same_bits(g.tests[0].points[v], scene.triangles[0].v[v])) << "vertex " << v;
}

}  // namespace
}  // namespace vkray::gpu
