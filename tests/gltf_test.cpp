// glTF 2.0 files: what each part of a file becomes in a scene (meshes through the node hierarchy,
// materials and textures, the camera, lights), both ways in (an object of a vkray scene, the file as
// the scene), and every way a file can be wrong: its values against glTF's schema, and its URIs.
#include <cstring>
#include <functional>
#include <set>
#include <vector>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_access.hpp>
#include <gtest/gtest.h>

#include "base/errors.h"
#include "gltf/gltf.h"
#include "load/scene_loader.h"
#include "scene/scene.h"
#include "support/error_of.h"
#include "support/temp_dir.h"
#include "support/test_assets.h"

namespace vkray {
namespace {

using nlohmann::json;
using test::GltfBuilder;

using test::error_of;

GltfScene parse(const std::string& bytes) { return parse_gltf(bytes, "test.gltf"); }

// The error parse() raises for a builder's file: it names the file and contains `what`.
void expect_error(const GltfBuilder& b, const std::string& what) {
  const std::string message = error_of([&] { parse(b.gltf()); });
  EXPECT_NE(message.find("test.gltf: "), std::string::npos) << message;
  EXPECT_NE(message.find(what), std::string::npos) << "expected \"" << what << "\" in: " << message;
}

// The same for the file as a .glb.
void expect_error_in_glb(const GltfBuilder& b, const std::string& what) {
  const std::string message = error_of([&] { parse_gltf(b.glb(), "test.glb"); });
  EXPECT_NE(message.find("test.glb: "), std::string::npos) << message;
  EXPECT_NE(message.find(what), std::string::npos) << "expected \"" << what << "\" in: " << message;
}

GltfBuilder textured_quad() {
  GltfBuilder b;
  const int texture = b.texture(test::png_bytes(test::four_colours()), {{"magFilter", 9728}, {"wrapS", 33648}, {"wrapT", 33071}});
  b.quad(b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", texture}}}, {"baseColorFactor", {0.5, 1, 1, 1}},
                                               {"metallicFactor", 0}}}}));
  return b;
}

TEST(GltfTest, ATexturedQuadAsGltfAndAsGlb) {
  const GltfBuilder b = textured_quad();
  for (const std::string& bytes : {b.gltf(), b.glb()}) {
    const GltfScene s = parse(bytes);
    ASSERT_EQ(s.triangles.size(), 2u);
    ASSERT_EQ(s.materials.size(), 1u);
    ASSERT_EQ(s.textures.size(), 1u);
    EXPECT_EQ(s.textures[0]->width, 2u);
    const Material& m = s.materials[0];
    EXPECT_EQ(m.albedo, glm::vec3(0.5f, 1.0f, 1.0f));
    EXPECT_EQ(m.albedo_texture, (TextureRef{0, TextureWrap::mirrored_repeat, TextureWrap::clamp_to_edge, TextureFilter::nearest}));
    EXPECT_EQ(s.triangles[0].v[2], glm::vec3(1, 1, 0));
    EXPECT_EQ(s.triangles[0].uv[2], glm::vec2(1, 0));
    EXPECT_FALSE(s.triangles[0].smooth);  // no NORMAL: flat
    EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  }
}

TEST(GltfTest, NonIndexedStripsAndFansMakeTheSameTriangles) {
  GltfBuilder plain;
  plain.quad(-1, false);
  EXPECT_EQ(parse(plain.gltf()).triangles.size(), 2u);
  for (const int mode : {5, 6}) {  // TRIANGLE_STRIP, TRIANGLE_FAN
    GltfBuilder b;
    b.quad();
    auto& primitive = b.doc["meshes"][0]["primitives"][0];
    primitive["mode"] = mode;
    primitive["indices"] = b.indices(mode == 5 ? std::vector<uint32_t>{0, 1, 3, 2} : std::vector<uint32_t>{0, 1, 2, 3}, 5121);
    const GltfScene s = parse(b.gltf());
    ASSERT_EQ(s.triangles.size(), 2u) << mode;
    for (const Triangle& t : s.triangles) {  // both face +z, as the quad does
      const glm::vec3 n = glm::cross(t.v[1] - t.v[0], t.v[2] - t.v[0]);
      EXPECT_GT(n.z, 0.0f) << mode;
    }
  }
  GltfBuilder lines;
  lines.quad();
  lines.doc["meshes"][0]["primitives"][0]["mode"] = 1;
  const GltfScene s = parse(lines.gltf());
  EXPECT_TRUE(s.triangles.empty());
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("meshes[0].primitives[0]: points and lines (mode 1) are not rendered"), std::string::npos) << s.warnings[0];
}

TEST(GltfTest, NodeTransformsComposeDownTheHierarchy) {
  GltfBuilder b;
  const int quad = b.quad();
  b.doc["scenes"][0]["nodes"] = {1};
  b.doc["nodes"][quad]["scale"] = {2, 3, 1};
  // A parent at x = 10, turned 90 degrees about z, that holds the scaled quad.
  b.doc["nodes"].push_back({{"translation", {10, 0, 0}}, {"rotation", {0, 0, 0.7071067811865476, 0.7071067811865476}}, {"children", {quad}}});
  const GltfScene s = parse(b.gltf());
  ASSERT_EQ(s.triangles.size(), 2u);
  // Quad corner (1, -1, 0), scaled to (2, -3, 0), turned to (3, 2, 0), moved to (13, 2, 0): scale
  // first, then rotation, then translation (T R S), and the parent's after the child's.
  EXPECT_NEAR(s.triangles[0].v[1].x, 13.0f, 1e-5f);
  EXPECT_NEAR(s.triangles[0].v[1].y, 2.0f, 1e-5f);
  // A matrix (column-major) in place of the TRS: a mirror in x turns the winding around, so the front stays +z.
  b.doc["nodes"][1].erase("translation");
  b.doc["nodes"][1].erase("rotation");
  b.doc["nodes"][1]["matrix"] = {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1};
  const GltfScene m = parse(b.gltf());
  EXPECT_NEAR(m.triangles[0].v[0].z, 5.0f, 1e-6f);
  const Triangle& t = m.triangles[0];
  EXPECT_GT(glm::cross(t.v[1] - t.v[0], t.v[2] - t.v[0]).z, 0.0f);
}

// A sparse accessor (glTF 3.6.2.3): its base elements (or zeros, without a buffer view) with the
// elements its indices name replaced by its values.
TEST(GltfTest, SparseAccessorsReplaceTheElementsTheyName) {
  GltfBuilder b;
  b.quad();
  const int values = b.accessor({2, 2, 0, -2, 2, 0}, "VEC3");
  const int indices = b.indices({2, 3}, 5123);
  const json sparse = {{"count", 2},
                       {"indices", {{"bufferView", b.doc["accessors"][indices]["bufferView"]}, {"componentType", 5123}}},
                       {"values", {{"bufferView", b.doc["accessors"][values]["bufferView"]}}}};
  const int position = b.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"];
  b.doc["accessors"][position]["sparse"] = sparse;
  const GltfScene s = parse(b.gltf());
  ASSERT_EQ(s.triangles.size(), 2u);
  EXPECT_EQ(s.triangles[0].v[0], glm::vec3(-1, -1, 0));  // vertex 0, as the buffer has it
  EXPECT_EQ(s.triangles[0].v[2], glm::vec3(2, 2, 0));    // vertex 2, replaced
  EXPECT_EQ(s.triangles[1].v[2], glm::vec3(-2, 2, 0));   // vertex 3, replaced
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];

  // Without a buffer view the base is zeros (SimpleSparseAccessor's form); a .glb reads the same.
  GltfBuilder z = b;
  z.doc["accessors"][position].erase("bufferView");
  for (const std::string& bytes : {z.gltf(), z.glb()}) {
    const GltfScene zs = parse_gltf(bytes, "test.gltf");
    ASSERT_EQ(zs.triangles.size(), 2u);
    EXPECT_EQ(zs.triangles[0].v[0], glm::vec3(0, 0, 0));
    EXPECT_EQ(zs.triangles[0].v[2], glm::vec3(2, 2, 0));
  }

  // Indices that do not increase, or name an element past the accessor, and too many substitutions.
  GltfBuilder bad = b;
  const int backwards = bad.indices({3, 2}, 5123);
  bad.doc["accessors"][position]["sparse"]["indices"]["bufferView"] = bad.doc["accessors"][backwards]["bufferView"];
  expect_error(bad, "accessors[" + std::to_string(position) + "].sparse.indices: index 2 at 1 does not increase on the one before");
  const int past = bad.indices({2, 4}, 5123);
  bad.doc["accessors"][position]["sparse"]["indices"]["bufferView"] = bad.doc["accessors"][past]["bufferView"];
  expect_error(bad, "sparse.indices: index 4 at 1 is past the accessor's 4 elements");
  bad.doc["accessors"][position]["sparse"]["count"] = 5;
  expect_error(bad, "sparse.count: 5 substitutions for an accessor of 4 elements");
  GltfBuilder strided = b;
  strided.doc["bufferViews"][int(b.doc["accessors"][values]["bufferView"])]["byteStride"] = 12;
  expect_error(strided, "has a byteStride; a sparse accessor's may not");
}

