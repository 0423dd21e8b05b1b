#include "load/scene_parser.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>

#include "base/grow.h"
#include "base/input_file.h"
#include "base/interrupt.h"
#include "mesh/normals.h"
#include "scene/transform.h"

namespace vkray::scene_file {

SceneParser::LoadedGltf& SceneParser::gltf_file(const Value* where, const std::filesystem::path& file) {
  // A file placed several times is read once: its materials and textures are the scene's once, and
  // its warnings said once.
  auto loaded = gltf_files_.find(file);
  if (loaded == gltf_files_.end()) {
    LoadedGltf entry;
    GltfLimits limits;
    limits.max_texels = kMaxSceneTexels - std::min(kMaxSceneTexels, scene_texels_);
    try {
      entry.gltf = load_gltf(file, limits);
    } catch (const LimitError& e) {
      if (!where) throw;
      throw LimitError(file_.string() + ": " + where->path + ": " + e.what());
    } catch (const SceneError& e) {
      if (!where) throw;
      throw SceneError(file_.string() + ": " + where->path + ": " + e.what());
    }
    reference(file);
    for (const auto& f : entry.gltf.files) reference(f);
    for (const std::string& w : entry.gltf.warnings) {
      if (where) warn(*where, w);
      else scene_.warnings.push_back(w);
    }
    entry.material_offset = uint32_t(scene_.materials.size());
    const auto texture_offset = int32_t(scene_.textures.size());
    for (Material m : entry.gltf.materials) {
      for (TextureRef* ref : m.textures())
        if (ref->present()) ref->texture += texture_offset;
      scene_.materials.push_back(std::move(m));
    }
    for (const auto& t : entry.gltf.textures) add_texture(t);
    loaded = gltf_files_.emplace(file, std::move(entry)).first;
  }
  return loaded->second;
}

std::pair<std::optional<Camera>, float> SceneParser::add_gltf(const Value* where, const std::filesystem::path& file,
                                                              const glm::mat4& transform) {
  const LoadedGltf& loaded = gltf_file(where, file);
  const GltfScene& gltf = loaded.gltf;
  const uint32_t material_offset = loaded.material_offset;
  static const json kNothing;
  const Value root{kNothing, ""};  // where messages point when the file is the scene itself
  const Value& at = where ? *where : root;
  // The object's transform on top of the file's own: normals by the inverse transpose, tangents (the
  // file's TANGENT) as directions along the surface, and the winding, with the tangents' sign, turned
  // around where it mirrors.
  const glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(transform)));
  const bool mirrors = glm::determinant(glm::mat3(transform)) < 0.0f;
  const bool moved = transform != glm::mat4(1.0f);
  std::vector<Triangle> placed = gltf.triangles;
  for (Triangle& t : placed) {
    t.material += material_offset;
    t.object = object_;
    if (!moved) continue;
    const bool tangents = t.has_tangents();
    for (size_t k = 0; k < 3; ++k) {
      t.v[k] = transform_point(transform, t.v[k]);
      if (t.smooth) t.normals[k] = glm::normalize(normal_matrix * t.normals[k]);
      if (tangents) {
        const glm::vec3 tangent = glm::mat3(transform) * glm::vec3(t.tangents[k]);
        const float length = glm::length(tangent);
        t.tangents[k] = length > 0.0f && std::isfinite(length) ? glm::vec4(tangent / length, mirrors ? -t.tangents[k].w : t.tangents[k].w)
                                                               : glm::vec4(0.0f);
      }
    }
    if (!std::all_of(t.tangents.begin(), t.tangents.end(), [](const glm::vec4& corner) { return corner.w != 0.0f; })) t.tangents = {};
    if (t.smooth && !std::all_of(t.normals.begin(), t.normals.end(), [](const glm::vec3& n) { return std::isfinite(n.x) && glm::length(n) > 0.5f; }))
      t.smooth = false;
    if (mirrors) t.swap_corners();
  }
  add_triangles(at, placed);
  add_gltf_meshes(at, loaded, {transform});
  add_gltf_lights(at, gltf, transform);
  std::optional<Camera> camera = gltf.camera;
  if (camera && moved) {
    camera->position = transform_point(transform, camera->position);
    camera->forward = glm::normalize(glm::mat3(transform) * camera->forward);
    camera->up = glm::normalize(glm::mat3(transform) * camera->up);
  }
  return {camera, gltf.aspect_ratio};
}

