#include "cpu/tracer.h"

#include <algorithm>
#include <cmath>

#include "bvh/bvh.h"
#include "cpu/texture.h"
#include "shared/materials.h"
#include "shared/sampling.h"
#include "shared/types.h"

namespace vkray::cpu {
namespace {

// Determinant of the 3x3 matrix with columns a, b, c.
double det3(dvec3 a, dvec3 b, dvec3 c) {
  return a.x * (b.y * c.z - b.z * c.y) - b.x * (a.y * c.z - a.z * c.y) + c.x * (a.y * b.z - a.z * b.y);
}

// The largest t still worth testing: up to a tie with the best hit so far (VKRAY_TIE).
double limit(const Hit& best, double t_max) { return best.primitive < 0 ? t_max : best.t * (1 + VKRAY_TIE); }

// Tests primitive p (in the scene's numbering) and keeps it in `best` if it is nearer, or ties
// Whether the ray enters `box` before `t_max`, and where. Exit distances are padded by 1e-12
// relative, so a flat box (an axis-aligned wall's) is never lost to rounding.
bool enters(const Aabb& box, const Ray& ray, const dvec3& inv, double t_min, double t_max, double& t_enter) {
  double enter = t_min, exit = t_max;
  for (int a = 0; a < 3; ++a) {
    double t0 = (double(box.min[a]) - ray.origin[a]) * inv[a];
    double t1 = (double(box.max[a]) - ray.origin[a]) * inv[a];
    if (t0 > t1) std::swap(t0, t1);
    enter = std::max(enter, t0);
    exit = std::min(exit, t1 * (1 + 1e-12));
  }
  t_enter = enter;
  return enter <= exit;
}

// The lecture's ray-triangle test: solve [-d, e1, e2] (t, u, v)^T = s - v0 by Cramer's rule and
// accept u >= 0, v >= 0, u + v <= 1. Returns t, or -1.
double intersect_triangle(const Ray& ray, const Triangle& tri, double t_min, double t_max, double& u, double& v) {
  const dvec3 v0(tri.v[0]);
  const dvec3 e1 = dvec3(tri.v[1]) - v0, e2 = dvec3(tri.v[2]) - v0, b = ray.origin - v0;
  const double det = det3(-ray.dir, e1, e2);
  if (det == 0) return -1;  // parallel to the plane, or degenerate
  u = det3(-ray.dir, b, e2) / det;
  v = det3(-ray.dir, e1, b) / det;
  if (u < 0 || v < 0 || u + v > 1) return -1;
  const double t = det3(b, e1, e2) / det;
  return (t > t_min && t < t_max) ? t : -1;
}

// The lecture's ray-sphere test: |o + t d - c|^2 = r^2 as a t^2 + b t + c = 0; the nearest root
// in range counts. Returns t, or -1.
double intersect_sphere(const Ray& ray, const Sphere& s, double t_min, double t_max) {
  const dvec3 oc = ray.origin - dvec3(s.center);
  const double a = glm::dot(ray.dir, ray.dir);
  const double b = 2 * glm::dot(ray.dir, oc);
  const double c = glm::dot(oc, oc) - double(s.radius) * double(s.radius);
  const double discriminant = b * b - 4 * a * c;
  if (discriminant < 0) return -1;
  const double root = std::sqrt(discriminant);
  for (const double t : {(-b - root) / (2 * a), (-b + root) / (2 * a)})
    if (t > t_min && t < t_max) return t;
  return -1;
}
}  // namespace

double opacity_at(const Scene& scene, const PrimitiveNumbering::Placed& primitive, double u, double v) {
  if (primitive.sphere) return scene.materials[primitive.sphere->material].opacity;
  const Triangle& tri = *primitive.triangle;
  const Material& m = scene.materials[tri.material];
  double opacity = m.opacity;
  if (m.opacity_texture.present()) opacity *= sample_texture_rgba(scene, m.opacity_texture, triangle_texcoord(tri, m.opacity_texture, u, v)).a;
  if (tri.coloured()) opacity *= vertex_colour(tri, u, v).a;
  return opacity;
}

glm::dvec4 vertex_colour(const Triangle& tri, double u, double v) {
  return (1 - u - v) * glm::dvec4(tri.colours[0]) + u * glm::dvec4(tri.colours[1]) + v * glm::dvec4(tri.colours[2]);
}

Tracer::Tracer(const Scene& scene, const SceneBvh* bvh)
    : scene_(scene), bvh_(bvh), numbering_(scene), epsilon_(scene.epsilon()), see_through_(scene.see_through()) {
  for (const Instance& instance : scene.instances) {
    const glm::dmat4 to_world(instance.to_world);
    to_mesh_.push_back(glm::inverse(to_world));
    normal_matrix_.push_back(glm::transpose(glm::inverse(glm::dmat3(to_world))));
  }
}

Ray Tracer::to_mesh(int64_t instance, const Ray& ray) const {
  const glm::dmat4& m = to_mesh_[size_t(instance)];
  return {dvec3(m * glm::dvec4(ray.origin, 1.0)), dvec3(m * glm::dvec4(ray.dir, 0.0))};
}

dvec3 Tracer::normal_to_world(int64_t instance, const dvec3& n) const { return glm::normalize(normal_matrix_[size_t(instance)] * n); }

dvec3 Tracer::point_to_world(int64_t instance, const dvec3& p) const {
  return dvec3(glm::dmat4(scene_.instances[size_t(instance)].to_world) * glm::dvec4(p, 1.0));
}

uint32_t Tracer::alpha_key(uint32_t& stream) const { return see_through_ ? gpu::next_word(stream) : 0; }

// The hit as search() finds it; where the scene has see-through materials, the nearest hit, and
// where its surface lets the ray through, the next in the tie rule's order (a sphere's far side among
// them), until one stops the ray or none is left: the shader's rule (trace() in traversal.glsl).
Hit Tracer::find(const Ray& ray, double t_min, double t_max, bool any_hit, bool camera_ray, uint32_t alpha_key) const {
  if (!see_through_) return search(ray, t_min, t_max, any_hit, camera_ray, {});
  Hit hit = search(ray, t_min, t_max, false, camera_ray, {});
  while (hit.primitive >= 0 && !solid(ray, hit, alpha_key))
    hit = search(ray, std::max(t_min, hit.t * (1 - VKRAY_TIE)), t_max, false, camera_ray, {hit.t, hit.primitive});
  return hit;
}

bool Tracer::solid(const Ray& ray, const Hit& hit, uint32_t alpha_key) const {
  const PrimitiveNumbering::Placed placed = numbering_.at(uint64_t(hit.primitive));
  const Material& m = scene_.materials[placed.sphere ? placed.sphere->material : placed.triangle->material];
  if (placed.sphere ? !m.see_through() : !scene_.see_through(*placed.triangle)) return true;
  // A sphere is two surfaces to a ray: the side it enters by and the side it leaves by.
  const bool far_side = placed.sphere && glm::dot(ray.dir, ray.origin + hit.t * ray.dir - dvec3(placed.sphere->center)) > 0;
  return gpu::alpha_solid(uint32_t(m.alpha_mode), float(opacity_at(scene_, placed, hit.u, hit.v)), m.alpha_cutoff,
                          gpu::alpha_random(alpha_key, uint32_t(hit.primitive), far_side));
}

Hit Tracer::search(const Ray& ray, double t_min, double t_max, bool any_hit, bool camera_ray, const Passed& passed) const {
  Hit best{t_max, -1};
  if (!bvh_) {
    for (uint64_t p = 0; p < numbering_.count() && !(any_hit && best.primitive >= 0); ++p) {
      const int64_t instance = numbering_.at(p).instance;
      test(instance < 0 ? ray : to_mesh(instance, ray), p, instance, t_min, t_max, camera_ray, passed, best);
    }
    return best;
  }
  // The scene's own primitives: slot i of their BVH is triangles[i] or, past them, a sphere.
  const uint64_t triangles = scene_.triangles.size();
  const auto own = [&](uint32_t slot) {
    const uint64_t i = bvh_->primitives.order[slot];
    test(ray, i < triangles ? i : numbering_.sphere_first() + (i - triangles), -1, t_min, t_max, camera_ray, passed, best);
    return any_hit && best.primitive >= 0;
  };
  if (!bvh_->primitives.nodes.empty() && visit(bvh_->primitives, 0, ray, t_min, t_max, best, own)) return best;
  if (bvh_->instances.nodes.empty()) return best;
  // Each instance the ray enters: its mesh's BVH, walked with the ray in the mesh's space.
  const auto instance = [&](uint32_t slot) {
    const uint32_t k = bvh_->instances.order[slot];
    const Ray local = to_mesh(k, ray);
    const Bvh& mesh = bvh_->meshes[scene_.instances[k].mesh];
    const uint64_t first = numbering_.instance_first(k);
    return visit(mesh, 0, local, t_min, t_max, best, [&](uint32_t mesh_slot) {
      test(local, first + mesh.order[mesh_slot], k, t_min, t_max, camera_ray, passed, best);
      return any_hit && best.primitive >= 0;
    });
  };
  visit(bvh_->instances, 0, ray, t_min, t_max, best, instance);
  return best;
}

// Tests primitive p, which becomes the best hit when it is closer than the best so far by more
// than VKRAY_TIE, or ties with it and comes first in the scene.
void Tracer::test(const Ray& ray, uint64_t p, int64_t instance, double t_min_all, double t_max, bool camera_ray, const Passed& passed,
                  Hit& best) const {
  Hit candidate{-1, int64_t(p)};
  candidate.instance = instance;
  // After a surface passed, a primitive that does not come later in the scene counts only past a tie with it.
  const double t_min = int64_t(p) <= passed.primitive ? std::max(t_min_all, passed.t * (1 + VKRAY_TIE)) : t_min_all;
  const PrimitiveNumbering::Placed placed = numbering_.at(p);
  if (placed.triangle) {
    const Triangle& tri = *placed.triangle;
    candidate.t = intersect_triangle(ray, tri, t_min, limit(best, t_max), candidate.u, candidate.v);
    // A camera ray passes the back face of a single-sided triangle: the side away from its winding's
    // normal (in an instance, turned to world space: a mirroring instance turns it around).
    if (camera_ray && candidate.t >= 0 && !scene_.materials[tri.material].double_sided) {
      const dvec3 n = glm::cross(dvec3(tri.v[1]) - dvec3(tri.v[0]), dvec3(tri.v[2]) - dvec3(tri.v[0]));
      // dot(M^-1 d, n) is dot(d, M^-T n): the same side test in either space, the normal's
      // direction kept by the inverse transpose, so a mirror keeps front faces front.
      if (glm::dot(ray.dir, n) > 0) return;
    }
  } else {
    candidate.t = intersect_sphere(ray, *placed.sphere, t_min, limit(best, t_max));
  }
  if (candidate.t < 0) return;
  if (best.primitive < 0 || candidate.t < best.t * (1 - VKRAY_TIE) || candidate.primitive < best.primitive) best = candidate;
}

// Recursive descent, nearer child first.
template <typename Leaf>
bool Tracer::visit(const Bvh& bvh, uint32_t node, const Ray& ray, double t_min, double t_max, const Hit& best, const Leaf& leaf) const {
  // 1 / d with zero components replaced by tiny ones, so a slab test never computes 0 * inf.
  dvec3 inv;
  for (int a = 0; a < 3; ++a) inv[a] = (ray.dir[a] < 0 ? -1.0 : 1.0) / std::max(std::abs(ray.dir[a]), 1e-300);
  const auto walk = [&](const auto& self, uint32_t at) -> bool {
    const BvhNode& n = bvh.nodes[at];
    double t_enter[2];
    const bool hit[2] = {enters(n.child[0], ray, inv, t_min, limit(best, t_max), t_enter[0]),
                         enters(n.child[1], ray, inv, t_min, limit(best, t_max), t_enter[1])};
    const int first = (hit[0] && hit[1] && t_enter[1] < t_enter[0]) ? 1 : 0;
    for (const int c : {first, 1 - first}) {
      if (!hit[c]) continue;
      const uint32_t link = n.link[c];
      if (is_leaf(link)) {
        for (uint32_t slot = leaf_first(link); slot < leaf_first(link) + leaf_count(link); ++slot)
          if (leaf(slot)) return true;
      } else if (self(self, link)) {
        return true;
      }
    }
    return false;
  };
  return walk(walk, node);
}

dvec3 valid_reflection_normal(const dvec3& ng, const dvec3& wo, const dvec3& n) {
  const double cos_o = glm::dot(wo, ng);
  const double threshold = std::min(0.9 * cos_o, 0.01);
  const dvec3 reflected = 2 * glm::dot(n, wo) * n - wo;
  if (glm::dot(reflected, ng) >= threshold) return n;
  // The bent normal is sin(theta) x + cos(theta) ng, x the unit direction of n's part across ng. Its
  // reflection's height 2 (wo . N) cos(theta) - cos_o = threshold, squared, is a quadratic in
  // c = cos^2(theta): 4 a c^2 - 2 b c + (threshold + cos_o)^2 = 0 with a = (wo . x)^2 + cos_o^2 and
  // b = 2 (a + cos_o threshold); of its two roots, the one on the side wo's part along x picks.
  const dvec3 across = n - glm::dot(n, ng) * ng;
  const double across_length = glm::length(across);
  if (!(across_length > 0)) return ng;
  const dvec3 x = across / across_length;
  const double wo_x = glm::dot(wo, x);
  const double a = wo_x * wo_x + cos_o * cos_o;
  if (!(a > 0)) return ng;
  const double b = 2 * (a + cos_o * threshold);
  const double root = std::sqrt(std::max(b * b - 4 * a * (threshold + cos_o) * (threshold + cos_o), 0.0));
  const double c = std::clamp((wo_x < 0 ? b + root : b - root) / (4 * a), 0.0, 1.0);
  return std::sqrt(1 - c) * x + std::sqrt(c) * ng;
}

Facing facing(const SurfacePoint& s, const dvec3& dir, bool front) {
  const dvec3 ng = front ? s.geometric_normal : -s.geometric_normal;
  const dvec3 n = front ? s.shading_normal : -s.shading_normal;
  return {ng, s.properties == VKRAY_BSDF_DIFFUSE ? n : valid_reflection_normal(ng, -dir, n)};
}

SurfacePoint Tracer::surface(const Ray& ray, const Hit& hit) const {
  if (hit.instance < 0) return local_surface(ray, hit);
  // An instance's surface is its mesh's, found with the ray in the mesh's space, its normals turned to
  // world space by the inverse transpose.
  SurfacePoint s = local_surface(to_mesh(hit.instance, ray), hit);
  s.position = ray.origin + hit.t * ray.dir;
  s.geometric_normal = normal_to_world(hit.instance, s.geometric_normal);
  s.shading_normal = normal_to_world(hit.instance, s.shading_normal);
  return s;
}

SurfacePoint Tracer::local_surface(const Ray& ray, const Hit& hit) const {
  SurfacePoint s;
  s.position = ray.origin + hit.t * ray.dir;
  const PrimitiveNumbering::Placed placed = numbering_.at(uint64_t(hit.primitive));
  const bool triangle = placed.triangle != nullptr;
  // The material's values, then (on a triangle) its textures at the hit.
  s.material = triangle ? placed.triangle->material : placed.sphere->material;
  const Material& m = scene_.materials[s.material];
  s.properties = m.properties();
  s.albedo = dvec3(m.albedo);
  s.emission = dvec3(m.emission);
  s.metallic = m.metallic;
  s.roughness = m.roughness;
  s.transmission = m.transmission;
  if (!triangle) {
    const Sphere& sphere = *placed.sphere;
    s.geometric_normal = (s.position - dvec3(sphere.center)) / double(sphere.radius);
    if (sphere.inward) s.geometric_normal = -s.geometric_normal;
    s.shading_normal = s.geometric_normal;
    return s;
  }
  const Triangle& tri = *placed.triangle;
  s.geometric_normal = glm::normalize(glm::cross(dvec3(tri.v[1]) - dvec3(tri.v[0]), dvec3(tri.v[2]) - dvec3(tri.v[0])));
  s.shading_normal = s.geometric_normal;
  if (tri.smooth)
    s.shading_normal = glm::normalize((1 - hit.u - hit.v) * dvec3(tri.normals[0]) + hit.u * dvec3(tri.normals[1]) +
                                      hit.v * dvec3(tri.normals[2]));
  // Vertex colours (glTF's COLOR_0) multiply the base colour, which an unlit material emits.
  if (tri.coloured()) (m.vertex_colours_emit ? s.emission : s.albedo) *= dvec3(vertex_colour(tri, hit.u, hit.v));
  if (!m.textured()) return s;
  // Each texture at the texture coordinate of the set it reads.
  const auto at = [&](const TextureRef& ref) { return sample_texture(scene_, ref, triangle_texcoord(tri, ref, hit.u, hit.v)); };
  if (m.albedo_texture.present()) s.albedo *= at(m.albedo_texture);
  if (m.emission_texture.present()) s.emission *= at(m.emission_texture);
  if (m.metallic_roughness_texture.present()) {  // metalness in blue, roughness in green
    const dvec3 layers = at(m.metallic_roughness_texture);
    s.metallic *= layers.b;
    s.roughness *= layers.g;
  }
  if (m.transmission_texture.present()) s.transmission *= at(m.transmission_texture).r;
  // A normal map in MikkTSpace's frame: the tangent interpolated and not normalized, the bitangent
  // its sign times normal x tangent, the map's red and green scaled (glTF's formula).
  if (m.normal_texture.present() && tri.has_tangents()) {
    const double weight[3] = {1 - hit.u - hit.v, hit.u, hit.v};
    dvec3 tangent(0.0);
    double sign = 0;
    for (size_t k = 0; k < 3; ++k) {
      tangent += weight[k] * dvec3(tri.tangents[k]);
      sign += weight[k] * double(tri.tangents[k].w);
    }
    const dvec3 bitangent = (sign < 0 ? -1.0 : 1.0) * glm::cross(s.shading_normal, tangent);
    const dvec3 mapped = (2.0 * at(m.normal_texture) - 1.0) * dvec3(m.normal_scale, m.normal_scale, 1.0);
    const dvec3 n = mapped.x * tangent + mapped.y * bitangent + mapped.z * s.shading_normal;
    if (glm::dot(n, n) > 0) s.shading_normal = n / std::sqrt(glm::dot(n, n));
  }
  return s;
}

}  // namespace vkray::cpu