// Morph targets displace the mesh by their default weights: the node's, else the mesh's (glTF 3.7.2.2).
TEST(GltfTest, MorphTargetsTakeTheNodesOrTheMeshsDefaultWeights) {
  GltfBuilder b;
  const int node = b.quad();
  auto& primitive = b.doc["meshes"][0]["primitives"][0];
  primitive["attributes"]["NORMAL"] = b.accessor({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3");
  primitive["targets"] = {{{"POSITION", b.accessor({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3")}},
                          {{"POSITION", b.accessor({0, 0, 0, 0, 0, 0, 0, 0, 0, 4, 0, 0}, "VEC3")},
                           {"NORMAL", b.accessor({1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0}, "VEC3")}}};
  const GltfScene rest = parse(b.gltf());  // no weights: as stored
  EXPECT_EQ(rest.triangles[0].v[0], glm::vec3(-1, -1, 0));
  b.doc["meshes"][0]["weights"] = {0.5, 0.25};
  const GltfScene mesh = parse(b.gltf());
  ASSERT_EQ(mesh.triangles.size(), 2u);
  EXPECT_EQ(mesh.triangles[0].v[0], glm::vec3(-1, -1, 0.5f));
  EXPECT_EQ(mesh.triangles[1].v[2], glm::vec3(0, 1, 0.5f));  // vertex 3: x -1 + 0.25 * 4
  // Normals are displaced too, then made unit: (0.25, 0, 1) / |...|.
  EXPECT_NEAR(mesh.triangles[0].normals[0].x, 0.25f / std::sqrt(1.0625f), 1e-6f);
  EXPECT_TRUE(mesh.warnings.empty()) << mesh.warnings[0];
  b.doc["nodes"][node]["weights"] = {2, 0};
  const GltfScene by_node = parse(b.gltf());
  EXPECT_EQ(by_node.triangles[0].v[0], glm::vec3(-1, -1, 2));
  EXPECT_EQ(by_node.triangles[1].v[2], glm::vec3(-1, 1, 2));
  // An animation of the weights is not played, and a warning says so.
  b.doc["animations"] = {{{"channels", {{{"sampler", 0}, {"target", {{"node", node}, {"path", "weights"}}}}}},
                          {"samplers", {{{"input", b.accessor({0, 1}, "SCALAR")}, {"output", b.accessor({0, 0, 1, 1}, "SCALAR")}}}}}};
  const GltfScene animated = parse(b.gltf());
  EXPECT_EQ(animated.triangles[0].v[0], by_node.triangles[0].v[0]);
  ASSERT_EQ(animated.warnings.size(), 1u);
  EXPECT_NE(animated.warnings[0].find("animations: 1 animations are not played: the file is shown at rest"), std::string::npos)
      << animated.warnings[0];
  // Applying them is held to the file's budget: here 2 triangles x 3 corners x 1 displacement (target
  // 0's POSITION; target 1 weighs 0).
  GltfLimits budget;
  budget.max_morph_displacements = 5;
  const std::string work = error_of([&] { parse_gltf(b.gltf(), "test.gltf", budget); });
  EXPECT_NE(work.find("morph targets take more than 5 vertex displacements"), std::string::npos) << work;
  budget.max_morph_displacements = 6;
  EXPECT_NO_THROW(parse_gltf(b.gltf(), "test.gltf", budget));
  b.doc["nodes"][node]["weights"] = {1};
  expect_error(b, "nodes[0].weights: 1 weights for the 2 morph targets of meshes[0].primitives[0]");
  b.doc["nodes"][node]["weights"] = {1, 1};
  b.doc["meshes"][0]["primitives"][0]["targets"][1]["POSITION"] = b.accessor({0, 0, 0}, "VEC3");
  expect_error(b, "meshes[0].primitives[0].targets[1].POSITION: 1 elements, where POSITION has 4");
}

// EXT_mesh_gpu_instancing: the node's mesh once per instance, each placed by its own translation,
// rotation and scale and then by the node's transform.
TEST(GltfTest, GpuInstancingPlacesTheMeshOncePerInstance) {
  GltfBuilder b;
  const int node = b.quad();
  b.doc["nodes"][node]["translation"] = {0, 0, 5};
  b.doc["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
  b.doc["extensionsRequired"] = {"EXT_mesh_gpu_instancing"};
  b.doc["nodes"][node]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"] = {
      {"TRANSLATION", b.accessor({0, 0, 0, 10, 0, 0, 0, 10, 0}, "VEC3")},
      {"SCALE", b.accessor({1, 1, 1, 2, 2, 2, 1, 1, 1}, "VEC3")},
      {"ROTATION", b.accessor({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0.7071067811865476f, 0.7071067811865476f}, "VEC4")},
      {"_ID", b.accessor({0, 1, 2}, "SCALAR")}};
  const GltfScene s = parse(b.gltf());
  // The quad read once, in its own space, and placed three times.
  EXPECT_TRUE(s.triangles.empty());
  ASSERT_EQ(s.meshes.size(), 1u);
  ASSERT_EQ(s.meshes[0].triangles.size(), 2u);
  ASSERT_EQ(s.instances.size(), 3u);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  const auto placed = [&](size_t instance) { return placed_triangle(s.meshes[0].triangles[0], glm::dmat4(s.instances[instance].to_world)); };
  EXPECT_EQ(placed(0).v[0], glm::vec3(-1, -1, 5));
  EXPECT_EQ(placed(1).v[0], glm::vec3(8, -2, 5));  // corner (-1, -1) scaled by 2, then moved by 10
  // Turned 90 degrees about z: (-1, -1) to (1, -1), moved up by 10.
  EXPECT_NEAR(placed(2).v[0].x, 1.0f, 1e-6f);
  EXPECT_NEAR(placed(2).v[0].y, 9.0f, 1e-6f);
  // More than the file may place are refused.
  GltfLimits small;
  small.max_placed_triangles = 5;
  const std::string many = error_of([&] { parse_gltf(b.gltf(), "test.gltf", small); });
  EXPECT_NE(many.find("test.gltf: nodes[0]: the file places more than 5 triangles"), std::string::npos) << many;
  small.max_placed_triangles = 2;
  const std::string instances = error_of([&] { parse_gltf(b.gltf(), "test.gltf", small); });
  EXPECT_NE(instances.find("test.gltf: nodes[0].extensions.EXT_mesh_gpu_instancing: 3 instances; vkray places at most 16777216 "
                            "meshes and 2 triangles"),
            std::string::npos)
      << instances;
  b.doc["nodes"][node]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["SCALE"] = b.accessor({1, 1, 1}, "VEC3");
  expect_error(b, "EXT_mesh_gpu_instancing.attributes.SCALE: 1 instances, where another attribute has 3");
}

// A mesh that several nodes place is read once and placed by instances; one placed once, or by a
// transform that cannot be inverted, is read in place as before.
TEST(GltfTest, NodesSharingAMeshPlaceItByInstances) {
  GltfBuilder b;
  b.quad();
  b.quad();  // a second mesh, placed once
  // (The last: a scale no float holds, 1e-50, which leaves the mesh to be read in place.)
  for (const auto& [translation, scale] : {std::pair{3.0, 1.0}, std::pair{-3.0, -1.0}, std::pair{0.0, 0.0}, std::pair{0.0, 1e-50}}) {
    b.doc["nodes"].push_back({{"mesh", 0}, {"translation", {translation, 0, 0}}, {"scale", {scale, 1, 1}}});
    b.doc["scenes"][0]["nodes"].push_back(int(b.doc["nodes"].size()) - 1);
  }
  const GltfScene s = parse(b.gltf());
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].triangles.size(), 2u);
  ASSERT_EQ(s.instances.size(), 3u);  // the first node, and the two it shares its mesh with
  EXPECT_EQ(glm::vec3(s.instances[1].to_world[3]), glm::vec3(3, 0, 0));
  EXPECT_LT(glm::determinant(glm::mat3(s.instances[2].to_world)), 0.0f);  // mirrored, as the file has it
  // In place: the second mesh, and the first where a node scales it to nothing (its triangles then
  // degenerate, which the scene leaves out).
  EXPECT_EQ(s.triangles.size(), 6u);
  // A node's matrix whose last row is not (0, 0, 0, 1) places its copies by the affine part, and so
  // its instances.
  b.doc["nodes"][3] = {{"mesh", 0}, {"matrix", {1, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, 0, 3, 0, 0, 2}}};
  const GltfScene projective = parse(b.gltf());
  ASSERT_EQ(projective.instances.size(), 3u);
  EXPECT_EQ(glm::row(projective.instances[2].to_world, 3), glm::vec4(0, 0, 0, 1));
  EXPECT_EQ(glm::vec3(projective.instances[2].to_world[3]), glm::vec3(3, 0, 0));
}

TEST(GltfTest, AFlatteningScaleKeepsWhatStaysInThePlane) {
  GltfBuilder b;
  const int quad = b.quad();
  b.doc["nodes"][quad]["scale"] = {1, 1, 0};  // the quad lies in z = 0: unchanged
  b.doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = b.accessor({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3");
  const GltfScene s = parse(b.gltf());
  ASSERT_EQ(s.triangles.size(), 2u);
  EXPECT_TRUE(s.triangles[0].smooth);
  EXPECT_EQ(s.triangles[0].normals[0], glm::vec3(0, 0, 1));
}

TEST(GltfTest, ARotatedCameraLooksDownItsLocalMinusZ) {
  GltfBuilder b;
  b.quad();
  b.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}}};
  // Turned 90 degrees about y: its -z becomes -x, its +y stays up; tilted by its parent 90 about x.
  b.doc["nodes"].push_back({{"camera", 0}, {"rotation", {0, 0.7071067811865476, 0, 0.7071067811865476}}});
  b.doc["nodes"].push_back({{"children", {1}}, {"rotation", {0.7071067811865476, 0, 0, 0.7071067811865476}}});
  b.doc["scenes"][0]["nodes"].push_back(2);
  const GltfScene s = parse(b.gltf());
  ASSERT_TRUE(s.camera);
  EXPECT_NEAR(glm::distance(s.camera->forward, glm::vec3(-1, 0, 0)), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::distance(s.camera->up, glm::vec3(0, 0, 1)), 0.0f, 1e-6f);  // +y turned by the parent to +z
}

TEST(GltfTest, PicturesAreDecodedOnceAndWithinTheTexelBudget) {
  GltfBuilder b;
  const int texture = b.texture(test::png_bytes(test::four_colours()));
  b.doc["images"].push_back(b.doc["images"][0]);  // two more images of the same buffer view
  b.doc["images"].push_back(b.doc["images"][0]);
  b.doc["textures"].push_back({{"source", 1}});
  b.doc["textures"].push_back({{"source", 2}});
  for (int t = 0; t < 3; ++t) b.quad(b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", texture + t}}}}}}));
  const GltfScene s = parse(b.gltf());
  EXPECT_EQ(s.textures.size(), 1u);
  GltfLimits tight;
  tight.max_texels = 3;  // the 2 x 2 picture needs 4
  const std::string message = error_of([&] { parse_gltf(b.gltf(), "test.gltf", tight); });
  EXPECT_NE(message.find("test.gltf: images[0]: a 2 x 2 picture would bring the scene's textures past"), std::string::npos) << message;
}

TEST(GltfTest, TheFirstCameraDepthFirstAndTheLights) {
  GltfBuilder b;
  b.quad();
  b.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}, {"aspectRatio", 2.0}}}},
                      {{"type", "perspective"}, {"perspective", {{"yfov", 1.0}, {"znear", 0.1}}}}};
  b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {
      {{"type", "point"}, {"color", {1, 0.5, 0}}, {"intensity", 4}},
      {{"type", "spot"}, {"spot", json::object()}, {"intensity", 2}},
      {{"type", "spot"}, {"spot", {{"innerConeAngle", 0.25}, {"outerConeAngle", 0.5}}}},
      {{"type", "directional"}, {"color", {0.5, 1, 1}}, {"intensity", 3}}};
  // Root 1 holds camera 1 deep inside; root 2 holds camera 0: depth-first, camera 1 comes first.
  b.doc["nodes"].push_back({{"children", {2}}});
  b.doc["nodes"].push_back({{"camera", 1}, {"translation", {0, 0, 3}}});
  b.doc["nodes"].push_back({{"camera", 0}});
  b.doc["nodes"].push_back({{"translation", {0, 4, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  b.doc["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  // Turned a quarter about x: -z, the way a light shines, becomes -y; the translation moves it.
  const double h = std::sqrt(0.5);
  b.doc["nodes"].push_back({{"rotation", {-h, 0, 0, h}}, {"translation", {1, 2, 3}}, {"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}});
  b.doc["nodes"].push_back({{"rotation", {-h, 0, 0, h}}, {"extensions", {{"KHR_lights_punctual", {{"light", 3}}}}}});
  b.doc["scenes"][0]["nodes"] = {0, 1, 3, 4, 5, 6, 7};
  const GltfScene s = parse(b.gltf());
  ASSERT_TRUE(s.camera);
  EXPECT_EQ(s.camera->position, glm::vec3(0, 0, 3));
  EXPECT_EQ(s.camera->forward, glm::vec3(0, 0, -1));
  EXPECT_NEAR(s.camera->focal_length, 0.5f / std::tan(0.5f), 1e-6f);
  EXPECT_EQ(s.aspect_ratio, 0.0f);  // camera 1 gives none
  ASSERT_EQ(s.lights.size(), 4u);
  EXPECT_EQ(s.lights[0].type, Light::Type::point);
  EXPECT_EQ(s.lights[0].position, glm::vec3(0, 4, 0));
  EXPECT_EQ(s.lights[0].intensity, glm::vec3(4, 2, 0));
  // A spot with the specification's defaults: no inner cone, the outer at pi/4, along -z.
  EXPECT_EQ(s.lights[1].type, Light::Type::spot);
  EXPECT_EQ(s.lights[1].falloff, Light::Falloff::gltf);
  EXPECT_EQ(s.lights[1].intensity, glm::vec3(2));
  EXPECT_EQ(s.lights[1].direction, glm::vec3(0, 0, -1));
  EXPECT_FLOAT_EQ(s.lights[1].cutoff_angle, glm::quarter_pi<float>());
  EXPECT_EQ(s.lights[1].beam_width, 0.0f);
  EXPECT_EQ(s.lights[2].position, glm::vec3(1, 2, 3));
  EXPECT_NEAR(glm::distance(s.lights[2].direction, glm::vec3(0, -1, 0)), 0.0f, 1e-6f);
  EXPECT_FLOAT_EQ(s.lights[2].cutoff_angle, 0.5f);
  EXPECT_FLOAT_EQ(s.lights[2].beam_width, 0.25f);
  // A directional light's lux become its irradiance.
  EXPECT_EQ(s.lights[3].type, Light::Type::directional);
  EXPECT_EQ(s.lights[3].intensity, glm::vec3(1.5, 3, 3));
  EXPECT_NEAR(glm::distance(s.lights[3].direction, glm::vec3(0, -1, 0)), 0.0f, 1e-6f);
  EXPECT_TRUE(s.warnings.empty());
}

TEST(GltfTest, ASpotsConesAreCheckedAgainstTheSpecification) {
  for (const auto& [spot, what] : std::vector<std::pair<json, std::string>>{
           {{{"innerConeAngle", 0.5}, {"outerConeAngle", 0.5}}, "lights[0].spot.innerConeAngle: expected radians from 0 to below outerConeAngle"},
           {{{"outerConeAngle", 2.0}}, "lights[0].spot.outerConeAngle: expected radians in (0, pi/2]"},
           {{{"innerConeAngle", -0.1}}, "lights[0].spot.innerConeAngle"}}) {
    GltfBuilder b;
    b.quad();
    b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "spot"}, {"spot", spot}}};
    b.doc["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    b.doc["scenes"][0]["nodes"].push_back(b.doc["nodes"].size() - 1);
    expect_error(b, what);
  }
}

TEST(GltfTest, MaterialsKeepTheirColourAndEmissionAndNameWhatIsNotRendered) {
  GltfBuilder b;
  const int texture = b.texture(test::jpeg_bytes(test::four_colours()));
  const int lamp = b.material({{"emissiveFactor", {1, 0.5, 0.25}},
                               {"emissiveTexture", {{"index", texture}}},
                               {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4}}}}}});
  const int metal = b.material({{"pbrMetallicRoughness", {{"baseColorFactor", {0.2, 0.3, 0.4, 0.5}}, {"metallicFactor", 1}}},
                                {"alphaMode", "MASK"}, {"normalTexture", {{"index", texture}, {"scale", -0.5}}},
                                {"occlusionTexture", {{"index", texture}}}});
  const int leaf = b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", texture}}}}}, {"alphaMode", "BLEND"}});
  b.quad(lamp);
  b.quad(metal);
  b.quad(metal);
  b.quad(leaf);
  const GltfScene s = parse(b.gltf());
  ASSERT_EQ(s.materials.size(), 3u);
  EXPECT_EQ(s.materials[0].emission, glm::vec3(4, 2, 1));
  EXPECT_TRUE(s.materials[0].emission_texture.present());
  EXPECT_EQ(s.materials[1].albedo, glm::vec3(0.2f, 0.3f, 0.4f));
  EXPECT_EQ(s.materials[1].type, MaterialType::metallic_roughness);
  EXPECT_EQ(s.materials[1].metallic, 1.0f);
  EXPECT_EQ(s.materials[1].roughness, 1.0f);  // glTF's default
  EXPECT_TRUE(s.materials[1].normal_texture.present());
  EXPECT_EQ(s.materials[1].normal_scale, -0.5f);
  // Alpha: the base colour's, with glTF's default cutoff; the opacity texture is the base colour's
  // (here none), and an opaque material reads none.
  EXPECT_EQ(s.materials[1].alpha_mode, AlphaMode::mask);
  EXPECT_EQ(s.materials[1].opacity, 0.5f);
  EXPECT_EQ(s.materials[1].alpha_cutoff, 0.5f);
  EXPECT_FALSE(s.materials[1].see_through());  // an opacity at the cutoff, no texture: whole
  EXPECT_EQ(s.materials[0].alpha_mode, AlphaMode::opaque);
  EXPECT_FALSE(s.materials[0].see_through());
  EXPECT_EQ(s.materials[2].alpha_mode, AlphaMode::blend);
  EXPECT_EQ(s.materials[2].opacity_texture, s.materials[2].albedo_texture);
  EXPECT_TRUE(s.materials[2].see_through());
  EXPECT_EQ(s.triangles.size(), 8u);
  std::string all;
  for (const auto& w : s.warnings) all += w + "\n";
  EXPECT_EQ(s.warnings.size(), 1u) << all;  // once, though two quads use the material
  EXPECT_NE(all.find("occlusion textures are not rendered"), std::string::npos) << all;
}

TEST(GltfTest, MaterialsAreGltfsMetallicRoughnessModelWithTheirFactorsAndIor) {
  GltfBuilder b;
  const int plastic = b.material({{"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.1, 0.1, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 0.25}}},
                                  {"extensions", {{"KHR_materials_ior", {{"ior", 1.33}}}}}, {"doubleSided", true}});
  const int mirror_like = b.material({{"pbrMetallicRoughness", {{"metallicFactor", 1}, {"roughnessFactor", 0}}},
                                      {"extensions", {{"KHR_materials_ior", {{"ior", 0}}}}}});
  b.quad(plastic);
  b.quad(mirror_like);
  b.quad();  // no material: glTF's default
  b.doc["extensionsUsed"] = {"KHR_materials_ior"};
  b.doc["extensionsRequired"] = {"KHR_materials_ior"};
  const GltfScene s = parse(b.gltf());
  ASSERT_EQ(s.materials.size(), 3u);
  EXPECT_EQ(s.materials[0].type, MaterialType::metallic_roughness);
  EXPECT_EQ(s.materials[0].albedo, glm::vec3(0.8f, 0.1f, 0.1f));
  EXPECT_EQ(s.materials[0].metallic, 0.0f);
  EXPECT_EQ(s.materials[0].roughness, 0.25f);
  EXPECT_EQ(s.materials[0].ior, 1.33f);
  EXPECT_EQ(s.materials[1].metallic, 1.0f);
  EXPECT_EQ(s.materials[1].roughness, 0.0f);
  EXPECT_EQ(s.materials[1].ior, 0.0f);
  EXPECT_TRUE(s.materials[0].double_sided);
  EXPECT_FALSE(s.materials[1].double_sided);  // glTF's default: single-sided
  const Material& fallback = s.materials[2];  // every property its default: a white rough metal, single-sided
  EXPECT_EQ(fallback.type, MaterialType::metallic_roughness);
  EXPECT_EQ(fallback.albedo, glm::vec3(1.0f));
  EXPECT_EQ(fallback.metallic, 1.0f);
  EXPECT_EQ(fallback.roughness, 1.0f);
  EXPECT_FALSE(fallback.double_sided);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  {
    GltfBuilder bad = textured_quad();
    bad.doc["materials"][0]["pbrMetallicRoughness"]["metallicFactor"] = 1.5;
    expect_error(bad, "materials[0].pbrMetallicRoughness.metallicFactor: expected a number from 0 to 1");
  }
  {
    GltfBuilder bad = textured_quad();
    bad.doc["materials"][0]["extensions"]["KHR_materials_ior"]["ior"] = 0.5;
    expect_error(bad, "materials[0].extensions.KHR_materials_ior.ior: expected 0 or an index of refraction from 1 to 100");
    bad.doc["materials"][0]["extensions"]["KHR_materials_ior"]["ior"] = "glass";
    expect_error(bad, "materials[0].extensions.KHR_materials_ior.ior: expected a number");
    bad.doc["materials"][0]["extensions"]["KHR_materials_ior"]["ior"] = 4294967297;  // tinygltf would take 1
    expect_error(bad, "materials[0].extensions.KHR_materials_ior.ior: expected an index of refraction");
  }
}

TEST(GltfTest, TransmissionIsThinWalledWithItsFactorAndTheRedOfItsTexture) {
  // KHR_materials_transmission: the factor (default 0) times the texture's red, linear data even where
  // the same picture is the base colour (sRGB); the metadata extension KHR_xmp_json_ld warns of nothing.
  GltfBuilder b;
  const int picture = b.texture(test::png_bytes({1, 1, {128, 64, 32}}));
  const int sheet = b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", picture}}}, {"metallicFactor", 0}}},
                                {"extensions", {{"KHR_materials_transmission",
                                                 {{"transmissionFactor", 0.75}, {"transmissionTexture", {{"index", picture}}}}}}}});
  const int bare = b.material({{"extensions", {{"KHR_materials_transmission", nlohmann::json::object()}}}});
  b.quad(sheet);
  b.quad(bare);
  b.doc["extensionsUsed"] = {"KHR_materials_transmission", "KHR_xmp_json_ld"};
  b.doc["extensionsRequired"] = {"KHR_materials_transmission"};
  const GltfScene s = parse(b.gltf());
  ASSERT_EQ(s.materials.size(), 2u);
  const Material& m = s.materials[0];
  EXPECT_EQ(m.transmission, 0.75f);
  EXPECT_TRUE(m.has(VKRAY_BSDF_TRANSMISSION));
  ASSERT_TRUE(m.transmission_texture.present());
  ASSERT_NE(m.transmission_texture.texture, m.albedo_texture.texture);
  EXPECT_NEAR(s.textures[size_t(m.transmission_texture.texture)]->texel(0, 0).r, 128.0f / 255.0f, 1e-3f);
  EXPECT_EQ(s.materials[1].transmission, 0.0f);  // the extension's default
  EXPECT_FALSE(s.materials[1].has(VKRAY_BSDF_TRANSMISSION));
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  {
    GltfBuilder bad = textured_quad();
    bad.doc["materials"][0]["extensions"]["KHR_materials_transmission"]["transmissionFactor"] = -0.5;
    expect_error(bad, "materials[0].extensions.KHR_materials_transmission.transmissionFactor: expected a number from 0 to 1");
  }
}

