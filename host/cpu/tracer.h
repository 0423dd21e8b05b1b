// The CPU reference's ray queries, in double precision and written the plain way the lecture writes
// them: the ray-triangle 3x3 system by Cramer's rule, the ray-sphere quadratic, a recursive BVH walk
// (or every primitive, to check the walk), and the surface at a hit.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace vkray {
struct Bvh;
}

namespace vkray::cpu {

using glm::dvec3;

struct Ray {
  dvec3 origin;
  dvec3 dir;  // unit length
};

struct Hit {
  double t;
  int primitive;        // triangle index, then sphere index + triangle count; -1 for none
  double u = 0, v = 0;  // barycentrics of a triangle hit: x = v0 + u e1 + v e2
};

// The surface where a ray hit.
struct SurfacePoint {
  dvec3 position;
  dvec3 geometric_normal;  // unit; the side it faces emits, and is glass's outside
  dvec3 shading_normal;    // unit: the geometric normal, or the interpolated vertex normal; then the normal map's
  uint32_t material = 0;
  dvec3 albedo{0.0};    // the material's albedo (or reflectance), its texture applied
  dvec3 emission{0.0};  // the material's emission, its texture applied
  double metallic = 1;   // metallic_roughness: the material's metallic and roughness, its texture applied
  double roughness = 1;
};

// A surface as a ray along `dir` meets it, on its front (the side its geometric normal faces) or
// not: both normals turned toward the ray, the shading one bent toward the geometric one where the
// mirror reflection of -dir about it would not leave the surface (valid_reflection_normal).
struct Facing {
  dvec3 n_geometric;
  dvec3 n;
};
Facing facing(const SurfacePoint& s, const dvec3& dir, bool front);

// Cycles' rule for a shading normal n that faces away from the viewer along wo (ng . wo >= 0): the
// unit normal in the plane of n and ng, nearest n, about which wo's mirror reflection r has
// r . ng = min(0.9 (ng . wo), 0.01); n itself where r . ng is already at least that.
dvec3 valid_reflection_normal(const dvec3& ng, const dvec3& wo, const dvec3& n);

class Tracer {
 public:
  // `bvh` null: every primitive is tested (slow; checks the traversal).
  Tracer(const Scene& scene, const Bvh* bvh) : scene_(scene), bvh_(bvh), epsilon_(scene.epsilon()) {}

  // Closest intersection with t in (t_min, t_max); with any_hit, the first one found.
  Hit closest(const Ray& ray, double t_min, double t_max, bool any_hit = false) const { return find(ray, t_min, t_max, any_hit, false); }
  // The closest hit of a ray from the camera, which passes the back faces of single-sided
  // triangles (Material::double_sided).
  Hit camera_hit(const Ray& ray, double t_min, double t_max) const { return find(ray, t_min, t_max, false, true); }
  // Whether anything lies on the ray with t in (t_min, t_max).
  bool occluded(const Ray& ray, double t_min, double t_max) const { return closest(ray, t_min, t_max, true).primitive >= 0; }

  SurfacePoint surface(const Ray& ray, const Hit& hit) const;

  const Scene& scene() const { return scene_; }
  // The scene's epsilon (Scene::epsilon, which walks every primitive), computed once.
  double epsilon() const { return epsilon_; }

 private:
  Hit find(const Ray& ray, double t_min, double t_max, bool any_hit, bool camera_ray) const;
  void test(const Ray& ray, size_t p, double t_min, double t_max, bool camera_ray, Hit& best) const;
  bool visit(uint32_t node, const Ray& ray, const dvec3& inv, double t_min, double t_max, bool any_hit, bool camera_ray,
             Hit& best) const;

  const Scene& scene_;
  const Bvh* bvh_;
  double epsilon_;
};

}  // namespace vkray::cpu
