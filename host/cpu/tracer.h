// The CPU reference's ray queries, in double precision and written the plain way the lecture writes
// them: the ray-triangle 3x3 system by Cramer's rule, the ray-sphere quadratic, a recursive BVH walk
// (or every primitive, to check the walk), and the surface at a hit.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace vkray {
struct Bvh;
struct SceneBvh;
}

namespace vkray::cpu {

using glm::dvec3;

struct Ray {
  dvec3 origin;
  dvec3 dir;  // unit length
};

struct Hit {
  double t;
  int64_t primitive;    // in the scene's numbering (PrimitiveNumbering); -1 for none
  double u = 0, v = 0;  // barycentrics of a triangle hit: x = v0 + u e1 + v e2
  int64_t instance = -1;  // the instance it belongs to (Scene::instances), or -1
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
  double transmission = 0;  // metallic_roughness: the material's transmission, its texture applied
  uint32_t properties = 0;  // the material's (VKRAY_BSDF_*)
};

// A surface as a ray along `dir` meets it, on its front (the side its geometric normal faces) or
// not: both normals turned toward the ray, the shading one, where the material is not purely
// Lambertian, bent toward the geometric one where the mirror reflection of -dir about it would not
// leave the surface (valid_reflection_normal).
struct Facing {
  dvec3 n_geometric;
  dvec3 n;
};
Facing facing(const SurfacePoint& s, const dvec3& dir, bool front);

// Cycles' rule for a shading normal n that faces away from the viewer along wo (ng . wo >= 0): the
// unit normal in the plane of n and ng, nearest n, about which wo's mirror reflection r has
// r . ng = min(0.9 (ng . wo), 0.01); n itself where r . ng is already at least that.
dvec3 valid_reflection_normal(const dvec3& ng, const dvec3& wo, const dvec3& n);

// The opacity of a primitive at barycentrics (u, v) of a triangle: its material's factor times its
// opacity texture's alpha times its vertex colours' (a sphere's: the factor).
double opacity_at(const Scene& scene, const PrimitiveNumbering::Placed& primitive, double u, double v);

// A triangle's vertex colour at barycentrics (u, v).
glm::dvec4 vertex_colour(const Triangle& tri, double u, double v);

class Tracer {
 public:
  // `bvh` null: every primitive is tested (slow; checks the traversal).
  Tracer(const Scene& scene, const SceneBvh* bvh);

  // Each query draws the ray's alpha key from the sample's stream, where the scene has see-through
  // materials (Material::see_through), as the shader does (traversal.glsl): the key decides where
  // the ray passes a blended surface (shared/sampling.h, alpha_random).
  // Closest intersection with t in (t_min, t_max).
  Hit closest(const Ray& ray, double t_min, double t_max, uint32_t& stream) const {
    return find(ray, t_min, t_max, false, false, alpha_key(stream));
  }
  // The closest hit of a ray from the camera, which passes the back faces of single-sided
  // triangles (Material::double_sided).
  Hit camera_hit(const Ray& ray, double t_min, double t_max, uint32_t& stream) const {
    return find(ray, t_min, t_max, false, true, alpha_key(stream));
  }
  // Whether anything lies on the ray with t in (t_min, t_max).
  bool occluded(const Ray& ray, double t_min, double t_max, uint32_t& stream) const {
    return find(ray, t_min, t_max, true, false, alpha_key(stream)).primitive >= 0;
  }

  SurfacePoint surface(const Ray& ray, const Hit& hit) const;

  const Scene& scene() const { return scene_; }
  const PrimitiveNumbering& numbering() const { return numbering_; }
  // A world-space ray in instance `instance`'s mesh space: its direction not made unit again, so
  // that t is the same along both.
  Ray to_mesh(int64_t instance, const Ray& ray) const;
  // A mesh-space normal of instance `instance` in world space, unit.
  dvec3 normal_to_world(int64_t instance, const dvec3& n) const;
  // A mesh-space point of instance `instance` in world space.
  dvec3 point_to_world(int64_t instance, const dvec3& p) const;
  // The scene's epsilon (Scene::epsilon, which walks every primitive), computed once.
  double epsilon() const { return epsilon_; }

 private:
  // A ray's key: the next word of the stream where the scene has see-through materials.
  uint32_t alpha_key(uint32_t& stream) const;
  Hit find(const Ray& ray, double t_min, double t_max, bool any_hit, bool camera_ray, uint32_t alpha_key) const;
  // Whether the ray with `alpha_key` meets the surface it reaches at `hit`.
  bool solid(const Ray& ray, const Hit& hit, uint32_t alpha_key) const;
  // A surface the ray has passed: the search after it goes on in the tie rule's order, a primitive
  // within a tie of `t` counting only if it comes later in the scene. t 0: none.
  struct Passed {
    double t = 0;
    int64_t primitive = -1;
  };
  // The surface at a hit, with `ray` in the hit primitive's own space.
  SurfacePoint local_surface(const Ray& ray, const Hit& hit) const;
  // Every surface taken as whole.
  Hit search(const Ray& ray, double t_min, double t_max, bool any_hit, bool camera_ray, const Passed& passed) const;
  // Tests primitive p (the scene's numbering), of `instance` (-1: none), with `ray` in its space.
  void test(const Ray& ray, uint64_t p, int64_t instance, double t_min, double t_max, bool camera_ray, const Passed& passed,
            Hit& best) const;
  // Walks `bvh` from `node` with `ray`, calling leaf(slot) for each slot of each leaf it enters (true
  // from leaf: stop, any_hit found one). Returns true when stopped.
  template <typename Leaf>
  bool visit(const Bvh& bvh, uint32_t node, const Ray& ray, double t_min, double t_max, const Hit& best, const Leaf& leaf) const;

  const Scene& scene_;
  const SceneBvh* bvh_;
  PrimitiveNumbering numbering_;
  std::vector<glm::dmat4> to_mesh_;        // each instance's inverse transform
  std::vector<glm::dmat3> normal_matrix_;  // each instance's inverse transpose
  double epsilon_;
  bool see_through_;
};

}  // namespace vkray::cpu