void SceneParser::add_gltf_lights(const Value& where, const GltfScene& gltf, const glm::mat4& transform) {
  for (Light light : gltf.lights) {
    if (light.type != Light::Type::directional) {
      light.position = transform_point(transform, light.position);
      check_coordinates(where, light.position, "a light of the glTF file");
    }
    if (light.type != Light::Type::point) {
      // A direction turns by the transform's linear part (an invertible one: the object's transform is).
      const glm::dvec3 d = glm::dmat3(transform) * glm::dvec3(light.direction);
      light.direction = glm::vec3(glm::normalize(d));
    }
    scene_.lights.push_back(light);
  }
}

void SceneParser::add_gltf_instances(const Value& file_value, const Value& where, const std::filesystem::path& file,
                                     const std::vector<glm::mat4>& placements) {
  const LoadedGltf& loaded = gltf_file(&file_value, file);
  std::vector<Triangle> triangles = loaded.gltf.triangles;
  for (Triangle& t : triangles) t.material += loaded.material_offset;
  add_instances(where, triangles, placements);
  add_gltf_meshes(where, loaded, placements);
  for (const glm::mat4& transform : placements) add_gltf_lights(where, loaded.gltf, transform);
}

void SceneParser::add_gltf_meshes(const Value& where, const LoadedGltf& loaded, const std::vector<glm::mat4>& placements) {
  // Each mesh the file places by instances, placed by each of them, each of those moved by each
  // placement: held to the scene's limit before any is made.
  if (!loaded.gltf.instances.empty() &&
      placements.size() > (kMaxInstances - std::min(kMaxInstances, scene_.instances.size())) / loaded.gltf.instances.size())
    throw LimitError(file_.string() + ": " + where.path + ": " + std::to_string(placements.size()) + " placements of a file of " +
                     std::to_string(loaded.gltf.instances.size()) + " instances would make more than " + std::to_string(kMaxInstances) +
                     " instances; vkray renders at most that many");
  for (size_t m = 0; m < loaded.gltf.meshes.size(); ++m) {
    std::vector<glm::mat4> transforms;
    for (const glm::mat4& placement : placements)
      for (const Instance& instance : loaded.gltf.instances)
        if (instance.mesh == m) transforms.push_back(placement * instance.to_world);
    if (transforms.empty()) continue;
    std::vector<Triangle> triangles = loaded.gltf.meshes[m].triangles;
    for (Triangle& t : triangles) t.material += loaded.material_offset;
    add_instances(where, triangles, transforms, false);
  }
}

