// The environment map (Mitsuba's `envmap`): the radiance a ray that leaves the scene brings, and
// directions drawn in proportion to it, as pbrt-v4's image infinite light and Mitsuba's envmap draw
// them: a texel by the map's luminance times sin(theta) (two inversions of cumulative sums, rows then
// the row's texels), a point uniform in it, and that point of (u, v) as a direction. Texel layout
// and orientation: shared/scene_layout.h ("The environment map").
#ifndef VKRAY_ENVIRONMENT_GLSL
#define VKRAY_ENVIRONMENT_GLSL

#include "resources.glsl"
#include "shared/sampling.h"
#include "warp.glsl"

// ---- Directions and the map's texels ---------------------------------------------------------------
// The texel a world direction (unit) looks at, and the sine of its polar angle in the map's frame.
struct EnvironmentTexel {
  int index;
  float sin_theta;
};

EnvironmentTexel environment_texel(vec3 dir) {
  vec3 d = vec3(dot(frame.environment_row0.xyz, dir), dot(frame.environment_row1.xyz, dir), dot(frame.environment_row2.xyz, dir));
  float u = atan(d.x, -d.z) * (0.5 / PI);
  u = u < 0.0 ? u + 1.0 : u;
  // The polar angle from both of its sides, as Mitsuba's safe form: acos(y) and sqrt(1 - y^2) lose
  // their precision near the poles, where y rounds to 1.
  float sin_theta = length(d.xz);
  float v = atan(sin_theta, d.y) * (1.0 / PI);
  uint x = min(uint(u * float(frame.environment_width)), frame.environment_width - 1u);
  uint y = min(uint(v * float(frame.environment_height)), frame.environment_height - 1u);
  return EnvironmentTexel(int(y * frame.environment_width + x), sin_theta);
}

// The radiance from direction `dir`, and the density per unit solid angle with which
// sample_environment draws it: the texel's density per unit area of (u, v) over the 2 pi^2 sin(theta)
// that a unit of (u, v) covers of the sphere there (0 at the poles, where that is 0).
struct EnvironmentLookup {
  vec3 radiance;
  float pdf;
};

EnvironmentLookup environment_lookup(vec3 dir) {
  EnvironmentTexel t = environment_texel(dir);
  vec4 texel = texelFetch(environment, t.index);
  return EnvironmentLookup(texel.rgb, t.sin_theta > 0.0 ? texel.w / (2.0 * PI * PI * t.sin_theta) : 0.0);
}

// What a ray that leaves the scene along `dir` brings: the map's radiance, or the constant background.
vec3 background_radiance(vec3 dir) { return SCENE_HAS_ENVIRONMENT ? environment_lookup(dir).radiance : frame.background.rgb; }

// ---- Drawing a direction -----------------------------------------------------------------------
// The first of `count` cumulative shares from `first` on that is above u (the last is 1, and u < 1):
// the interval u falls in, a share without weight never.
uint environment_interval(int first, uint count, float u) {
  uint lo = 0u, hi = count - 1u;
  while (lo < hi) {
    uint mid = (lo + hi) >> 1u;
    if (texelFetch(environment_cdf, first + int(mid)).x > u) hi = mid;
    else lo = mid + 1u;
  }
  return lo;
}

// Where u falls within interval i of the cumulative shares from `first` on, from 0 to 1.
float environment_offset(int first, uint i, float u) {
  float below = i == 0u ? 0.0 : texelFetch(environment_cdf, first + int(i) - 1).x;
  float above = texelFetch(environment_cdf, first + int(i)).x;
  return clamp((u - below) / (above - below), 0.0, 1.0);
}

struct EnvironmentSample {
  vec3 dir;        // unit, in the world
  vec3 radiance;   // from it
  float pdf;       // per unit solid angle; 0: none drawn (a pole)
};

// Draws two numbers from the stream.
EnvironmentSample sample_environment(inout uint stream) {
  float u_row = next_random(stream), u_column = next_random(stream);
  uint w = frame.environment_width, h = frame.environment_height;
  int marginal = int(VKRAY_ENVIRONMENT_MARGINAL_CDF(w, h));
  uint y = environment_interval(marginal, h, u_row);
  int row = int(VKRAY_ENVIRONMENT_ROW_CDF(w, y));
  uint x = environment_interval(row, w, u_column);
  float v = (float(y) + environment_offset(marginal, y, u_row)) / float(h);
  float u = (float(x) + environment_offset(row, x, u_column)) / float(w);
  // (u, v) as a direction of the map's frame (Mitsuba's envmap), then of the world (the frame's
  // rows are the rotation's inverse: its columns turn the other way).
  float theta = v * PI, phi = u * (2.0 * PI);
  float sin_theta = sin(theta);
  vec3 d = vec3(sin_theta * sin(phi), cos(theta), -sin_theta * cos(phi));
  vec3 dir = normalize(d.x * frame.environment_row0.xyz + d.y * frame.environment_row1.xyz + d.z * frame.environment_row2.xyz);
  vec4 texel = texelFetch(environment, int(y * w + x));
  return EnvironmentSample(dir, texel.rgb, sin_theta > 0.0 ? texel.w / (2.0 * PI * PI * sin_theta) : 0.0);
}

#endif