// KHR_materials_unlit: the base colour (factor times texture) is what the surface sends, and it
// scatters nothing; its alpha stays.
TEST(GltfTest, AnUnlitMaterialShowsItsBaseColourAndScattersNothing) {
  GltfBuilder b;
  const int texture = b.texture(test::png_bytes(test::four_colours()));
  b.quad(b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", texture}}}, {"baseColorFactor", {0.5, 1, 0.25, 0.5}}}},
                     {"alphaMode", "BLEND"}, {"emissiveFactor", {1, 1, 1}}, {"extensions", {{"KHR_materials_unlit", json::object()}}}}));
  b.doc["extensionsUsed"] = {"KHR_materials_unlit"};
  b.doc["extensionsRequired"] = {"KHR_materials_unlit"};
  const GltfScene s = parse(b.gltf());
  ASSERT_EQ(s.materials.size(), 1u);
  const Material& m = s.materials[0];
  EXPECT_EQ(m.type, MaterialType::diffuse);
  EXPECT_EQ(m.albedo, glm::vec3(0.0f));
  EXPECT_EQ(m.emission, glm::vec3(0.5f, 1.0f, 0.25f));  // the base colour, not the emissive factor
  EXPECT_EQ(m.emission_texture.texture, 0);
  EXPECT_FALSE(m.albedo_texture.present());
  EXPECT_EQ(m.alpha_mode, AlphaMode::blend);
  EXPECT_EQ(m.opacity, 0.5f);
  EXPECT_EQ(m.opacity_texture.texture, 0);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  EXPECT_FALSE(m.emits_both_sides);  // glTF's default: single-sided
  // Double-sided, it shows its base colour from both sides.
  b.doc["materials"][0]["doubleSided"] = true;
  const GltfScene two = parse(b.gltf());
  EXPECT_TRUE(two.materials[0].emits_both_sides);
  EXPECT_TRUE(two.warnings.empty()) << two.warnings[0];
}