void SceneParser::add_instances(const Value& where, std::vector<Triangle>& triangles, const std::vector<glm::mat4>& placements,
                                bool each_named) {
  // Where a placement's error points: its element of "instances", or `where` itself.
  const auto at = [&](size_t i) { return each_named ? where[i] : where; };
  // The mesh in its own space, its zero-area triangles left out; nothing is placed when none is left.
  SharedMesh mesh;
  glm::vec3 lo(FLT_MAX), hi(-FLT_MAX);
  size_t left_out = 0;
  for (size_t i = 0; i < triangles.size(); ++i) {
    if (i % 4096 == 0) throw_if_interrupted();
    const Triangle& t = triangles[i];
    for (const glm::vec3& p : t.v) {
      if (!glm::all(glm::lessThanEqual(glm::abs(p), glm::vec3(kMaxCoordinate))))
        check_coordinates(where, p, ("triangle " + std::to_string(i) + " of the mesh").c_str());
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    if (glm::length(glm::cross(t.v[1] - t.v[0], t.v[2] - t.v[0])) == 0.0f) {
      ++left_out;
      continue;
    }
    mesh.triangles.push_back(t);
  }
  if (left_out > 0) warn(where, std::to_string(left_out) + " degenerate (zero-area) triangles left out");
  if (mesh.triangles.empty()) return;
  // Stored once (within kMaxScenePrimitives with everything else stored), placed many times (within
  // kMaxPlacedPrimitives, each placement counted).
  size_t stored = scene_.triangles.size() + scene_.spheres.size() + mesh.triangles.size();
  uint64_t placed = scene_.triangles.size() + scene_.spheres.size();
  for (const SharedMesh& m : scene_.meshes) stored += m.triangles.size();
  for (const Instance& i : scene_.instances) placed += scene_.meshes[i.mesh].triangles.size();
  if (stored > kMaxScenePrimitives)
    throw LimitError(file_.string() + ": " + where.path + ": the scene would store " + std::to_string(stored) +
                     " primitives; vkray renders at most " + std::to_string(kMaxScenePrimitives));
  if (placements.size() > kMaxInstances - std::min(kMaxInstances, scene_.instances.size()) ||
      placements.size() > (kMaxPlacedPrimitives - std::min(kMaxPlacedPrimitives, placed)) / mesh.triangles.size())
    throw LimitError(file_.string() + ": " + where.path + ": " + std::to_string(placements.size()) + " instances of " +
                     std::to_string(mesh.triangles.size()) + " triangles would place more than " + std::to_string(kMaxPlacedPrimitives) +
                     " primitives; vkray renders at most that many");
  const auto mesh_index = uint32_t(scene_.meshes.size());
  for (size_t i = 0; i < placements.size(); ++i) {
    if (i % 1024 == 0) throw_if_interrupted();
    // Renderers move rays by the inverse, in 32-bit floats.
    const glm::dmat4 inverse = glm::inverse(glm::dmat4(placements[i]));
    bool invertible = glm::determinant(glm::dmat3(placements[i])) != 0.0;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 3; ++r) invertible = invertible && std::abs(inverse[c][r]) <= double(FLT_MAX);
    if (!invertible)
      fail(at(i), "the transform cannot be inverted in 32-bit floats (a scale of zero, or too near it)");
    // Every corner of the mesh's box, placed, within the coordinates vkray renders: so is every vertex.
    for (int corner = 0; corner < 8; ++corner) {
      const glm::vec3 p((corner & 1) ? hi.x : lo.x, (corner & 2) ? hi.y : lo.y, (corner & 4) ? hi.z : lo.z);
      const glm::vec3 q = transform_point(placements[i], p);
      if (!glm::all(glm::lessThanEqual(glm::abs(q), glm::vec3(kMaxCoordinate))))
        check_coordinates(at(i), q, "the placed mesh's bounding box");
    }
    scene_.instances.push_back({mesh_index, placements[i], object_});
  }
  scene_.meshes.push_back(std::move(mesh));
}

void SceneParser::check_coordinates(const Value& where, const glm::vec3& p, const char* what) const {
  for (int c = 0; c < 3; ++c)
    if (!(std::abs(p[c]) <= kMaxCoordinate)) {
      char value[32];
      std::snprintf(value, sizeof value, "%g", double(p[c]));
      fail(where, std::string(what) + " has a coordinate of " + value +
                      "; vkray renders world-space coordinates within +-1e9 (docs/limits.md)");
    }
}

void SceneParser::check_primitive_count(const Value& where, size_t adding) const {
  const size_t count = scene_.triangles.size() + scene_.spheres.size();
  if (adding > kMaxScenePrimitives - count)
    throw LimitError(file_.string() + ": " + where.path + ": the scene would have " + std::to_string(count + adding) +
                     " primitives; vkray renders at most " + std::to_string(kMaxScenePrimitives));
}

