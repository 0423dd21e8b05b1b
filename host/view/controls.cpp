#include "view/controls.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <glm/gtc/matrix_transform.hpp>

#include "scene/camera.h"

namespace vkray::view {
namespace {

// Rotates v about the unit axis by `radians` (Rodrigues).
glm::vec3 rotate(glm::vec3 v, glm::vec3 axis, float radians) {
  const float c = std::cos(radians), s = std::sin(radians);
  return v * c + glm::cross(axis, v) * s + axis * glm::dot(axis, v) * (1.0f - c);
}

// The shortest decimal that reads back as the same float (9 significant digits always do).
std::string number(float v) {
  char text[32];
  for (int digits = 6; digits <= 9; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, double(v));
    if (std::strtof(text, nullptr) == v) break;
  }
  return text;
}

}  // namespace

Steps steps_for(const Scene& scene) {
  Steps steps;
  // The Cornell box's extent is 3 (its camera at z = -3): a press moves 0.075, the lab's pace.
  const float extent = std::max(scene.extent(), 1e-6f);
  steps.move = 0.025f * extent;
  return steps;
}

Frame camera_frame(const Camera& camera) {
  const CameraBasis basis = camera_basis(camera, 1);
  return {basis.right, basis.up, basis.forward};
}

void move_camera(Camera& camera, float distance) { camera.position += camera.forward * distance; }

void turn_camera(Camera& camera, float radians) {
  // A yaw about the scene's up (the camera's "up" setting), as the lab's camera turns about y: the
  // view keeps its elevation. Positive swings it toward the image's right (right = forward x up).
  camera.forward = glm::normalize(rotate(camera.forward, glm::normalize(camera.up), -radians));
}

bool move_light(Light& light, const Camera& camera, glm::vec3 steps, float step) {
  if (light.type == Light::Type::directional) return false;
  const Frame frame = camera_frame(camera);
  light.position += (frame.right * steps.x + frame.up * steps.y + frame.forward * steps.z) * step;
  return true;
}

void orbit(Camera& camera, float distance, float yaw, float pitch) {
  const glm::vec3 pivot = camera.position + camera.forward * distance;
  // Yaw about the scene's up (the camera's own "up" setting), so that the horizon stays level.
  const glm::vec3 world_up = glm::normalize(camera.up);
  glm::vec3 forward = rotate(camera.forward, world_up, -yaw);
  // Pitch about the new right, held short of the poles.
  const glm::vec3 right = glm::normalize(glm::cross(forward, world_up));
  const float limit = glm::radians(89.0f);
  const float elevation = std::asin(std::clamp(glm::dot(forward, world_up), -1.0f, 1.0f));
  const float new_elevation = std::clamp(elevation + pitch, -limit, limit);
  forward = rotate(forward, right, new_elevation - elevation);
  camera.forward = glm::normalize(forward);
  camera.position = pivot - camera.forward * distance;
}

void pan(Camera& camera, float distance, glm::vec2 pixels, uint32_t image_height) {
  const Frame frame = camera_frame(camera);
  // A pixel at the pivot's distance spans distance / focal_px scene units; the scene follows the
  // mouse, so the camera moves the other way.
  const float per_pixel = distance / (camera.focal_length * float(std::max(image_height, 1u)));
  camera.position += (-frame.right * pixels.x + frame.up * pixels.y) * per_pixel;
}

float zoom(Camera& camera, float distance, float notches, float closest) {
  const float new_distance = std::max(distance * std::pow(0.9f, notches), std::min(closest, distance));
  camera.position += camera.forward * (distance - new_distance);
  return new_distance;
}

glm::vec3 settle(Camera& camera, float distance) {
  glm::vec3 look_at = camera.position + camera.forward * distance;
  // A point too close to tell from the position (a zero distance, or below its float spacing)
  // gives no direction: look one unit ahead instead.
  if (!(glm::length(look_at - camera.position) > 0.0f)) look_at = camera.position + camera.forward;
  camera.forward = unit_direction(look_at - camera.position);  // as the scene parser computes it
  return look_at;
}

std::string point_json(glm::vec3 p) { return "[" + number(p.x) + ", " + number(p.y) + ", " + number(p.z) + "]"; }

std::string camera_json(const Camera& camera, glm::vec3 look_at) {
  std::string json = "\"camera\": {\"position\": " + point_json(camera.position) + ", \"look_at\": " + point_json(look_at) +
                     ", \"up\": " + point_json(camera.up) + ", \"focal_length\": " + number(camera.focal_length);
  if (camera.aperture_radius > 0.0f)
    json += ", \"aperture_radius\": " + number(camera.aperture_radius) + ", \"focus_distance\": " + number(camera.focus_distance);
  return json + "}";
}

}  // namespace vkray::view