TEST(GltfTest, TexturesReadTheirOwnTextureCoordinateSets) {
  // The first two sets a material's textures name become the triangles' uv and uv1, in the order its
  // textures are read; a third is named in one warning and reads the first.
  GltfBuilder b;
  const int picture = b.texture(test::png_bytes({1, 1, {128, 128, 128}}));
  b.quad(b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", picture}, {"texCoord", 1}}},
                                               {"metallicRoughnessTexture", {{"index", picture}}}}},
                     {"emissiveTexture", {{"index", picture}, {"texCoord", 1}}}, {"emissiveFactor", {1, 1, 1}},
                     {"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 1}, {"transmissionTexture", {{"index", picture}, {"texCoord", 2}}}}}}}}));
  b.doc["extensionsUsed"] = {"KHR_materials_transmission"};
  auto& attributes = b.doc["meshes"][0]["primitives"][0]["attributes"];
  attributes["TEXCOORD_1"] = b.accessor({5, 6, 7, 8, 9, 10, 11, 12}, "VEC2");
  attributes["TEXCOORD_2"] = b.accessor({0, 0, 0, 0, 0, 0, 0, 0}, "VEC2");
  const GltfScene s = parse(b.gltf());
  const Material& m = s.materials[0];
  EXPECT_EQ(m.albedo_texture.texcoord, 0u);  // TEXCOORD_1, read first: uv
  EXPECT_EQ(m.emission_texture.texcoord, 0u);
  EXPECT_EQ(m.metallic_roughness_texture.texcoord, 1u);  // TEXCOORD_0: uv1
  EXPECT_EQ(m.transmission_texture.texcoord, 0u);        // TEXCOORD_2: a third, read as the first
  ASSERT_EQ(s.triangles.size(), 2u);
  EXPECT_EQ(s.triangles[0].uv[1], glm::vec2(7, 8));   // vertex 1 of TEXCOORD_1
  EXPECT_EQ(s.triangles[0].uv1[1], glm::vec2(1, 1));  // vertex 1 of the quad's TEXCOORD_0
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("the transmissionTexture reads TEXCOORD_2; vkray reads two sets for a material's textures (here "
                               "TEXCOORD_1 and TEXCOORD_0), and it reads TEXCOORD_1"),
            std::string::npos)
      << s.warnings[0];
}

// COLOR_0: normalized integers or floats, three components or four, each clamped to [0, 1]; white
// where a primitive has none.
TEST(GltfTest, VertexColoursAreReadAsTheSpecificationSays) {
  GltfBuilder b;
  b.quad();
  b.doc["accessors"].push_back({{"bufferView", 0}, {"componentType", 5121}, {"normalized", true}, {"count", 4}, {"type", "VEC4"}});
  std::string bytes = {char(255), 0, 0, char(255), 0, char(51), 0, char(255), 0, 0, char(255), char(128), char(255), char(255), char(255), 0};
  while (b.bin.size() % 4) b.bin += '\0';
  b.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", b.bin.size()}, {"byteLength", bytes.size()}});
  b.bin += bytes;
  const int bytes_accessor = int(b.doc["accessors"].size()) - 1;
  b.doc["accessors"][bytes_accessor]["bufferView"] = int(b.doc["bufferViews"].size()) - 1;
  b.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = bytes_accessor;
  const GltfScene s = parse(b.gltf());
  ASSERT_EQ(s.triangles.size(), 2u);
  EXPECT_EQ(s.triangles[0].colours[0], glm::vec4(1, 0, 0, 1));
  EXPECT_EQ(s.triangles[0].colours[1], glm::vec4(0, 0.2f, 0, 1));
  EXPECT_EQ(s.triangles[0].colours[2], glm::vec4(0, 0, 1, 128 / 255.0f));
  EXPECT_EQ(s.triangles[1].colours[2], glm::vec4(1, 1, 1, 0));
  EXPECT_TRUE(s.triangles[0].coloured());
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  // Floats, three components: alpha 1, and a value past 1 clamped.
  b.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = b.accessor({1.5f, 0.5f, 0, 0, 0, 0, 0, 0, 0, 0.25f, 0.25f, 0.25f}, "VEC3");
  const GltfScene f = parse(b.gltf());
  EXPECT_EQ(f.triangles[0].colours[0], glm::vec4(1, 0.5f, 0, 1));
  EXPECT_EQ(f.triangles[1].colours[2], glm::vec4(0.25f, 0.25f, 0.25f, 1));
  // None: white.
  b.doc["meshes"][0]["primitives"][0]["attributes"].erase("COLOR_0");
  EXPECT_FALSE(parse(b.gltf()).triangles[0].coloured());
  // Integers that are not normalized are not colours.
  b.doc["accessors"][bytes_accessor]["normalized"] = false;
  b.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = bytes_accessor;
  expect_error(b, "COLOR_0: accessors[" + std::to_string(bytes_accessor) + "]: integer components here must be normalized");
}

