#include "embree/embree_tracer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include <embree3/rtcore.h>

#include "base/errors.h"
#include "scene/camera.h"

namespace vkray::bench {

struct EmbreeTracer::State {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<RTCScene> meshes;  // one per Scene::meshes, which the scene's instance geometries place
  ~State() {
    if (scene) rtcReleaseScene(scene);
    for (RTCScene mesh : meshes) rtcReleaseScene(mesh);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

// Attaches a triangle geometry of `triangles` to `scene`.
void attach_triangles(RTCDevice device, RTCScene scene, const std::vector<Triangle>& triangles) {
  if (triangles.empty()) return;
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), 3 * triangles.size()));
  auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(unsigned), triangles.size()));
  for (size_t i = 0; i < triangles.size(); ++i)
    for (size_t k = 0; k < 3; ++k) {
      for (int c = 0; c < 3; ++c) vertices[9 * i + 3 * k + size_t(c)] = triangles[i].v[k][c];
      indices[3 * i + k] = unsigned(3 * i + k);
    }
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene, geometry);
  rtcReleaseGeometry(geometry);
}

}  // namespace

EmbreeTracer::EmbreeTracer(const Scene& scene, unsigned threads) : state_(std::make_unique<State>()), scene_(scene) {
  const std::string config = "threads=" + std::to_string(threads);  // the build's threads, as vkray's
  state_->device = rtcNewDevice(config.c_str());
  if (!state_->device) throw DeviceError("Embree: rtcNewDevice failed");
  const auto start = std::chrono::steady_clock::now();
  state_->scene = rtcNewScene(state_->device);
  attach_triangles(state_->device, state_->scene, scene.triangles);
  // Meshes placed by instances: one scene each, placed by Embree's instance geometries (one level).
  for (const SharedMesh& mesh : scene.meshes) {
    RTCScene& placed = state_->meshes.emplace_back(rtcNewScene(state_->device));
    attach_triangles(state_->device, placed, mesh.triangles);
    rtcCommitScene(placed);
  }
  for (const Instance& instance : scene.instances) {
    RTCGeometry geometry = rtcNewGeometry(state_->device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(geometry, state_->meshes[instance.mesh]);
    rtcSetGeometryTransform(geometry, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &instance.to_world[0][0]);
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(state_->scene, geometry);
    rtcReleaseGeometry(geometry);
  }
  if (!scene.spheres.empty()) {
    RTCGeometry geometry = rtcNewGeometry(state_->device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    auto* points = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                                               4 * sizeof(float), scene.spheres.size()));
    for (size_t i = 0; i < scene.spheres.size(); ++i) {
      for (int c = 0; c < 3; ++c) points[4 * i + size_t(c)] = scene.spheres[i].center[c];
      points[4 * i + 3] = scene.spheres[i].radius;
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(state_->scene, geometry);
    rtcReleaseGeometry(geometry);
  }
  rtcCommitScene(state_->scene);
  build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (rtcGetDeviceError(state_->device) != RTC_ERROR_NONE) throw DeviceError("Embree: scene build failed");
}

EmbreeTracer::~EmbreeTracer() = default;

const char* EmbreeTracer::version() { return RTC_VERSION_STRING; }

EmbreeTracer::Result EmbreeTracer::trace(uint32_t width, uint32_t height, bool shadows, unsigned threads) const {
  const CameraBasis cam = camera_basis(scene_.camera, height);
  const float epsilon = scene_.epsilon();
  const uint32_t packets_x = (width + 3) / 4, packets_y = (height + 1) / 2;
  std::atomic<uint32_t> next{0};
  std::atomic<uint64_t> total_rays{0}, total_hits{0};
  RTCScene scene = state_->scene;

  auto worker = [&] {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    alignas(32) RTCRayHit8 primary;
    alignas(32) RTCRay8 shadow;
    alignas(32) int valid[8];
    alignas(32) int shadow_valid[8];
    uint64_t rays = 0, hits = 0;
    for (uint32_t packet; (packet = next++) < packets_x * packets_y;) {
      const uint32_t px = (packet % packets_x) * 4, py = (packet / packets_x) * 2;
      for (int lane = 0; lane < 8; ++lane) {
        const uint32_t i = px + uint32_t(lane % 4), j = py + uint32_t(lane / 4);
        valid[lane] = (i < width && j < height) ? -1 : 0;
        const float x = (float(i) + 0.5f) - 0.5f * float(width), y = 0.5f * float(height) - (float(j) + 0.5f);
        const glm::vec3 d = glm::normalize(x * cam.right + y * cam.up + cam.focal_px * cam.forward);
        primary.ray.org_x[lane] = cam.origin.x;
        primary.ray.org_y[lane] = cam.origin.y;
        primary.ray.org_z[lane] = cam.origin.z;
        primary.ray.dir_x[lane] = d.x;
        primary.ray.dir_y[lane] = d.y;
        primary.ray.dir_z[lane] = d.z;
        primary.ray.tnear[lane] = epsilon;
        primary.ray.tfar[lane] = std::numeric_limits<float>::infinity();
        primary.ray.time[lane] = 0;
        primary.ray.mask[lane] = ~0u;
        primary.ray.id[lane] = 0;
        primary.ray.flags[lane] = 0;
        primary.hit.geomID[lane] = RTC_INVALID_GEOMETRY_ID;
        primary.hit.instID[0][lane] = RTC_INVALID_GEOMETRY_ID;
        rays += valid[lane] != 0;
      }
      rtcIntersect8(valid, scene, &context, &primary);
      for (int lane = 0; lane < 8; ++lane) hits += valid[lane] && primary.hit.geomID[lane] != RTC_INVALID_GEOMETRY_ID;
      if (!shadows) continue;
      for (const Light& light : scene_.lights) {
        for (int lane = 0; lane < 8; ++lane) {
          shadow_valid[lane] = 0;
          if (!valid[lane] || primary.hit.geomID[lane] == RTC_INVALID_GEOMETRY_ID) continue;
          const glm::vec3 d(primary.ray.dir_x[lane], primary.ray.dir_y[lane], primary.ray.dir_z[lane]);
          const glm::vec3 x = cam.origin + primary.ray.tfar[lane] * d;
          glm::vec3 n = glm::normalize(glm::vec3(primary.hit.Ng_x[lane], primary.hit.Ng_y[lane], primary.hit.Ng_z[lane]));
          if (glm::dot(n, d) > 0) n = -n;
          // A directional light's shadow ray goes on past the scene; any other's stops at the light.
          const bool directional = light.type == Light::Type::directional;
          if (!(glm::dot(n, directional ? -light.direction : light.position - x) > 0)) continue;
          const glm::vec3 origin = x + epsilon * n;
          const glm::vec3 to_light = directional ? -light.direction : light.position - origin;
          const float distance = directional ? 1.0f : glm::length(to_light);
          shadow.org_x[lane] = origin.x;
          shadow.org_y[lane] = origin.y;
          shadow.org_z[lane] = origin.z;
          shadow.dir_x[lane] = to_light.x / distance;
          shadow.dir_y[lane] = to_light.y / distance;
          shadow.dir_z[lane] = to_light.z / distance;
          shadow.tnear[lane] = epsilon;
          shadow.tfar[lane] = directional ? std::numeric_limits<float>::infinity() : distance - epsilon;
          shadow.time[lane] = 0;
          shadow.mask[lane] = ~0u;
          shadow.id[lane] = 0;
          shadow.flags[lane] = 0;
          shadow_valid[lane] = -1;
          ++rays;
        }
        rtcOccluded8(shadow_valid, scene, &context, &shadow);
      }
    }
    total_rays += rays;
    total_hits += hits;
  };

  const auto start = std::chrono::steady_clock::now();
  std::vector<std::jthread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  pool.clear();
  Result result;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.rays = total_rays;
  result.hits = total_hits;
  return result;
}

}  // namespace vkray::bench
