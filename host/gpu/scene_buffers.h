// A scene's buffers on the device: its BVH built, packed (host/packing/) and uploaded into texel
// buffers, ready for any number of renders. It owns what it was built from and keeps its device
// alive, so whoever holds it need not order it against anything else. The session hands it to the
// faces as a DeviceScene (session/session.h).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "gpu/context.h"
#include "gpu/descriptors.h"
#include "packing/scene_packing.h"
#include "scene/scene.h"

namespace vkray {
struct SceneBvh;
}

namespace vkray::gpu {

class SceneBuffers {
 public:
  // `bvh`: one already built for this scene (parity traverses the same one on the CPU); null builds
  // one. Throws DeviceError naming the limit when a buffer or the whole does not fit the device.
  SceneBuffers(std::shared_ptr<const Context> ctx, std::shared_ptr<const Scene> scene, const SceneBvh* bvh = nullptr);
  // `scene`, whose geometry is `same`'s (same_geometry): shares `same`'s BVH and primitive buffers,
  // and uploads only its lighting (materials, lights, area lights).
  SceneBuffers(const SceneBuffers& same, std::shared_ptr<const Scene> scene);
  ~SceneBuffers();

  const Scene& scene() const { return *scene_; }
  const Context& context() const { return *ctx_; }
  // The code that compiles this scene into the shader (packing/inline_scene.h); empty for a scene
  // with more than kMaxInlinePrimitives primitives, or none.
  const std::string& inline_scene() const { return inline_scene_; }
  // Primitives stored (a mesh that instances place counted once).
  uint32_t primitive_count() const { return primitive_count_; }
  double bvh_seconds() const { return bvh_seconds_; }
  double upload_seconds() const { return upload_seconds_; }  // BVH build included, prebuilt or not
  double environment_seconds() const { return environment_seconds_; }  // of upload: the environment map's packing
  bool shares_geometry() const { return shares_geometry_; }  // made by the second constructor
  const LightingFrame& lighting() const { return lighting_frame_; }
  // Whether some triangle is shaded with its vertex normals (Triangle::smooth).
  bool vertex_normals() const { return vertex_normals_; }
  // Whether some triangle has vertex colours (Triangle::colours).
  bool vertex_colours() const { return vertex_colours_; }
  // Whether the scene places meshes by instances: a BVH of two levels.
  bool instances() const { return instances_; }
  // Whether some primitive lets rays through (Scene::see_through), read off the packed flags once.
  bool see_through() const { return see_through_; }

  // Adds the scene's buffers at their bindings (shared/types.h).
  void bind(DescriptorWriter& writer) const;

 private:
  struct Geometry;
  struct Lighting;
  std::shared_ptr<const Context> ctx_;  // first: destroyed last
  std::shared_ptr<const Scene> scene_;
  std::shared_ptr<const Geometry> geometry_;  // shared by the scenes made from this one
  std::unique_ptr<Lighting> lighting_;
  uint32_t primitive_count_ = 0;
  std::string inline_scene_;
  LightingFrame lighting_frame_;
  double bvh_seconds_ = 0, upload_seconds_ = 0, environment_seconds_ = 0;
  bool shares_geometry_ = false;
  bool vertex_normals_ = false;
  bool vertex_colours_ = false;
  bool instances_ = false;
  bool see_through_ = false;
};

}  // namespace vkray::gpu