TEST(GltfTest, AMetallicRoughnessTextureIsLinearDataWhereTheSamePictureAsBaseColourIsSrgb) {
  // One grey picture, 128 of 255, used as both textures: as base colour it decodes from sRGB (0.216),
  // as metallic-roughness it is data (128 / 255), and the two are decoded once each.
  GltfBuilder b;
  const int picture = b.texture(test::png_bytes({1, 1, {128, 128, 128}}));
  b.quad(b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", picture}}},
                                               {"metallicRoughnessTexture", {{"index", picture}}}}}}));
  const GltfScene s = parse(b.gltf());
  ASSERT_EQ(s.materials.size(), 1u);
  const Material& m = s.materials[0];
  ASSERT_TRUE(m.albedo_texture.present());
  ASSERT_TRUE(m.metallic_roughness_texture.present());
  ASSERT_NE(m.albedo_texture.texture, m.metallic_roughness_texture.texture);
  ASSERT_EQ(s.textures.size(), 2u);
  EXPECT_NEAR(s.textures[size_t(m.albedo_texture.texture)]->texel(0, 0).g, 0.2158f, 1e-3f);
  EXPECT_NEAR(s.textures[size_t(m.metallic_roughness_texture.texture)]->texel(0, 0).g, 128.0f / 255.0f, 1e-3f);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
}

TEST(GltfTest, TextureTransformsMapTheTextureCoordinate) {
  // KHR_texture_transform: u' = sx u cos r + sy v sin r + ox, v' = sy v cos r - sx u sin r + oy
  // (the rotation counter-clockwise in the picture, as the extension's sample model shows it), and
  // its texCoord chooses the set.
  GltfBuilder b;
  const int picture = b.texture(test::png_bytes(test::four_colours()));
  b.quad(b.material({{"pbrMetallicRoughness",
                      {{"baseColorTexture", {{"index", picture},
                                             {"extensions", {{"KHR_texture_transform", {{"offset", {0.5, 0.25}},
                                                                                        {"rotation", 1.5707963267948966},
                                                                                        {"scale", {2, 3}}}}}}}},
                       {"metallicRoughnessTexture", {{"index", picture}, {"texCoord", 1},
                                                     {"extensions", {{"KHR_texture_transform", {{"texCoord", 0}}}}}}}}}}));
  b.doc["extensionsUsed"] = {"KHR_texture_transform"};
  const GltfScene s = parse(b.gltf());
  ASSERT_EQ(s.materials.size(), 1u);
  const TextureRef& t = s.materials[0].albedo_texture;
  EXPECT_TRUE(t.transformed());
  const glm::dvec2 mapped = t.map({0.1, 0.2});  // cos = 0, sin = 1: u' = 3 v + 0.5, v' = -2 u + 0.25
  EXPECT_NEAR(mapped.x, 3 * 0.2 + 0.5, 1e-6);
  EXPECT_NEAR(mapped.y, -2 * 0.1 + 0.25, 1e-6);
  EXPECT_FALSE(s.materials[0].metallic_roughness_texture.transformed());  // only texCoord: the identity
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];  // the texCoord sets agree: 0 for both
  {
    GltfBuilder bad = textured_quad();
    bad.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"]["scale"] = {1};
    expect_error(bad, "baseColorTexture.extensions.KHR_texture_transform.scale: expected an array of 2 numbers");
  }
  {
    GltfBuilder bad = textured_quad();
    bad.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"]["rotation"] = "half";
    expect_error(bad, "KHR_texture_transform.rotation: expected a number");
    // A whole number past 32 bits, which tinygltf would take round to 0.
    bad.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"]["rotation"] = 4294967296;
    expect_error(bad, "KHR_texture_transform.rotation: expected a number of at most 1e6 in magnitude");
  }
  {
    GltfBuilder bad = textured_quad();
    bad.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"]["texCoord"] = -1;
    expect_error(bad, "KHR_texture_transform.texCoord: expected a whole number");
  }
}

TEST(GltfTest, BrokenFilesNameTheElement) {
  EXPECT_NE(error_of([] { parse("{\"asset\": {\"version\": \"2.0\"},"); }).find("test.gltf:1:"), std::string::npos);
  {
    GltfBuilder b = textured_quad();
    b.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 17;
    expect_error(b, "meshes[0].primitives[0].attributes.POSITION: accessors[17] does not exist");
  }
  {
    GltfBuilder b = textured_quad();
    b.doc["accessors"][0]["count"] = 400;
    expect_error(b, "meshes[0].primitives[0].attributes.POSITION: accessors[0]: 400 elements from byte 0 run past the end of bufferViews[1]");
  }
  {
    GltfBuilder b = textured_quad();
    b.doc["bufferViews"][1]["byteOffset"] = 100000;
    expect_error(b, "bufferViews[1]: bytes 100000 + 48 run past the end of buffers[0]");
  }
  {
    GltfBuilder b = textured_quad();
    b.doc["meshes"][0]["primitives"][0]["indices"] = b.indices({0, 1, 9});
    expect_error(b, "meshes[0].primitives[0].indices: index 9 at 2 is out of range (POSITION has 4 vertices)");
  }
  {
    GltfBuilder b = textured_quad();
    b.doc["accessors"][0]["type"] = "VEC2";
    expect_error(b, "attributes.POSITION: accessors[0]: expected VEC3, got VEC2");
  }
  {
    GltfBuilder b = textured_quad();
    b.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["index"] = 3;
    expect_error(b, "materials[0].pbrMetallicRoughness.baseColorTexture.index: textures[3] does not exist (the file has 1)");
  }
  {
    GltfBuilder b;
    const int texture = b.texture(test::png_header_only(100000, 100000));
    b.quad(b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", texture}}}}}}));
    expect_error(b, "test.gltf: images[0]: a picture of 100000 x 100000 pixels");
  }
  {
    GltfBuilder b;
    b.quad();
    b.quad();
    b.doc["nodes"][0]["children"] = {1};
    b.doc["nodes"][1]["children"] = {0};
    expect_error(b, "scenes[0].nodes: nodes[0] is a child of another node, not a root");
    b.doc["nodes"][1].erase("children");  // 0 holds 1, and so does a new node 2
    b.doc["nodes"].push_back({{"children", {1}}});
    b.doc["scenes"][0]["nodes"] = {0, 2};
    expect_error(b, "nodes[2].children: nodes[1] has two parents (or is its own child)");
  }
  {
    GltfBuilder b = textured_quad();
    b.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    expect_error(b, "extensionsRequired: the file requires KHR_draco_mesh_compression, which vkray does not read");
  }
  {
    GltfBuilder b = textured_quad();
    b.doc["nodes"][0]["mesh"] = 5;
    expect_error(b, "nodes[0].mesh: meshes[5] does not exist");
  }
  {
    GltfBuilder b;  // no buffer of its own: the one below stands
    b.doc["buffers"] = {{{"byteLength", 0}}};
    const std::string empty = error_of([&] { parse_gltf(b.glb(), "empty.glb"); });
    EXPECT_NE(empty.find("empty.glb: buffers[0].byteLength: expected a whole number of bytes, at least 1"), std::string::npos) << empty;
  }
  {
    // A JSON chunk not padded to 4 bytes.
    std::string glb = textured_quad().glb();
    uint32_t json_length;
    std::memcpy(&json_length, glb.data() + 12, 4);
    json_length -= 1;
    std::memcpy(glb.data() + 12, &json_length, 4);
    const std::string unpadded = error_of([&] { parse_gltf(glb, "unpadded.glb"); });
    EXPECT_NE(unpadded.find("is not a multiple of 4"), std::string::npos) << unpadded;
  }
  // A .glb cut short: its header's length is past the end.
  std::string glb = textured_quad().glb();
  glb.resize(glb.size() - 10);
  const std::string cut = error_of([&] { parse_gltf(glb, "cut.glb"); });
  EXPECT_NE(cut.find("cut.glb: the header gives a length of"), std::string::npos) << cut;
}

// A value tinygltf would read as absent or as a default (a negative byteOffset as 0, an index of
// -1 or 1.5 as "none", 2^32 as 0, a string as the default) is refused, naming its place.
struct BadValue {
  const char* pointer;  // into the textured quad's document
  json value;
  const char* expected;  // in the message
};

TEST(GltfSchemaTest, AValueTinygltfWouldTakeForAbsentOrDefaultIsRefused) {
  const std::vector<BadValue> cases = {
      {"/accessors/0/byteOffset", -4, "accessors[0].byteOffset: expected a whole number of bytes, at least 0 and at most 2147483648, got -4"},
      {"/meshes/0/primitives/0/indices", -1, "meshes[0].primitives[0].indices: accessors[-1] does not exist (the file has 3)"},
      {"/meshes/0/primitives/0/indices", 1.5, "meshes[0].primitives[0].indices: expected an index into accessors, got 1.5"},
      {"/meshes/0/primitives/0/indices", "2", "meshes[0].primitives[0].indices: expected an index into accessors, got \"2\""},
      {"/meshes/0/primitives/0/attributes/POSITION", 4294967296, "attributes.POSITION: accessors[4294967296] does not exist"},
      {"/meshes/0/primitives/0/material", -1, "meshes[0].primitives[0].material: materials[-1] does not exist (the file has 1)"},
      {"/meshes/0/primitives/0/mode", 4.0, "meshes[0].primitives[0].mode: expected one of 0, 1, 2, 3, 4, 5, 6, got 4.0"},
      {"/meshes/0/primitives", json::object(), "meshes[0].primitives: expected an array of objects, got {}"},
      {"/nodes/0/mesh", 0.0, "nodes[0].mesh: expected an index into meshes, got 0.0"},
      {"/nodes/0/children", {0.5}, "nodes[0].children[0]: expected an index into nodes, got 0.5"},
      {"/scene", -1, "scene: scenes[-1] does not exist (the file has 1)"},
      {"/scenes/0/nodes/0", true, "scenes[0].nodes[0]: expected an index into nodes, got true"},
      {"/accessors/0/count", "4", "accessors[0].count: expected a whole number, at least 1 and at most 2147483648, got \"4\""},
      {"/accessors/0/count", 0, "accessors[0].count: expected a whole number, at least 1"},
      {"/accessors/0/componentType", 5124, "accessors[0].componentType: expected one of 5120, 5121, 5122, 5123, 5125, 5126, got 5124"},
      {"/accessors/0/normalized", "false", "accessors[0].normalized: expected true or false, got \"false\""},
      {"/accessors/0/sparse", {{"count", -2}}, "accessors[0].sparse.count: expected a whole number, at least 1 and at most 2147483647, got -2"},
      {"/bufferViews/1/byteStride", 6, "bufferViews[1].byteStride: expected a multiple of 4 from 4 to 252, got 6"},
      {"/bufferViews/1/byteLength", 48.0, "bufferViews[1].byteLength: expected a whole number of bytes, at least 1 and at most 2147483648, got 48.0"},
      {"/bufferViews/1/buffer", -1, "bufferViews[1].buffer: buffers[-1] does not exist (the file has 1)"},
      {"/bufferViews/1/target", 34961, "bufferViews[1].target: expected one of 34962, 34963, got 34961"},
      {"/materials/0/pbrMetallicRoughness/baseColorTexture/texCoord", -1, "baseColorTexture.texCoord: expected a whole number, at least 0"},
      {"/materials/0/pbrMetallicRoughness/baseColorTexture/index", 0.0, "baseColorTexture.index: expected an index into textures, got 0.0"},
      {"/materials/0/pbrMetallicRoughness/baseColorFactor/1", "1", "pbrMetallicRoughness.baseColorFactor: expected an array of 4 numbers"},
      {"/materials/0/pbrMetallicRoughness/metallicFactor", "0", "pbrMetallicRoughness.metallicFactor: expected a number, got \"0\""},
      {"/materials/0/alphaMode", "mask", "materials[0].alphaMode: expected one of \"OPAQUE\", \"MASK\", \"BLEND\", got \"mask\""},
      {"/materials/0/extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", "4"}}}}, "emissiveStrength: expected a number"},
      {"/samplers/0/magFilter", 9728.5, "samplers[0].magFilter: expected one of 9728, 9729, got 9728.5"},
      {"/samplers/0/wrapS", -1, "samplers[0].wrapS: expected one of 33071, 33648, 10497, got -1"},
      {"/textures/0/source", 7, "textures[0].source: images[7] does not exist (the file has 1)"},
      {"/textures/0/sampler", -1, "textures[0].sampler: samplers[-1] does not exist (the file has 1)"},
      {"/images/0/bufferView", -1, "images[0].bufferView: bufferViews[-1] does not exist"},
      {"/images/0/uri", "four.png", "images[0]: give a uri or a bufferView, not both"},
      {"/asset/version", "1.0", "asset.version: glTF 1.0; vkray reads glTF 2.0"},
      {"/extensionsUsed", {"KHR_lights_punctual", 3}, "extensionsUsed: expected an array of names"},
      {"/nodes/0/extensions", {{"KHR_lights_punctual", {{"light", 0}}}},
       "nodes[0].extensions.KHR_lights_punctual.light: KHR_lights_punctual.lights[0] does not exist (the file has 0)"},
      {"/cameras", {{{"type", "perspective"}, {"perspective", {{"yfov", "0.5"}, {"znear", 0.1}}}}}, "cameras[0].perspective.yfov: expected a number"},
      {"/skins", {{{"joints", {0, -1}}}}, "skins[0].joints[1]: nodes[-1] does not exist (the file has 1)"},
      {"/animations", {{{"channels", {{{"sampler", 1}, {"target", {{"node", 0}, {"path", "rotation"}}}}}}, {"samplers", {{{"input", 0}, {"output", 0}}}}}},
       "animations[0].channels[0].sampler: animations[0].samplers[1] does not exist (the file has 1)"},
  };
  for (const BadValue& c : cases) {
    SCOPED_TRACE(c.pointer);
    GltfBuilder b = textured_quad();
    b.doc[json::json_pointer(c.pointer)] = c.value;
    expect_error(b, c.expected);
    expect_error_in_glb(b, c.expected);
  }
  // tinygltf, as vkray, would take the matrix and ignore the scale.
  GltfBuilder b = textured_quad();
  b.doc["nodes"][0]["matrix"] = {2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1};
  b.doc["nodes"][0]["scale"] = {1, 1, 1};
  expect_error(b, "nodes[0]: a matrix and translation, rotation or scale together");
}