void SceneParser::add_triangles(const Value& where, std::vector<Triangle>& triangles) {
  const auto within_limit = [](const glm::vec3& p) { return glm::all(glm::lessThanEqual(glm::abs(p), glm::vec3(kMaxCoordinate))); };
  std::vector<bool> degenerate(triangles.size());
  size_t left_out = 0;
  for (size_t i = 0; i < triangles.size(); ++i) {
    if (i % 4096 == 0) throw_if_interrupted();  // a mesh of millions takes a while to place
    const Triangle& t = triangles[i];
    for (const glm::vec3& p : t.v)  // the message is made only for a triangle that fails
      if (!within_limit(p)) check_coordinates(where, p, ("triangle " + std::to_string(i) + " (after the transform)").c_str());
    degenerate[i] = glm::length(glm::cross(t.v[1] - t.v[0], t.v[2] - t.v[0])) == 0.0f;
    left_out += degenerate[i];
  }
  check_primitive_count(where, triangles.size() - left_out);
  reserve_more(scene_.triangles, triangles.size() - left_out);
  for (size_t i = 0; i < triangles.size(); ++i)
    if (!degenerate[i]) scene_.triangles.push_back(triangles[i]);
  if (left_out > 0) warn(where, std::to_string(left_out) + " degenerate (zero-area) triangles left out");
}

void SceneParser::reference(const std::filesystem::path& file) {
  if (referenced_.insert(file).second) scene_.referenced_files.push_back(file);
}

int32_t SceneParser::texture_file(const Value& where, const std::filesystem::path& file, TextureUse use) {
  const auto key = std::make_pair(file, use);
  if (const auto found = texture_files_.find(key); found != texture_files_.end()) return found->second;
  reference(file);
  std::shared_ptr<const Texture> texture;
  try {
    texture = std::make_shared<const Texture>(load_texture(file, use));
  } catch (const LimitError& e) {
    throw LimitError(file_.string() + ": " + where.path + ": " + e.what());
  } catch (const SceneError& e) {
    throw SceneError(file_.string() + ": " + where.path + ": " + e.what());
  }
  const uint64_t texels = uint64_t(texture->width) * texture->height;
  if (texels > kMaxSceneTexels - std::min(kMaxSceneTexels, scene_texels_))
    throw LimitError(file_.string() + ": " + where.path + ": " + file.string() + ": it brings the scene's textures past " +
                     std::to_string(kMaxSceneTexels >> 20) + "M texels, vkray's limit (docs/limits.md)");
  const auto index = int32_t(scene_.textures.size());
  add_texture(std::move(texture));
  texture_files_[key] = index;
  return index;
}

std::filesystem::path SceneParser::file_of(const Value& name) const { return (file_.parent_path() / string(name)).lexically_normal(); }

