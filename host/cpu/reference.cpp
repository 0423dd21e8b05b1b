#include "cpu/reference.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <numbers>
#include <thread>

#include "base/errors.h"
#include "base/interrupt.h"
#include "bvh/bvh.h"
#include "scene/camera.h"
#include "shared/types.h"
#include "shared/sampling.h"

namespace vkray::cpu {
namespace {

using glm::dvec3;

// Determinant of the 3x3 matrix with columns a, b, c.
double det3(dvec3 a, dvec3 b, dvec3 c) {
  return a.x * (b.y * c.z - b.z * c.y) - b.x * (a.y * c.z - a.z * c.y) + c.x * (a.y * b.z - a.z * b.y);
}

struct Ray {
  dvec3 origin;
  dvec3 dir;  // unit length
};

struct Hit {
  double t;
  int primitive;   // triangle index, then sphere index + triangle count; -1 for none
  double u = 0, v = 0;  // barycentrics of a triangle hit: x = v0 + u e1 + v e2
};

class Tracer {
 public:
  Tracer(const Scene& scene, const Bvh* bvh, bool shadows)
      : scene_(scene), bvh_(bvh), shadows_(shadows), epsilon_(scene.epsilon()) {}

  // Closest intersection with t in (t_min, t_max); with any_hit, the first one found.
  Hit closest(const Ray& ray, double t_min, double t_max, bool any_hit = false) const {
    Hit best{t_max, -1};
    const size_t count = scene_.triangles.size() + scene_.spheres.size();
    if (!bvh_) {
      for (size_t p = 0; p < count && !(any_hit && best.primitive >= 0); ++p) test(ray, p, t_min, t_max, best);
      return best;
    }
    if (bvh_->nodes.empty()) return best;
    // 1 / d with zero components replaced by tiny ones, so a slab test never computes 0 * inf.
    dvec3 inv;
    for (int a = 0; a < 3; ++a) inv[a] = (ray.dir[a] < 0 ? -1.0 : 1.0) / std::max(std::abs(ray.dir[a]), 1e-300);
    visit(0, ray, inv, t_min, t_max, any_hit, best);
    return best;
  }

  // Radiance along one camera ray; records what it saw into `signature`.
  dvec3 radiance(const Ray& ray, uint64_t& signature, uint64_t& rays) const {
    const Hit hit = closest(ray, epsilon_, std::numeric_limits<double>::infinity());
    mix(signature, uint64_t(int64_t(hit.primitive)));
    if (hit.primitive < 0) return dvec3(scene_.background);

    const dvec3 x = ray.origin + hit.t * ray.dir;
    dvec3 n;
    uint32_t material;
    dvec3 shading_n;
    if (size_t(hit.primitive) < scene_.triangles.size()) {
      const Triangle& tri = scene_.triangles[size_t(hit.primitive)];
      n = glm::normalize(glm::cross(dvec3(tri.v[1]) - dvec3(tri.v[0]), dvec3(tri.v[2]) - dvec3(tri.v[0])));
      shading_n = n;
      if (tri.smooth)
        shading_n = glm::normalize((1 - hit.u - hit.v) * dvec3(tri.normals[0]) + hit.u * dvec3(tri.normals[1]) +
                                   hit.v * dvec3(tri.normals[2]));
      material = tri.material;
    } else {
      const Sphere& s = scene_.spheres[size_t(hit.primitive) - scene_.triangles.size()];
      n = (x - dvec3(s.center)) / double(s.radius);
      shading_n = n;
      material = s.material;
    }
    if (glm::dot(n, ray.dir) > 0) {  // face the incoming ray, as the geometric normal decides
      n = -n;
      shading_n = -shading_n;
    }

    dvec3 irradiance(scene_.ambient);
    const dvec3 shadow_origin = x + epsilon_ * n;
    for (size_t l = 0; l < scene_.lights.size(); ++l) {
      const dvec3 light(scene_.lights[l].position);
      const dvec3 to_light = light - x;
      const double r2 = glm::dot(to_light, to_light);
      const double cos_theta = glm::dot(shading_n, to_light / std::sqrt(r2));
      // The light must stand more than epsilon above the plane of the normal: one on the surface
      // (or at x) lights nothing there.
      if (!(glm::dot(shading_n, to_light) > epsilon_)) continue;
      if (shadows_) {
        ++rays;
        const dvec3 shadow = light - shadow_origin;
        const double distance = glm::length(shadow);
        if (closest({shadow_origin, shadow / distance}, epsilon_, distance - epsilon_, true).primitive >= 0) continue;
      }
      mix(signature, 0x8000000000000000ull | l);
      irradiance += dvec3(scene_.lights[l].intensity) * (cos_theta / (std::numbers::pi * r2));
    }
    return dvec3(scene_.materials[material].albedo) * irradiance;
  }

  static void mix(uint64_t& h, uint64_t v) {  // FNV-1a over the 8 bytes of v
    for (int i = 0; i < 8; ++i) h = (h ^ ((v >> (8 * i)) & 0xff)) * 0x100000001b3ull;
  }

 private:
  // The largest t still worth testing: up to a tie with the best hit so far (VKRAY_TIE).
  static double limit(const Hit& best, double t_max) { return best.primitive < 0 ? t_max : best.t * (1 + VKRAY_TIE); }

