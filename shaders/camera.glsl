// Pinhole camera of the scene contract: pixel (i, j), j = 0 the top row, sample offset xi in [0,1)^2:
//   x = i + xi.x - W/2,  y = H/2 - (j + xi.y),  d = normalize(x r + y u + F f).
// With an aperture, the thin lens (Mitsuba's `thinlens`): the ray leaves a point of the lens disk
// for the point where the pinhole ray meets the plane of focus.
#ifndef VKRAY_CAMERA_GLSL
#define VKRAY_CAMERA_GLSL

#include "ray.glsl"
#include "resources.glsl"
#include "warp.glsl"

Ray camera_ray(uvec2 pixel, vec2 xi) {
  // `precise` forbids fusing these multiply-adds, so the ray matches the CPU's bit for bit on drivers
  // that would otherwise contract them into FMAs.
  precise float x = (float(pixel.x) + xi.x) - 0.5 * float(frame.width);
  precise float y = 0.5 * float(frame.height) - (float(pixel.y) + xi.y);
  precise vec3 d = x * frame.right.xyz + y * frame.up.xyz + frame.forward.w * frame.forward.xyz;
  return Ray(frame.origin.xyz, normalize(d));
}

// The pinhole ray moved onto the lens: u picks the point on the disk (concentric_disk).
Ray lens_ray(Ray pinhole, vec2 u) {
  vec3 focus = pinhole.origin + (frame.focus_distance / dot(pinhole.dir, frame.forward.xyz)) * pinhole.dir;
  vec2 disk = frame.aperture_radius * concentric_disk(u);
  vec3 origin = pinhole.origin + disk.x * frame.right.xyz + disk.y * frame.up.xyz;
  return Ray(origin, normalize(focus - origin));
}

#endif
