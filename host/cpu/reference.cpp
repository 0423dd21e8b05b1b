#include "cpu/reference.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <numbers>
#include <thread>

#include "camera.h"
#include "../shaders/shared/sampling.h"

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
  int primitive;  // triangle index, then sphere index + triangle count; -1 for none
};

class Tracer {
 public:
  explicit Tracer(const Scene& scene) : scene_(scene), epsilon_(scene.epsilon()) {}

  // Closest intersection with t in (t_min, t_max).
  Hit closest(const Ray& ray, double t_min, double t_max) const {
    Hit best{t_max, -1};
    for (size_t i = 0; i < scene_.triangles.size(); ++i) {
      const double t = intersect_triangle(ray, scene_.triangles[i], t_min, best.t);
      if (t >= 0) best = {t, int(i)};
    }
    for (size_t i = 0; i < scene_.spheres.size(); ++i) {
      const double t = intersect_sphere(ray, scene_.spheres[i], t_min, best.t);
      if (t >= 0) best = {t, int(scene_.triangles.size() + i)};
    }
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
    if (size_t(hit.primitive) < scene_.triangles.size()) {
      const Triangle& tri = scene_.triangles[size_t(hit.primitive)];
      n = glm::normalize(glm::cross(dvec3(tri.v[1]) - dvec3(tri.v[0]), dvec3(tri.v[2]) - dvec3(tri.v[0])));
      material = tri.material;
    } else {
      const Sphere& s = scene_.spheres[size_t(hit.primitive) - scene_.triangles.size()];
      n = (x - dvec3(s.center)) / double(s.radius);
      material = s.material;
    }
    if (glm::dot(n, ray.dir) > 0) n = -n;  // face the incoming ray

    dvec3 irradiance(scene_.ambient);
    const dvec3 shadow_origin = x + epsilon_ * n;
    for (size_t l = 0; l < scene_.lights.size(); ++l) {
      const dvec3 light(scene_.lights[l].position);
      const dvec3 to_light = light - x;
      const double r2 = glm::dot(to_light, to_light);
      const double cos_theta = glm::dot(n, to_light / std::sqrt(r2));
      if (!(cos_theta > 0)) continue;
      ++rays;
      const dvec3 shadow = light - shadow_origin;
      const double distance = glm::length(shadow);
      if (closest({shadow_origin, shadow / distance}, epsilon_, distance - epsilon_).primitive >= 0) continue;
      mix(signature, 0x8000000000000000ull | l);
      irradiance += dvec3(scene_.lights[l].intensity) * (cos_theta / (std::numbers::pi * r2));
    }
    return dvec3(scene_.materials[material].albedo) * irradiance;
  }

  static void mix(uint64_t& h, uint64_t v) {  // FNV-1a over the 8 bytes of v
    for (int i = 0; i < 8; ++i) h = (h ^ ((v >> (8 * i)) & 0xff)) * 0x100000001b3ull;
  }

 private:
  // The lecture's ray-triangle test: solve [-d, e1, e2] (t, u, v)^T = s - v0 by Cramer's rule and
  // accept u >= 0, v >= 0, u + v <= 1. Returns t, or -1.
  static double intersect_triangle(const Ray& ray, const Triangle& tri, double t_min, double t_max) {
    const dvec3 v0(tri.v[0]);
    const dvec3 e1 = dvec3(tri.v[1]) - v0, e2 = dvec3(tri.v[2]) - v0, b = ray.origin - v0;
    const double det = det3(-ray.dir, e1, e2);
    if (det == 0) return -1;  // parallel to the plane, or degenerate
    const double u = det3(-ray.dir, b, e2) / det;
    const double v = det3(-ray.dir, e1, b) / det;
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
  double epsilon_;
};

}  // namespace

ReferenceResult render_reference(const Scene& scene, const ImageSettings& settings, const ReferenceOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  ReferenceResult result;
  result.image = Image(settings.width, settings.height);
  result.signatures.assign(size_t(settings.width) * settings.height, 0);

  const Tracer tracer(scene);
  const CameraBasis cam = camera_basis(scene.camera, settings.height);
  const SampleStrata strata = sample_strata(settings.samples_per_pixel);
  const dvec3 origin(cam.origin), right(cam.right), up(cam.up), forward(cam.forward);
  const double half_w = settings.width / 2.0, half_h = settings.height / 2.0;

  std::atomic<uint32_t> next_row{0};
  std::atomic<uint64_t> total_rays{0};
  std::mutex progress_mutex;
  uint32_t rows_done = 0;
  auto worker = [&] {
    uint64_t rays = 0;
    for (uint32_t j; (j = next_row++) < settings.height;) {
      for (uint32_t i = 0; i < settings.width; ++i) {
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
      if (options.progress) {
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

  result.rays = total_rays;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace vkray::cpu
