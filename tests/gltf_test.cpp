// glTF 2.0 files: what each part of a file becomes in a scene (meshes through the node hierarchy,
// materials and textures, the camera, lights), both ways in (an object of a vkray scene, the file as
// the scene), and every way a file can be wrong.
#include <cstring>
#include <set>

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

TEST(GltfTest, TheFirstCameraDepthFirstAndPointLights) {
  GltfBuilder b;
  b.quad();
  b.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}, {"aspectRatio", 2.0}}}},
                      {{"type", "perspective"}, {"perspective", {{"yfov", 1.0}, {"znear", 0.1}}}}};
  b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}, {"color", {1, 0.5, 0}}, {"intensity", 4}},
                                                           {{"type", "spot"}, {"spot", json::object()}}};
  // Root 1 holds camera 1 deep inside; root 2 holds camera 0: depth-first, camera 1 comes first.
  b.doc["nodes"].push_back({{"children", {2}}});
  b.doc["nodes"].push_back({{"camera", 1}, {"translation", {0, 0, 3}}});
  b.doc["nodes"].push_back({{"camera", 0}});
  b.doc["nodes"].push_back({{"translation", {0, 4, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  b.doc["nodes"].push_back({{"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  b.doc["scenes"][0]["nodes"] = {0, 1, 3, 4, 5};
  const GltfScene s = parse(b.gltf());
  ASSERT_TRUE(s.camera);
  EXPECT_EQ(s.camera->position, glm::vec3(0, 0, 3));
  EXPECT_EQ(s.camera->forward, glm::vec3(0, 0, -1));
  EXPECT_NEAR(s.camera->focal_length, 0.5f / std::tan(0.5f), 1e-6f);
  EXPECT_EQ(s.aspect_ratio, 0.0f);  // camera 1 gives none
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].position, glm::vec3(0, 4, 0));
  EXPECT_EQ(s.lights[0].intensity, glm::vec3(4, 2, 0));
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("spot lights are not rendered"), std::string::npos) << s.warnings[0];
}

TEST(GltfTest, MaterialsKeepTheirColourAndEmissionAndNameWhatIsNotRendered) {
  GltfBuilder b;
  const int texture = b.texture(test::jpeg_bytes(test::four_colours()));
  const int lamp = b.material({{"emissiveFactor", {1, 0.5, 0.25}},
                               {"emissiveTexture", {{"index", texture}}},
                               {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4}}}}}});
  const int metal = b.material({{"pbrMetallicRoughness", {{"baseColorFactor", {0.2, 0.3, 0.4, 0.5}}, {"metallicFactor", 1}}},
                                {"alphaMode", "MASK"}, {"normalTexture", {{"index", texture}}}});
  b.quad(lamp);
  b.quad(metal);
  b.quad(metal);
  const GltfScene s = parse(b.gltf());
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_EQ(s.materials[0].emission, glm::vec3(4, 2, 1));
  EXPECT_TRUE(s.materials[0].emission_texture.present());
  EXPECT_EQ(s.materials[1].albedo, glm::vec3(0.2f, 0.3f, 0.4f));
  EXPECT_EQ(s.materials[1].type, MaterialType::diffuse);
  EXPECT_EQ(s.triangles.size(), 6u);
  std::string all;
  for (const auto& w : s.warnings) all += w + "\n";
  EXPECT_EQ(s.warnings.size(), 3u) << all;  // once each, though two quads use the material
  EXPECT_NE(all.find("materials[0]: metalness and roughness are not rendered"), std::string::npos) << all;
  EXPECT_NE(all.find("alphaMode MASK is not rendered"), std::string::npos) << all;
  EXPECT_NE(all.find("normal textures are not rendered"), std::string::npos) << all;
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
    expect_error(b, "materials[0].pbrMetallicRoughness.baseColorTexture: textures[3] does not exist");
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
  EXPECT_NE(all.find("the file brings no light: vkray adds a point light at the camera"), std::string::npos) << all;

  b.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.6}, {"znear", 0.1}, {"aspectRatio", 1.5}}}}};
  b.doc["nodes"].push_back({{"camera", 0}, {"translation", {0, 0, 4}}});
  b.doc["scenes"][0]["nodes"].push_back(1);
  b.doc["materials"][0]["emissiveFactor"] = {1, 1, 1};
  test::write_file(dir_ / "lit.gltf", b.gltf());
  const Scene lit = load_scene(dir_ / "lit.gltf");
  EXPECT_EQ(lit.camera.position, glm::vec3(0, 0, 4));
  EXPECT_EQ(lit.image.width, 768u);  // 512 high, 1.5 wide
  EXPECT_EQ(lit.image.height, 512u);
  EXPECT_TRUE(lit.lights.empty());  // it emits: no light added
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
  const GltfScene truck = load_gltf(dir / "CesiumMilkTruck/glTF/CesiumMilkTruck.gltf");
  EXPECT_EQ(truck.materials.size(), 4u);
  ASSERT_EQ(truck.textures.size(), 1u);  // the progressive JPEG
  EXPECT_EQ(truck.textures[0]->width, 2048u);
  const GltfScene settings = load_gltf(dir / "TextureSettingsTest/glTF/TextureSettingsTest.gltf");
  std::set<std::pair<TextureWrap, TextureWrap>> wraps;
  for (const Material& m : settings.materials)
    if (m.albedo_texture.present()) wraps.insert({m.albedo_texture.wrap_s, m.albedo_texture.wrap_t});
  EXPECT_GE(wraps.size(), 4u);  // clamp, repeat and mirror, per axis
  const GltfScene cameras = load_gltf(dir / "Cameras/glTF/Cameras.gltf");
  ASSERT_TRUE(cameras.camera);  // the perspective one
  EXPECT_NEAR(cameras.camera->focal_length, 0.5f / std::tan(0.35f), 1e-5f);  // yfov 0.7
}

}  // namespace
}  // namespace vkray
