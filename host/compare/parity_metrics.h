// Comparing the GPU image with the CPU reference: metrics, the tolerance, and a heatmap a person
// can read at a glance.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "image/aovs.h"
#include "image/image.h"

namespace vkray {

// What may legitimately differ (docs/parity.md, "The tolerance"): a pixel whose samples straddle a
// silhouette or shadow edge can flip, since GPU and CPU decide a ray that grazes an edge with
// different rounding.
// Everywhere else the two agree to float precision, i.e. to within one step of 8-bit sRGB. The
// edge allowance is a share of edge pixels, not of all pixels: edges are lines, so their share of
// an image shrinks as its resolution grows, while the share of edge pixels that flip does not.
//
// A render that makes random decisions (paths, area lights, an environment map, glass, a lens:
// `stochastic`) traces the
// same samples on both, since the two draw the same random numbers; a sample whose path the two
// renderers' rounding sends different ways differs by a whole sample's worth of noise, wherever it
// is. Its tolerance is a share of all pixels instead, and the mean of the image, which such
// samples hardly move but any error in the light transport does (docs/parity.md, "Parity for noisy images").
struct ParityTolerance {
  bool stochastic = false;
  double max_edge_share_over_1 = 0.02;  // edge pixels whose 8-bit sRGB values differ by more than 1
  uint64_t max_interior_over_1 = 0;     // such pixels away from edges
  double max_share_over_1 = 0.005;      // stochastic: pixels differing by more than 1 step, of all
  double max_mean_relative = 0.002;     // stochastic: |mean GPU - mean CPU| / mean CPU, per channel
  // The albedo pass is exact but for float rounding (10^-4 of the value), unless a texture makes it
  // depend on the interpolated texture coordinate: then it is judged by 8-bit sRGB steps, as the image is.
  bool textured = false;
};

struct ParityMetrics {
  uint32_t width = 0, height = 0;
  double max_abs = 0;       // largest |GPU - CPU| over pixels and channels, linear radiance
  double mean_abs = 0;      // mean over pixels and channels, linear
  double psnr = 0;          // dB, of the images clamped to [0, 1] (what a PNG shows); infinite when equal
  uint64_t over_1 = 0;      // pixels whose 8-bit sRGB values differ by more than 1 (in any channel)
  uint64_t over_2 = 0;      //   ... by more than 2
  uint64_t edge_pixels = 0; // pixels on a silhouette or shadow edge (from the reference's signatures)
  uint64_t interior_over_1 = 0, interior_over_2 = 0;  // over_1 / over_2 away from edges
  uint64_t edge_over_1 = 0;                            // over_1 on edges
  uint32_t worst_x = 0, worst_y = 0;                   // where max_abs is
  double mean_relative = 0;  // largest over channels of |mean GPU - mean CPU| / mean CPU (0 when both are 0)
  uint64_t non_finite = 0;   // GPU pixels with a NaN or infinite channel: never within any tolerance
  // The first-hit passes (compare_aovs), judged as the image is: pixels where any pass differs beyond
  // float precision, by where they are, and per pass (in kAllAovs order).
  bool aovs_compared = false;
  uint64_t aov_differing = 0, aov_interior_differing = 0, aov_edge_differing = 0;
  std::array<uint64_t, kAllAovs.size()> aov_differing_by_pass{};
  bool pass = false;

  uint64_t pixels() const { return uint64_t(width) * height; }
  double share_over_1() const { return pixels() ? double(over_1) / double(pixels()) : 0; }
  double share_over_2() const { return pixels() ? double(over_2) / double(pixels()) : 0; }
  double edge_share_over_1() const { return edge_pixels ? double(edge_over_1) / double(edge_pixels) : 0; }
  double aov_share() const { return pixels() ? double(aov_differing) / double(pixels()) : 0; }
  double aov_edge_share() const { return edge_pixels ? double(aov_edge_differing) / double(edge_pixels) : 0; }
};

// `signatures` (one per pixel, from the CPU reference) mark edges: a pixel is on an edge when its
// signature differs from one of its 4 neighbours'.
ParityMetrics compare_images(const Image& gpu, const Image& reference, const std::vector<uint64_t>& signatures,
                             const ParityTolerance& tolerance = {});

// Adds the comparison of the first-hit passes to `metrics` (from compare_images, whose edges it
// uses) and judges it by the rule for a deterministic image (camera rays are the same on both
// renderers, even in a noisy render): a pass differs at a pixel where the
// object ids differ, or a value beyond float precision: 1e-4 of the value for albedo, 1e-3 for a
// normal, 1e-4 of `scene_extent` for position and depth (or one depth is infinite, the other not).
void compare_aovs(const Aovs& gpu, const Aovs& reference, const std::vector<uint64_t>& signatures, double scene_extent,
                  const ParityTolerance& tolerance, ParityMetrics& metrics);

// What a person can see: per pixel, the largest difference of the 8-bit sRGB values over the
// channels. 0 shows as a faint grey copy of `reference`; 1 step is dark purple, rising through red
// and orange to pale yellow at the largest difference in the image, returned in `max_steps`.
Image difference_heatmap(const Image& a, const Image& reference, int& max_steps);

// |a - b| per channel in linear radiance, for a quantitative look (written as PFM).
Image absolute_difference(const Image& a, const Image& b);

std::string describe_tolerance(const ParityTolerance& tolerance);
// "> 1 step on 2 pixels away from edges and on 3 of 2513 edge pixels; > 2 steps on 5; max |diff|
// 0.274 at (8, 8)": what the tolerance is judged on.
std::string describe_metrics(const ParityMetrics& metrics);

}  // namespace vkray
