// How `vkray view`'s keys and mouse move the camera and the first light: the lecture lab's keys
// (W/S, A/D, Q/E move the light forward/back, left/right, up/down in the camera's frame; the arrow
// keys move the camera forward/back and turn it) and an orbit camera (orbit, pan and zoom about a
// point ahead of it). Plain functions on scene values, so that tests check them without a window.
#pragma once

#include <string>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace vkray::view {

// The sizes of one key press, from the scene's extent, so that the Cornell box and a city both move
// at a pace that shows.
struct Steps {
  float move = 0.1f;                   // scene units a press moves the camera or the light
  float turn = glm::radians(3.0f);     // radians a press turns the camera
  float orbit = glm::radians(0.25f);   // radians a pixel of mouse drag orbits
};
Steps steps_for(const Scene& scene);

// The camera's own frame, as the renderers build it (scene/camera.h): right, the image's up, forward.
struct Frame {
  glm::vec3 right, up, forward;
};
Frame camera_frame(const Camera& camera);

// Up/Down arrows: along the view direction.
void move_camera(Camera& camera, float distance);
// Left/Right arrows: about the camera's up (positive: to the right).
void turn_camera(Camera& camera, float radians);
// W/S, A/D, Q/E: the light moved by `steps` (right, up, forward) in the camera's frame, each times
// `step`. A directional light has no position: it is left as it is (returns false).
bool move_light(Light& light, const Camera& camera, glm::vec3 steps, float step);

// Left drag: the camera orbits the point `distance` ahead of it, turning by `yaw` about its up and
// `pitch` about its right (radians), still looking at that point. It stops short of looking straight
// along its up, where the frame would flip.
void orbit(Camera& camera, float distance, float yaw, float pitch);
// Right drag: the camera slides in its image plane by `pixels` (x right, y down) of an image
// `image_height` pixels high, as far as makes the point `distance` ahead follow the mouse.
void pan(Camera& camera, float distance, glm::vec2 pixels, uint32_t image_height);
// Wheel: the camera moves toward the point `distance` ahead, by 10% of the distance a notch (away
// from it for negative notches); returns the new distance, never below `closest`.

float zoom(Camera& camera, float distance, float notches, float closest);

// Sets the camera's view direction to the one a scene file with its position and look_at = position +
// forward * distance gives (unit_direction, scene/camera.h), and returns that look_at: written out
// by camera_json, the camera then reads back to the same bits, and `vkray render` renders the view.
glm::vec3 settle(Camera& camera, float distance);

// The camera as a scene file's "camera" object, to paste into one: position, look_at, up,
// focal_length (and the lens). Each number the shortest decimal that reads back as the same float.
std::string camera_json(const Camera& camera, glm::vec3 look_at);
// A point's coordinates the same way: "[x, y, z]".
std::string point_json(glm::vec3 p);

}  // namespace vkray::view
