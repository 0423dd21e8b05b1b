// vkray's tracer: one invocation per pixel of the current tile. For each sample: camera ray ->
// radiance (the direct model, direct.glsl, or paths, path.glsl) -> average -> store linear radiance,
// and the first-hit passes when asked for (aovs.glsl).
#version 460
#extension GL_GOOGLE_include_directive : require

#include "shared/sampling.h"
#include "shared/types.h"
#include "aovs.glsl"
#include "camera.glsl"
#include "resources.glsl"
#include "direct.glsl"
#include "path.glsl"
#include "traversal.glsl"

layout(local_size_x = VKRAY_WORKGROUP_X, local_size_y = VKRAY_WORKGROUP_Y, local_size_z = 1) in;

layout(push_constant) uniform Tile { TileConstants tile; };
layout(std430, set = 0, binding = VKRAY_BINDING_OUTPUT) buffer Output { vec4 radiance[]; };

// Camera ray k of a pixel, through the lens when there is one, and the sample's random stream.
Ray camera_sample(uvec2 pixel, uint pixel_index, uint k, out uint stream) {
  // Paths jitter even a single sample: at the pixel centre it would sharpen the image.
  vec2 xi = PATH_TRACING ? jittered_offset(pixel_index, frame.seed_key, k, frame.strata_x, frame.inv_strata_x, frame.inv_strata_y)
                         : sample_offset(pixel_index, frame.seed_key, k, frame.samples_per_pixel, frame.strata_x,
                                         frame.inv_strata_x, frame.inv_strata_y);
  Ray ray = camera_ray(pixel, xi);
  stream = sample_stream(pixel_index, frame.seed_key, k);
  first_sample = k == 0u;
  if (frame.aperture_radius > 0.0) ray = lens_ray(ray, vec2(next_random(stream), next_random(stream)));
  return ray;
}

// llvmpipe ends every loop of an invocation early, without a word, once the invocation has made
// 65535 loop iterations in all (host/gpu/renderer.cpp). A loop that must run twice tells: past the
// limit it runs once. (Its count comes from the host, so that the compiler cannot unroll it.) Run
// after each sample; if the limit ends the sample loop instead, k falls short of sample_end.
void probe_loop_limit(inout uint rays) {
  uint probe = 0u;
  do {
    ++probe;
  } while (probe < tile.probe_iterations);
  if (probe < tile.probe_iterations) rays |= VKRAY_LOOPS_CUT_SHORT;
}

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
  // The mean of the samples, each weighed by 1 / spp as it comes (not the sum, divided at the end,
  // which a bright pixel of many samples could take past the largest float).
  vec3 sum = vec3(0.0);
  uint rays = 0u;
  if (tile.sample_begin > 0u) {  // an earlier dispatch's running sum (TileConstants::sample_begin)
    vec4 so_far = radiance[index];
    sum = so_far.rgb;
    rays = floatBitsToUint(so_far.a);
  }
  if (FIRST_HIT_PASSES) load_first_hits(index, tile.sample_begin > 0u);
  uint k = tile.sample_begin;
  if (PATH_TRACING) {
    // One loop over the vertices of all the pixel's samples: a lane whose path ends starts its next
    // sample at once, so lanes do not wait, masked, for the longest path among them (path.glsl).
    uint stream;
    PathState path = start_path(camera_sample(pixel, pixel_index, k, stream));
    rays += 1u;
    do {
      if (path_step(path, stream, rays)) {
        sum += path.radiance * frame.inv_samples_per_pixel;
        probe_loop_limit(rays);
        if (++k < tile.sample_end) {
          path = start_path(camera_sample(pixel, pixel_index, k, stream));
          rays += 1u;
        }
      }
    } while (k < tile.sample_end);
  } else {
    do {
      uint stream;
      Ray ray = camera_sample(pixel, pixel_index, k, stream);
      rays += 1u;
      sum += direct_radiance(ray, stream, rays) * frame.inv_samples_per_pixel;
      probe_loop_limit(rays);
    } while (++k < tile.sample_end);
  }
  if (k < tile.sample_end) rays |= VKRAY_LOOPS_CUT_SHORT;
  // Alpha carries the number of rays traced for this pixel (bit pattern of a uint) for the rays/s
  // figure, and VKRAY_LOOPS_CUT_SHORT.
  radiance[index] = vec4(sum, uintBitsToFloat(rays));
  if (FIRST_HIT_PASSES) store_first_hits(index);
}