std::vector<uint32_t> SceneParser::mesh_materials(const Value& where, const std::filesystem::path& mesh_file, const Mesh& mesh) {
  // Every library the file names, read now; a later definition of a name replaces an earlier one.
  std::map<std::string, std::pair<MtlMaterial, std::filesystem::path>> defined;
  for (const std::string& library : mesh.material_libraries) {
    const std::filesystem::path file = (mesh_file.parent_path() / library).lexically_normal();
    reference(file);
    auto cached = mtl_files_.find(file);
    if (cached == mtl_files_.end()) {  // a mesh placed many times reads its libraries once
      const InputFile input = read_input_file(file, kMaxSceneFileBytes);
      if (!input.error.empty())
        throw MeshError(file_.string() + ": " + where.path + ": " + mesh_file.filename().string() + ": mtllib " + printable(library) +
                        ": " + (input.error == "not found" ? "material library not found" : input.error));
      MtlLibrary parsed;
      try {
        parsed = parse_mtl(input.text, file);
      } catch (const MeshError& e) {
        throw MeshError(file_.string() + ": " + where.path + ": " + e.what());
      }
      for (const std::string& w : parsed.warnings) warn(where, w);
      cached = mtl_files_.emplace(file, std::move(parsed)).first;
    }
    for (const MtlMaterial& m : cached->second.materials) defined[m.name] = {m, file};
  }
  std::vector<uint32_t> index;  // mesh material -> scene material
  for (const std::string& name : mesh.material_names) {
    const auto found = defined.find(name);
    if (found == defined.end())
      throw MeshError(file_.string() + ": " + where.path + ": " + mesh_file.filename().string() + ": usemtl " + printable(name) +
                      ": no material library it names (mtllib) defines it");
    const MtlMaterial& mtl = found->second.first;
    const std::filesystem::path& library = found->second.second;
    if (scene_.integrator.type == Integrator::Type::path && glm::any(glm::greaterThan(mtl.diffuse, glm::vec3(1.0f))))
      throw MeshError(file_.string() + ": " + where.path + ": " + library.filename().string() + ": material " + printable(name) +
                      ": Kd above 1 reflects more light than arrives, which the path integrator would carry without end "
                      "(radiance past any bound): at most 1");
    Material material;
    material.name = mesh_file.filename().string() + ": " + name;
    material.albedo = mtl.diffuse;
    material.emission = mtl.emission;
    const auto map = [&](const MtlTexture& t, TextureUse use) {
      TextureRef ref;
      ref.texture = texture_file(where, (library.parent_path() / t.file).lexically_normal(), use);
      ref.wrap_s = ref.wrap_t = t.wrap;
      return ref;
    };
    if (!mtl.diffuse_map.file.empty()) material.albedo_texture = map(mtl.diffuse_map, TextureUse::colour);
    if (!mtl.emission_map.file.empty()) material.emission_texture = map(mtl.emission_map, TextureUse::colour);
    // The dissolve: each ray meets the surface with probability d times map_d's value.
    material.opacity = mtl.opacity;
    if (!mtl.opacity_map.file.empty()) material.opacity_texture = map(mtl.opacity_map, TextureUse::opacity);
    if (material.opacity < 1.0f || material.opacity_texture.present()) material.alpha_mode = AlphaMode::blend;
    index.push_back(uint32_t(scene_.materials.size()));
    scene_.materials.push_back(std::move(material));
  }
  return index;
}