class GltfFileTest : public ::testing::Test {
 protected:
  test::TempDir dir_;
};

TEST_F(GltfFileTest, MissingBuffersAndPicturesNameTheirFile) {
  GltfBuilder b = textured_quad();
  json doc = json::parse(b.gltf());
  doc["buffers"][0]["uri"] = "missing.bin";
  test::write_file(dir_ / "a.gltf", doc.dump());
  const std::string buffer = error_of([&] { load_gltf(dir_ / "a.gltf"); });
  EXPECT_NE(buffer.find("a.gltf: "), std::string::npos) << buffer;
  EXPECT_NE(buffer.find("missing.bin"), std::string::npos) << buffer;

  doc = json::parse(b.gltf());
  doc["images"][0] = {{"uri", "pictures/four%20colours.png"}};
  test::write_file(dir_ / "b.gltf", doc.dump());
  const std::string picture = error_of([&] { load_gltf(dir_ / "b.gltf"); });
  EXPECT_NE(picture.find("images[0] (pictures/four%20colours.png): picture file not found"), std::string::npos) << picture;
  std::filesystem::create_directories(dir_ / "pictures");
  test::write_file(dir_ / "pictures/four colours.png", test::png_bytes(test::four_colours()));
  const GltfScene s = load_gltf(dir_ / "b.gltf");
  EXPECT_EQ(s.textures.size(), 1u);
  ASSERT_EQ(s.files.size(), 1u);
  EXPECT_EQ(s.files[0], dir_ / "pictures/four colours.png");
}

// The textured quad as a .gltf whose buffer is a file (`buffer_uri`, holding the buffer's bytes
// when `bin` is given), its picture in a buffer view; `edit` may change the document first.
std::filesystem::path write_with_buffer_file(const std::filesystem::path& gltf, const std::string& buffer_uri, const std::string& bin_name,
                                             const std::function<void(json&)>& edit = nullptr) {
  const GltfBuilder b = textured_quad();
  json doc = json::parse(b.gltf());
  doc["buffers"][0]["uri"] = buffer_uri;
  if (!bin_name.empty()) test::write_file(gltf.parent_path() / bin_name, b.bin);
  if (edit) edit(doc);
  test::write_file(gltf, doc.dump());
  return gltf;
}

TEST_F(GltfFileTest, AUriNamesTheFileItSaysOrIsRefused) {
  test::write_file(dir_ / "four.png", test::png_bytes(test::four_colours()));
  std::filesystem::create_directories(dir_ / "pictures");
  test::write_file(dir_ / "pictures/four.png", test::png_bytes(test::four_colours()));
  const auto picture_error = [&](const std::string& uri) {
    write_with_buffer_file(dir_ / "a.gltf", "quad.bin", "quad.bin", [&](json& doc) { doc["images"][0] = {{"uri", uri}}; });
    return error_of([&] { load_gltf(dir_ / "a.gltf"); });
  };
  // Each of these once read a file (four.png, pictures/four.png) that the uri does not name.
  EXPECT_NE(picture_error("four.png%00.jpg").find("a.gltf: images[0].uri: \"four.png%00.jpg\": %00 is a NUL character"), std::string::npos);
  EXPECT_NE(picture_error(std::string("four.png\0.jpg", 13)).find("images[0].uri: \"four.png?.jpg\" holds a NUL character"), std::string::npos);
  EXPECT_NE(picture_error("pictures%2Ffour.png").find("images[0].uri: \"pictures%2Ffour.png\": %2F is an escaped separator"), std::string::npos);
  EXPECT_NE(picture_error("pictures%5cfour.png").find("%5c is an escaped separator"), std::string::npos);
  // Neither a broken escape, nor a scheme or host vkray does not read.
  EXPECT_NE(picture_error("four%2.png").find("images[0].uri: \"four%2.png\": a '%' not followed by two hexadecimal digits"), std::string::npos);
  EXPECT_NE(picture_error("http://example.com/four.png").find("images[0].uri: http: URIs are not read"), std::string::npos);
  EXPECT_NE(picture_error("//example.com/four.png").find("names a host"), std::string::npos);
  EXPECT_NE(picture_error("data:image/png,%89PNG").find("images[0].uri: a data: URI that is not base64"), std::string::npos);
  EXPECT_NE(picture_error("data:image/png;base64,iVBO*w0K").find("a data: URI whose data is not base64"), std::string::npos);
  // A buffer's uri, too, before any file is read: the NUL once read quad.bin.
  write_with_buffer_file(dir_ / "b.gltf", "quad.bin%00.txt", "quad.bin");
  const std::string nul = error_of([&] { load_gltf(dir_ / "b.gltf"); });
  EXPECT_NE(nul.find("b.gltf: buffers[0].uri: \"quad.bin%00.txt\": %00 is a NUL character"), std::string::npos) << nul;
  write_with_buffer_file(dir_ / "b.gltf", "short.bin", "", [&](json&) { test::write_file(dir_ / "short.bin", "12345678"); });
  const std::string size = error_of([&] { load_gltf(dir_ / "b.gltf"); });
  EXPECT_NE(size.find("b.gltf: buffers[0] (short.bin): it holds 8 bytes, and byteLength says"), std::string::npos) << size;
}

TEST_F(GltfFileTest, EscapesAreDecodedOnceByRfc3986AndOnlyTheFileBesideIsRead) {
  // A '+' is a '+' (tinygltf read it as a space, as a web form does): "a+b.bin" is read, not "a b.bin".
  const GltfBuilder b = textured_quad();
  std::string other = b.bin;
  std::memset(other.data() + b.doc["bufferViews"][1]["byteOffset"].get<size_t>(), 0, 48);  // its POSITIONs all zero
  test::write_file(dir_ / "a b.bin", other);
  write_with_buffer_file(dir_ / "plus.gltf", "a+b.bin", "a+b.bin");
  const GltfScene plus = load_gltf(dir_ / "plus.gltf");
  ASSERT_EQ(plus.triangles.size(), 2u);
  EXPECT_EQ(plus.triangles[0].v[2], glm::vec3(1, 1, 0));
  ASSERT_FALSE(plus.files.empty());
  EXPECT_EQ(plus.files[0], dir_ / "a+b.bin");
  // "%20" is a space.
  write_with_buffer_file(dir_ / "space.gltf", "a%20b.bin", "");
  const GltfScene space = load_gltf(dir_ / "space.gltf");
  ASSERT_EQ(space.triangles.size(), 2u);
  EXPECT_EQ(space.triangles[0].v[2], glm::vec3(0, 0, 0));  // "a b.bin", whose POSITIONs are zero
  // A buffer missing beside the file is not looked for in the working directory.
  std::filesystem::create_directories(dir_ / "model");
  write_with_buffer_file(dir_ / "model/m.gltf", "only-in-cwd.bin", "");
  test::write_file(dir_ / "only-in-cwd.bin", b.bin);
  const std::filesystem::path cwd = std::filesystem::current_path();
  std::filesystem::current_path(dir_.path());
  const std::string missing = error_of([&] { load_gltf(dir_ / "model/m.gltf"); });
  std::filesystem::current_path(cwd);
  EXPECT_NE(missing.find("m.gltf: buffers[0] (only-in-cwd.bin): buffer file not found"), std::string::npos) << missing;
}

