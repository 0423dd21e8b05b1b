// vkray's tracer: one invocation per pixel of the current tile. For each sample: camera ray ->
// radiance (the direct model, direct.glsl, or paths, path.glsl) -> average -> store linear radiance.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "shared/sampling.h"
#include "shared/types.h"
#include "camera.glsl"
#include "resources.glsl"
#include "direct.glsl"
#include "path.glsl"
#include "traversal.glsl"

layout(local_size_x = VKRAY_WORKGROUP_X, local_size_y = VKRAY_WORKGROUP_Y, local_size_z = 1) in;

layout(push_constant) uniform Tile { TileConstants tile; };
layout(std430, set = 0, binding = VKRAY_BINDING_OUTPUT) buffer Output { vec4 radiance[]; };

void main() {
  load_frame();
  // The workgroup's place in the tile: its row permuted (TileConstants::row_stride).
  uvec2 group = uvec2(gl_WorkGroupID.x, (gl_WorkGroupID.y * tile.row_stride) % gl_NumWorkGroups.y);
  uvec2 local = group * uvec2(VKRAY_WORKGROUP_X, VKRAY_WORKGROUP_Y) + gl_LocalInvocationID.xy;
  if (local.x >= tile.width || local.y >= tile.height) return;
  uvec2 pixel = uvec2(tile.x0, tile.y0) + local;
  uint pixel_index = pixel.y * frame.width + pixel.x;  // the sample pattern's: the same in any tile
  uint index = tile.output_offset + local.y * tile.width + local.x;  // in the tile's part of the output

  // The samples as a do-while: llvmpipe runs a loop's body until no lane is left in it, so a loop
  // that tests its condition first runs the whole body once more, masked, after the last iteration
  // (here a second camera ray's traversal and shading for every pixel; docs/design.md, "What the
  // time goes to"). sample_end > sample_begin.
  vec3 sum = vec3(0.0);
  uint rays = 0u;
  if (tile.sample_begin > 0u) {  // an earlier dispatch's running sum (TileConstants::sample_begin)
    vec4 so_far = radiance[index];
    sum = so_far.rgb;
    rays = floatBitsToUint(so_far.a);
  }
  uint k = tile.sample_begin;
  do {
    // Paths jitter even a single sample: at the pixel centre it would sharpen the image.
    vec2 xi = PATH_TRACING ? jittered_offset(pixel_index, frame.seed_key, k, frame.strata_x, frame.inv_strata_x, frame.inv_strata_y)
                           : sample_offset(pixel_index, frame.seed_key, k, frame.samples_per_pixel, frame.strata_x,
                                           frame.inv_strata_x, frame.inv_strata_y);
    Ray ray = camera_ray(pixel, xi);
    uint stream = sample_stream(pixel_index, frame.seed_key, k);
    if (frame.aperture_radius > 0.0) ray = lens_ray(ray, vec2(next_random(stream), next_random(stream)));
    rays += 1u;
    sum += PATH_TRACING ? path_radiance(ray, stream, rays) : direct_radiance(ray, stream, rays);
    // llvmpipe ends every loop of an invocation early, without a word, once the invocation has made
    // 65535 loop iterations in all (host/gpu/renderer.cpp). A loop that must run twice tells: past
    // the limit it runs once. (Its count comes from the host, so that the compiler cannot unroll
    // it.) If the limit ends the sample loop instead, k falls short of sample_end.
    uint probe = 0u;
    do {
      ++probe;
    } while (probe < tile.probe_iterations);
    if (probe < tile.probe_iterations) rays |= VKRAY_LOOPS_CUT_SHORT;
  } while (++k < tile.sample_end);
  if (k < tile.sample_end) rays |= VKRAY_LOOPS_CUT_SHORT;
  // Alpha carries the number of rays traced for this pixel (bit pattern of a uint) for the rays/s
  // figure, and VKRAY_LOOPS_CUT_SHORT.
  vec3 stored = tile.sample_end == frame.samples_per_pixel ? sum * frame.inv_samples_per_pixel : sum;
  radiance[index] = vec4(stored, uintBitsToFloat(rays));
}