std::vector<Triangle> SceneParser::mesh_triangles(const Value& v, const glm::mat4& transform) {
  const Value file_value = require(v, "file");
  const std::filesystem::path file = file_of(file_value);
  bool smooth = false;
  if (v.has("smooth")) {
    if (!v["smooth"].j.is_boolean()) fail(v["smooth"], std::string("expected true or false, got ") + v["smooth"].j.type_name());
    smooth = v["smooth"].j.get<bool>();
  }
  std::shared_ptr<const Mesh> loaded;
  try {
    loaded = meshes_.get(file);
  } catch (const MeshError& e) {
    throw MeshError(file_.string() + ": " + file_value.path + ": " + e.what());
  }
  if (referenced_.insert(file).second) {
    scene_.referenced_files.push_back(file);
    if (loaded->polygons_split > 0)
      warn(file_value, file.filename().string() + ": " + std::to_string(loaded->polygons_split) +
                           " faces with more than 3 vertices split into triangles");
  }
  const Mesh& mesh = *loaded;

  // The scene's material for every face, or the ones the file's faces name (an OBJ file's usemtl).
  std::vector<uint32_t> file_materials;
  uint32_t material = 0;
  if (v.has("material")) {
    material = material_ref(v["material"]);
  } else if (!mesh.material_names.empty()) {
    // The file's materials are the scene's once, however often the file is placed (as a glTF file's are).
    // Keyed by the mesh read, not its path: a file saved again between two placements is read again
    // (MeshCache) and may name other materials.
    auto made = mesh_file_materials_.find(file);
    if (made == mesh_file_materials_.end() || made->second.mesh != loaded) {
      MeshFileMaterials m;
      m.mesh = loaded;
      m.named = mesh_materials(file_value, file, mesh);
      const bool unnamed = std::find(mesh.triangle_materials.begin(), mesh.triangle_materials.end(), Mesh::kNoMaterial) !=
                           mesh.triangle_materials.end();
      if (unnamed) {  // faces before the first usemtl
        Material grey;
        grey.name = file.filename().string() + ": (no usemtl)";
        grey.albedo = glm::vec3(0.8f);
        m.unnamed = uint32_t(scene_.materials.size());
        scene_.materials.push_back(grey);
      }
      made = mesh_file_materials_.insert_or_assign(file, std::move(m)).first;
    }
    file_materials = made->second.named;
    material = made->second.unnamed;
  } else {
    fail(v, "missing required key \"material\" (" + file.filename().string() + " names no materials of its own)");
  }

  std::vector<glm::vec3> points(mesh.positions.size());
  for (size_t i = 0; i < points.size(); ++i) points[i] = transform_point(transform, mesh.positions[i]);
  // A transform that mirrors turns the winding around: corners 1 and 2 are taken the other way, so
  // that front faces stay front (as a glTF file's are).
  const std::array<size_t, 3> corner = glm::determinant(glm::mat3(transform)) < 0.0f ? std::array<size_t, 3>{0, 2, 1}
                                                                                      : std::array<size_t, 3>{0, 1, 2};
  std::vector<Triangle> triangles(mesh.triangles.size());
  for (size_t i = 0; i < triangles.size(); ++i) {
    const uint32_t named = file_materials.empty() ? Mesh::kNoMaterial : mesh.triangle_materials[i];
    triangles[i].material = named == Mesh::kNoMaterial ? material : file_materials[named];
    triangles[i].object = object_;
    for (size_t k = 0; k < 3; ++k) triangles[i].v[k] = points[mesh.triangles[i][corner[k]]];
    if (!mesh.corner_uvs.empty())
      for (size_t k = 0; k < 3; ++k) triangles[i].uv[k] = mesh.corner_uvs[i][corner[k]];
  }
  if (mesh.corner_uvs.empty() &&
      std::any_of(triangles.begin(), triangles.end(), [&](const Triangle& t) { return scene_.materials[t.material].textured(); }))
    warn(file_value, file.filename().string() + ": a textured material on faces without texture coordinates (vt): "
                                                "every point takes the texture's value at (0, 0)");
  if (smooth) {
    if (!mesh.corner_normals.empty()) {
      // Normals transform by the inverse transpose.
      const glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(transform)));
      for (size_t i = 0; i < triangles.size(); ++i)
        for (size_t k = 0; k < 3; ++k) triangles[i].normals[k] = glm::normalize(normal_matrix * mesh.corner_normals[i][corner[k]]);
    } else {
      std::vector<std::array<glm::vec3, 3>> corners(triangles.size());
      for (size_t i = 0; i < triangles.size(); ++i) corners[i] = triangles[i].v;
      const auto normals = area_weighted_normals(corners);
      for (size_t i = 0; i < triangles.size(); ++i) triangles[i].normals = normals[i];
    }
    for (Triangle& t : triangles) {
      t.smooth = true;
      // A zero normal (a vertex only on degenerate faces, or a zero normal in the file) cannot be
      // interpolated meaningfully: shade that triangle flat.
      for (const glm::vec3& n : t.normals)
        if (!std::isfinite(n.x) || glm::length(n) < 0.5f) t.smooth = false;
    }
  }
  if (flip_normals(v))
    for (Triangle& t : triangles) {  // the other winding, and the vertex normals turned with it
      t.swap_corners();
      for (glm::vec3& n : t.normals) n = -n;
    }
  return triangles;
}


}  // namespace vkray::scene_file