TEST_F(GltfFileTest, PathsMayLeaveTheFolderAndDataUrisOfAnyTypeAreRead) {
  // As a scene file's paths: "..", a subfolder, or an absolute path, resolved from the file's folder.
  const GltfBuilder b = textured_quad();
  test::write_file(dir_ / "quad.bin", b.bin);
  test::write_file(dir_ / "four.png", test::png_bytes(test::four_colours()));
  std::filesystem::create_directories(dir_ / "model");
  write_with_buffer_file(dir_ / "model/up.gltf", "../quad.bin", "", [&](json& doc) { doc["images"][0] = {{"uri", (dir_ / "four.png").string()}}; });
  const GltfScene up = load_gltf(dir_ / "model/up.gltf");
  EXPECT_EQ(up.textures.size(), 1u);
  EXPECT_EQ(up.files, (std::vector<std::filesystem::path>{dir_ / "quad.bin", dir_ / "four.png"}));
  // data: URIs whose type tinygltf does not know (image/jpg, a made-up buffer type) are read all the same.
  const auto base64_of = [](const std::string& bytes) {
    GltfBuilder holder;  // its buffer, as the data: URI gltf() writes
    holder.bin = bytes;
    return json::parse(holder.gltf())["buffers"][0]["uri"].get<std::string>().substr(std::strlen("data:application/octet-stream;base64,"));
  };
  json doc = json::parse(b.gltf());
  doc["buffers"][0]["uri"] = "data:application/x-vkray-test;base64," + base64_of(b.bin);
  doc["images"][0] = {{"uri", "DATA:image/jpg;base64," + base64_of(test::png_bytes(test::four_colours()))}};
  const GltfScene data = parse_gltf(doc.dump(), dir_ / "data.gltf");
  EXPECT_EQ(data.textures.size(), 1u);
  EXPECT_EQ(data.triangles.size(), 2u);
  EXPECT_TRUE(data.files.empty());
  // A data: URI holding other than byteLength bytes.
  doc["buffers"][0]["byteLength"] = b.bin.size() + 4;
  const std::string length = error_of([&] { parse_gltf(doc.dump(), dir_ / "data.gltf"); });
  EXPECT_NE(length.find("buffers[0]: its data: URI holds " + std::to_string(b.bin.size()) + " bytes, and byteLength says"), std::string::npos) << length;
}

// A .glb file's bytes with its JSON chunk replaced by `doc`.
std::string with_json(const std::string& glb, const json& doc) {
  uint32_t json_length;
  std::memcpy(&json_length, glb.data() + 12, 4);
  std::string text = doc.dump();
  while (text.size() % 4) text += ' ';
  std::string out = glb.substr(0, 12);
  const auto u32 = [&](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  u32(uint32_t(text.size()));
  u32(0x4E4F534Au);
  out += text + glb.substr(20 + json_length);
  const auto total = uint32_t(out.size());
  std::memcpy(out.data() + 8, &total, 4);
  return out;
}

TEST(GltfTest, ABufferWithoutAUriIsOnlyAGlbFilesBinaryChunk) {
  // tinygltf gave every buffer without a uri the binary chunk.
  const GltfBuilder b = textured_quad();
  json doc = json::parse(b.gltf());
  doc["buffers"].push_back({{"byteLength", 4}});
  doc["bufferViews"].push_back({{"buffer", 1}, {"byteLength", 4}});
  doc["buffers"][0].erase("uri");
  const std::string glb = with_json(b.glb(), doc);
  const std::string second = error_of([&] { parse_gltf(glb, "two.glb"); });
  EXPECT_NE(second.find("two.glb: buffers[1]: no uri: only buffers[0] of a .glb file is its binary chunk"), std::string::npos) << second;
  const std::string gltf = error_of([&] { parse_gltf(doc.dump(), "two.gltf"); });
  EXPECT_NE(gltf.find("two.gltf: buffers[0]: no uri: a .gltf file's buffers are files or data: URIs"), std::string::npos) << gltf;
}

TEST_F(GltfFileTest, AnObjectOfAVkraySceneIsPlacedByItsTransform) {
  test::write_file(dir_ / "quad.glb", textured_quad().glb());
  test::write_file(dir_ / "scene.json", R"({
    "camera": {"position": [0, 0, 10], "look_at": [0, 0, 0], "vertical_fov": 40},
    "lights": [{"type": "point", "position": [0, 0, 10], "intensity": [50, 50, 50]}],
    "materials": {"grey": {"albedo": [0.5, 0.5, 0.5]}},
    "objects": [{"type": "sphere", "center": [0, 0, -5], "radius": 1, "material": "grey"},
                {"type": "gltf", "file": "quad.glb", "transform": {"translate": [3, 0, 0], "scale": 2}},
                {"type": "gltf", "file": "quad.glb", "transform": {"translate": [-3, 0, 0], "rotate": [0, 30, 0]}}]})");
  const Scene s = load_scene(dir_ / "scene.json");
  ASSERT_EQ(s.triangles.size(), 4u);
  EXPECT_EQ(s.materials.size(), 2u);  // the file placed twice, its material and texture the scene's once
  EXPECT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.triangles[2].material, 1u);
  EXPECT_EQ(s.triangles[2].object, 2u);
  EXPECT_EQ(s.triangles[0].material, 1u);
  EXPECT_EQ(s.triangles[0].object, 1u);
  EXPECT_EQ(s.materials[1].albedo_texture.texture, 0);
  EXPECT_EQ(s.triangles[0].v[2], glm::vec3(5, 2, 0));

  test::write_file(dir_ / "bad.json", R"({"camera": {"position": [0, 0, 10], "look_at": [0, 0, 0], "vertical_fov": 40},
    "objects": [{"type": "gltf", "file": "nothing.glb"}]})");
  const std::string missing = error_of([&] { load_scene(dir_ / "bad.json"); });
  EXPECT_NE(missing.find("bad.json: /objects/0/file: "), std::string::npos) << missing;
  EXPECT_NE(missing.find("nothing.glb: glTF file not found"), std::string::npos) << missing;
}

// "instances": an object placed once for each transform in the list, each then placed by the
// object's own "transform"; a mesh file and a glTF file alike, each read once.
TEST_F(GltfFileTest, AnObjectIsPlacedOnceForEachOfItsInstances) {
  test::write_file(dir_ / "quad.glb", textured_quad().glb());
  test::write_file(dir_ / "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  test::write_file(dir_ / "field.json", R"({"camera": {"position": [0, 0, 10], "look_at": [0, 0, 0], "vertical_fov": 40},
    "materials": {"m": {"albedo": [1, 1, 1]}},
    "objects": [{"type": "gltf", "file": "quad.glb", "transform": {"translate": [0, 0, 1]},
                 "instances": [{"translate": [0, 0, 0]}, {"translate": [5, 0, 0]}, {"scale": 2, "translate": [0, 5, 0]}]},
                {"type": "mesh", "file": "tri.obj", "material": "m", "transform": {"scale": 3},
                 "instances": [{"translate": [1, 0, 0]}, {"matrix": [0, -1, 0, 0,  1, 0, 0, 0,  0, 0, 1, 0,  0, 0, 0, 1]},
                               {"scale": [-1, 1, 1]}]}]})");
  const Scene s = load_scene(dir_ / "field.json");
  // Each object's triangles stored once, as a mesh, and placed by an instance each time.
  ASSERT_EQ(s.meshes.size(), 2u);
  ASSERT_EQ(s.instances.size(), 6u);
  EXPECT_TRUE(s.triangles.empty());
  EXPECT_EQ(s.meshes[0].triangles.size(), 2u);
  const auto placed = [&](size_t instance, size_t t) {
    return placed_triangle(s.meshes[s.instances[instance].mesh].triangles[t], glm::dmat4(s.instances[instance].to_world));
  };
  // The mirrored placement keeps the triangle's front toward +z, as a glTF file's mirror does.
  const Triangle mirrored = placed(5, 0);
  EXPECT_GT(glm::cross(mirrored.v[1] - mirrored.v[0], mirrored.v[2] - mirrored.v[0]).z, 0.0f);
  EXPECT_EQ(mirrored.v[2], glm::vec3(-3, 0, 0));
  EXPECT_EQ(s.textures.size(), 1u);  // the file read once
  EXPECT_EQ(placed(1, 0).v[2], glm::vec3(6, 1, 1));  // quad corner (1, 1, 0), moved by 5 in x, then 1 in z
  EXPECT_EQ(placed(2, 0).v[2], glm::vec3(2, 7, 1));  // scaled by 2 and moved by 5 in y first
  EXPECT_EQ(placed(3, 0).v[1], glm::vec3(6, 0, 0));  // (1, 0, 0) moved by 1, then scaled by 3
  EXPECT_EQ(placed(4, 0).v[1], glm::vec3(0, 3, 0));  // (1, 0, 0) turned to (0, 1, 0), then scaled
  for (size_t i = 0; i < s.instances.size(); ++i) EXPECT_EQ(s.instances[i].object, i < 3 ? 0u : 1u);

  // A warning about the mesh is said once, not once per placement.
  test::write_file(dir_ / "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n");
  test::write_file(dir_ / "flat.json", R"({"camera": {"position": [0, 0, 10], "look_at": [0, 0, 0], "vertical_fov": 40},
    "materials": {"m": {"albedo": [1, 1, 1]}},
    "objects": [{"type": "mesh", "file": "flat.obj", "material": "m", "instances": [{"translate": [0, 0, 0]}, {"translate": [5, 0, 0]}]}]})");
  const Scene flat = load_scene(dir_ / "flat.json");
  ASSERT_EQ(flat.meshes.size(), 1u);
  EXPECT_EQ(flat.meshes[0].triangles.size(), 1u);
  EXPECT_EQ(flat.instances.size(), 2u);
  EXPECT_EQ(std::count_if(flat.warnings.begin(), flat.warnings.end(),
                          [](const std::string& w) { return w.find("1 degenerate (zero-area) triangles left out") != std::string::npos; }),
            1);

  test::write_file(dir_ / "bad.json", R"({"camera": {"position": [0, 0, 10], "look_at": [0, 0, 0], "vertical_fov": 40},
    "objects": [{"type": "gltf", "file": "quad.glb", "instances": []}]})");
  const std::string empty = error_of([&] { load_scene(dir_ / "bad.json"); });
  EXPECT_NE(empty.find("bad.json: /objects/0/instances: expected at least one transform"), std::string::npos) << empty;
  test::write_file(dir_ / "bad.json", R"({"camera": {"position": [0, 0, 10], "look_at": [0, 0, 0], "vertical_fov": 40},
    "objects": [{"type": "gltf", "file": "quad.glb", "instances": [{"translate": [0, 0, 0]}, {"scale": 0}]}]})");
  const std::string zero = error_of([&] { load_scene(dir_ / "bad.json"); });
  EXPECT_NE(zero.find("bad.json: /objects/0/instances/1/scale: "), std::string::npos) << zero;
}