  // Tests primitive p (in the scene's numbering) and keeps it in `best` if it is nearer, or ties
  // with it and comes first in the scene.
  void test(const Ray& ray, size_t p, double t_min, double t_max, Hit& best) const {
    Hit candidate{-1, int(p)};
    if (p < scene_.triangles.size())
      candidate.t = intersect_triangle(ray, scene_.triangles[p], t_min, limit(best, t_max), candidate.u, candidate.v);
    else
      candidate.t = intersect_sphere(ray, scene_.spheres[p - scene_.triangles.size()], t_min, limit(best, t_max));
    if (candidate.t < 0) return;
    if (best.primitive < 0 || candidate.t < best.t * (1 - VKRAY_TIE) || candidate.primitive < best.primitive) best = candidate;
  }

  // Whether the ray enters `box` before `t_max`, and where. Exit distances are padded by 1e-12
  // relative, so a flat box (an axis-aligned wall's) is never lost to rounding.
  static bool enters(const Aabb& box, const Ray& ray, const dvec3& inv, double t_min, double t_max, double& t_enter) {
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

  // Recursive descent, nearer child first. Returns true to stop (any_hit found one).
  bool visit(uint32_t node, const Ray& ray, const dvec3& inv, double t_min, double t_max, bool any_hit, Hit& best) const {
    const BvhNode& n = bvh_->nodes[node];
    double t_enter[2];
    const bool hit[2] = {enters(n.child[0], ray, inv, t_min, limit(best, t_max), t_enter[0]),
                         enters(n.child[1], ray, inv, t_min, limit(best, t_max), t_enter[1])};
    const int first = (hit[0] && hit[1] && t_enter[1] < t_enter[0]) ? 1 : 0;
    for (const int c : {first, 1 - first}) {
      if (!hit[c]) continue;
      const uint32_t link = n.link[c];
      if (is_leaf(link)) {
        for (uint32_t slot = leaf_first(link); slot < leaf_first(link) + leaf_count(link); ++slot) {
          test(ray, bvh_->order[slot], t_min, t_max, best);
          if (any_hit && best.primitive >= 0) return true;
        }
      } else if (visit(link, ray, inv, t_min, t_max, any_hit, best)) {
        return true;
      }
    }
    return false;
  }

  // The lecture's ray-triangle test: solve [-d, e1, e2] (t, u, v)^T = s - v0 by Cramer's rule and
  // accept u >= 0, v >= 0, u + v <= 1. Returns t, or -1.
  static double intersect_triangle(const Ray& ray, const Triangle& tri, double t_min, double t_max, double& u, double& v) {
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
  static double intersect_sphere(const Ray& ray, const Sphere& s, double t_min, double t_max) {
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

  const Scene& scene_;
  const Bvh* bvh_;  // null: brute force
  bool shadows_;
  double epsilon_;
};

}  // namespace

ReferenceResult render_reference(const Scene& scene, const ImageSettings& settings, const ReferenceOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  ReferenceResult result;
  result.image = Image(settings.width, settings.height);
  result.signatures.assign(size_t(settings.width) * settings.height, 0);

  Bvh built;
  if (options.use_bvh && !options.bvh) {
    built = build_bvh(primitive_boxes(scene), options.threads);  // --threads holds for the build too
    result.bvh_seconds = built.build_seconds;
  }
  const Bvh* bvh = options.use_bvh ? (options.bvh ? options.bvh : &built) : nullptr;
  const Tracer tracer(scene, bvh, options.shadows);
  const CameraBasis cam = camera_basis(scene.camera, settings.height);
  const SampleStrata strata = sample_strata(settings.samples_per_pixel);
  const dvec3 origin(cam.origin), right(cam.right), up(cam.up), forward(cam.forward);
  const double half_w = settings.width / 2.0, half_h = settings.height / 2.0;

  std::atomic<uint32_t> next_row{0};
  std::atomic<uint64_t> total_rays{0};
  std::atomic<bool> cancelled{false};
  std::mutex progress_mutex;
  uint32_t rows_done = 0;
  auto worker = [&] {
    uint64_t rays = 0;
    for (uint32_t j; !cancelled && (j = next_row++) < settings.height;) {
      for (uint32_t i = 0; i < settings.width; ++i) {
        if (interrupt_requested()) {  // per pixel: a row of many samples can take seconds
          cancelled = true;
          break;
        }
        const uint32_t index = j * settings.width + i;
        uint64_t signature = 0xcbf29ce484222325ull;
        dvec3 sum(0.0);
        for (uint32_t k = 0; k < settings.samples_per_pixel; ++k) {
          const glm::vec2 xi = gpu::sample_offset(index, k, settings.samples_per_pixel, strata.x, strata.inv_x, strata.inv_y);
          const double x = i + double(xi.x) - half_w, y = half_h - (j + double(xi.y));
          const dvec3 d = glm::normalize(x * right + y * up + double(cam.focal_px) * forward);
          ++rays;
          sum += tracer.radiance({origin, d}, signature, rays);
        }
        result.image.pixels[index] = glm::vec3(sum / double(settings.samples_per_pixel));
        result.signatures[index] = signature;
      }
      if (options.progress && !cancelled) {
        std::lock_guard lock(progress_mutex);
        options.progress(++rows_done, settings.height);
      }
    }
    total_rays += rays;
  };

  const unsigned threads = options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  std::vector<std::jthread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  pool.clear();  // joins
  if (cancelled) throw Cancelled();

  result.rays = total_rays;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace vkray::cpu