TEST_F(GltfFileTest, TheFileAsAWholeSceneGetsACameraAndLight) {
  GltfBuilder b = textured_quad();
  test::write_file(dir_ / "quad.glb", b.glb());
  const Scene framed = load_scene(dir_ / "quad.glb");
  EXPECT_EQ(framed.triangles.size(), 2u);
  EXPECT_GT(framed.camera.position.z, 2.0f);  // in front of the quad, looking at it
  EXPECT_LT(framed.camera.forward.z, -0.9f);
  ASSERT_EQ(framed.lights.size(), 1u);  // the file brings no light: one at the camera
  EXPECT_EQ(framed.lights[0].position, framed.camera.position);
  std::string all;
  for (const auto& w : framed.warnings) all += w + "\n";
  EXPECT_NE(all.find("no perspective camera"), std::string::npos) << all;
  EXPECT_NE(all.find("the file brings no light (emissive surfaces do not count): vkray adds a point light at the camera"),
            std::string::npos) << all;

  b.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.6}, {"znear", 0.1}, {"aspectRatio", 1.5}}}}};
  b.doc["nodes"].push_back({{"camera", 0}, {"translation", {0, 0, 4}}});
  b.doc["scenes"][0]["nodes"].push_back(1);
  b.doc["materials"][0]["emissiveFactor"] = {1, 1, 1};
  test::write_file(dir_ / "lit.gltf", b.gltf());
  const Scene lit = load_scene(dir_ / "lit.gltf");
  EXPECT_EQ(lit.camera.position, glm::vec3(0, 0, 4));
  EXPECT_EQ(lit.image.width, 768u);  // 512 high, 1.5 wide
  EXPECT_EQ(lit.image.height, 512u);
  EXPECT_EQ(lit.lights.size(), 1u);  // emission does not count: the light at the camera is added

  // A point light of its own: none added.
  b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}, {"intensity", 5}}};
  b.doc["nodes"].push_back({{"translation", {0, 2, 2}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  b.doc["scenes"][0]["nodes"].push_back(2);
  test::write_file(dir_ / "lamp.gltf", b.gltf());
  const Scene lamp = load_scene(dir_ / "lamp.gltf");
  ASSERT_EQ(lamp.lights.size(), 1u);
  EXPECT_EQ(lamp.lights[0].position, glm::vec3(0, 2, 2));
  for (const auto& w : lamp.warnings) EXPECT_EQ(w.find("brings no light"), std::string::npos) << w;
}

// The shipped Khronos models: what each file holds, as their READMEs describe them.
TEST(ShippedGltfTest, KhronosModelsLoadAsDescribed) {
  const std::filesystem::path dir = std::filesystem::path(VKRAY_SCENE_DIR) / "gltf";
  for (const char* form : {"BoxTextured/glTF/BoxTextured.gltf", "BoxTextured/glTF-Binary/BoxTextured.glb",
                           "BoxTextured/glTF-Embedded/BoxTextured.gltf"}) {
    const GltfScene box = load_gltf(dir / form);
    EXPECT_EQ(box.triangles.size(), 12u) << form;
    ASSERT_EQ(box.textures.size(), 1u) << form;
    EXPECT_EQ(box.textures[0]->width, box.textures[0]->height) << form;  // the square Cesium logo
    // The root's matrix turns the box from z-up to y-up: a unit cube either way.
    for (const Triangle& t : box.triangles)
      for (const glm::vec3& v : t.v) EXPECT_NEAR(std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}), 0.5f, 1e-6f) << form;
  }
  // The lamp brings its five lights (one in its shade, whose paper lets light through), so vkray adds none.
  const Scene lamp = load_scene(dir / "LightsPunctualLamp/glTF/LightsPunctualLamp.gltf");
  EXPECT_EQ(lamp.lights.size(), 5u);
  EXPECT_EQ(lamp.lights[0].intensity, glm::vec3(15.0f, float(0.6318749785423279 * 15), float(0.23909975588321689 * 15)));
  const GltfScene truck = load_gltf(dir / "CesiumMilkTruck/glTF/CesiumMilkTruck.gltf");
  EXPECT_EQ(truck.materials.size(), 4u);
  ASSERT_EQ(truck.textures.size(), 1u);  // the progressive JPEG
  EXPECT_EQ(truck.textures[0]->width, 2048u);
  const GltfScene settings = load_gltf(dir / "TextureSettingsTest/glTF/TextureSettingsTest.gltf");
  std::set<std::pair<TextureWrap, TextureWrap>> wraps;
  for (const Material& m : settings.materials)
    if (m.albedo_texture.present()) wraps.insert({m.albedo_texture.wrap_s, m.albedo_texture.wrap_t});
  EXPECT_GE(wraps.size(), 4u);  // clamp, repeat and mirror, per axis
  // Transmission Test: twelve spheres, each with KHR_materials_transmission at factor 1, half of them
  // with the transmission texture; nothing warned of (its KHR_xmp is metadata).
  const GltfScene transmission = load_gltf(dir / "TransmissionTest/glTF-Binary/TransmissionTest.glb");
  int transmitting = 0, textured = 0;
  for (const Material& m : transmission.materials) {
    transmitting += m.transmission == 1.0f;
    textured += m.transmission_texture.present();
  }
  EXPECT_EQ(transmitting, 12);
  EXPECT_EQ(textured, 6);
  EXPECT_TRUE(transmission.warnings.empty()) << transmission.warnings[0];
  const GltfScene cameras = load_gltf(dir / "Cameras/glTF/Cameras.gltf");
  ASSERT_TRUE(cameras.camera);  // the perspective one
  EXPECT_NEAR(cameras.camera->focal_length, 0.5f / std::tan(0.35f), 1e-5f);  // yfov 0.7
  // The models of glTF's rarer features: each read whole, with nothing warned of but what is not
  // rendered (SimpleMorph's animation).
  const GltfScene instancing = load_gltf(dir / "SimpleInstancing/glTF-Binary/SimpleInstancing.glb");
  ASSERT_EQ(instancing.meshes.size(), 1u);  // 125 cubes of one mesh, stored once
  EXPECT_EQ(instancing.meshes[0].triangles.size(), 12u);
  EXPECT_EQ(instancing.instances.size(), 125u);
  EXPECT_TRUE(instancing.warnings.empty()) << instancing.warnings[0];
  const GltfScene sparse = load_gltf(dir / "SimpleSparseAccessor/glTF-Embedded/SimpleSparseAccessor.gltf");
  float top = 0;
  for (const Triangle& t : sparse.triangles)
    for (const glm::vec3& v : t.v) top = std::max(top, v.y);
  EXPECT_EQ(top, 4.0f);  // the highest substituted vertex, (5, 4, 0)
  EXPECT_TRUE(sparse.warnings.empty()) << sparse.warnings[0];
  const GltfScene morph = load_gltf(dir / "SimpleMorph/glTF-Embedded/SimpleMorph.gltf");
  ASSERT_EQ(morph.triangles.size(), 1u);
  // The mesh's weights 0.5 and 0.5: the apex (0.5, 0.5, 0) moved by half of each target's (0, 1, 0).
  const std::array<glm::vec3, 3>& v = morph.triangles[0].v;
  EXPECT_TRUE(std::find(v.begin(), v.end(), glm::vec3(0.5f, 1.5f, 0.0f)) != v.end()) << v[0].y << " " << v[1].y << " " << v[2].y;
  ASSERT_EQ(morph.warnings.size(), 1u);
  EXPECT_NE(morph.warnings[0].find("animations are not played"), std::string::npos) << morph.warnings[0];
  const GltfScene unlit = load_gltf(dir / "UnlitTest/glTF-Binary/UnlitTest.glb");
  ASSERT_EQ(unlit.materials.size(), 2u);
  for (const Material& m : unlit.materials) EXPECT_TRUE(m.vertex_colours_emit && m.albedo == glm::vec3(0.0f) && m.emissive());
  const GltfScene colours = load_gltf(dir / "VertexColorTest/glTF-Binary/VertexColorTest.glb");
  EXPECT_TRUE(std::any_of(colours.triangles.begin(), colours.triangles.end(), [](const Triangle& t) { return t.coloured(); }));
  EXPECT_TRUE(colours.warnings.empty()) << colours.warnings[0];
  const GltfScene uv = load_gltf(dir / "MultiUVTest/glTF-Binary/MultiUVTest.glb");
  ASSERT_FALSE(uv.materials.empty());
  EXPECT_NE(uv.materials[0].albedo_texture.texcoord, uv.materials[0].emission_texture.texcoord);
  EXPECT_TRUE(uv.warnings.empty()) << uv.warnings[0];
}

}  // namespace
}  // namespace vkray
