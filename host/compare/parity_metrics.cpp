#include "compare/parity_metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

namespace vkray {
namespace {

int srgb_step_difference(glm::vec3 a, glm::vec3 b) {
  int worst = 0;
  for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(int(encode_srgb8(a[c])) - int(encode_srgb8(b[c]))));
  return worst;
}

bool on_edge(const std::vector<uint64_t>& s, uint32_t w, uint32_t h, uint32_t x, uint32_t y) {
  const uint64_t here = s[size_t(y) * w + x];
  return (x > 0 && s[size_t(y) * w + x - 1] != here) || (x + 1 < w && s[size_t(y) * w + x + 1] != here) ||
         (y > 0 && s[size_t(y - 1) * w + x] != here) || (y + 1 < h && s[size_t(y + 1) * w + x] != here);
}

// Display-space colour for t in [0, 1]: dark purple, red, orange, pale yellow.
glm::vec3 heat(double t) {
  static const glm::vec3 stops[] = {{0.20f, 0.02f, 0.35f}, {0.80f, 0.10f, 0.25f}, {1.0f, 0.55f, 0.05f}, {1.0f, 1.0f, 0.6f}};
  const double x = std::clamp(t, 0.0, 1.0) * 3.0;
  const int i = std::min(int(x), 2);
  return glm::mix(stops[i], stops[i + 1], float(x - i));
}

}  // namespace

ParityMetrics compare_images(const Image& gpu, const Image& reference, const std::vector<uint64_t>& signatures,
                             const ParityTolerance& tolerance) {
  ParityMetrics m;
  m.width = reference.width;
  m.height = reference.height;
  double sum_abs = 0, sum_sq = 0;
  glm::dvec3 sum_gpu(0.0), sum_reference(0.0);
  for (uint32_t y = 0; y < m.height; ++y) {
    for (uint32_t x = 0; x < m.width; ++x) {
      const glm::vec3 a = gpu.at(x, y), b = reference.at(x, y);
      m.non_finite += !(std::isfinite(a.r) && std::isfinite(a.g) && std::isfinite(a.b));
      sum_gpu += glm::dvec3(a);
      sum_reference += glm::dvec3(b);
      for (int c = 0; c < 3; ++c) {
        const double d = std::abs(double(a[c]) - double(b[c]));
        if (d > m.max_abs || std::isnan(d)) {
          m.max_abs = std::isnan(d) ? std::numeric_limits<double>::infinity() : d;
          m.worst_x = x;
          m.worst_y = y;
        }
        sum_abs += d;
        const double dc = std::clamp(double(a[c]), 0.0, 1.0) - std::clamp(double(b[c]), 0.0, 1.0);
        sum_sq += dc * dc;
      }
      const bool edge = on_edge(signatures, m.width, m.height, x, y);
      m.edge_pixels += edge;
      const int steps = srgb_step_difference(a, b);
      m.over_1 += steps > 1;
      m.over_2 += steps > 2;
      m.interior_over_1 += !edge && steps > 1;
      m.interior_over_2 += !edge && steps > 2;
      m.edge_over_1 += edge && steps > 1;
    }
  }
  const double samples = double(m.pixels()) * 3.0;
  m.mean_abs = sum_abs / samples;
  const double mse = sum_sq / samples;
  m.psnr = mse > 0 ? 10.0 * std::log10(1.0 / mse) : std::numeric_limits<double>::infinity();
  for (int c = 0; c < 3; ++c) {
    const double difference = std::abs(sum_gpu[c] - sum_reference[c]);
    if (difference > 0) m.mean_relative = std::max(m.mean_relative, difference / std::abs(sum_reference[c]));
  }
  if (m.non_finite > 0) m.mean_relative = std::numeric_limits<double>::infinity();
  if (tolerance.stochastic)
    m.pass = m.share_over_1() <= tolerance.max_share_over_1 && m.mean_relative <= tolerance.max_mean_relative;
  else
    m.pass = m.edge_share_over_1() <= tolerance.max_edge_share_over_1 && m.interior_over_1 <= tolerance.max_interior_over_1;
  m.pass = m.pass && m.non_finite == 0;
  return m;
}

void compare_aovs(const Aovs& gpu, const Aovs& reference, const std::vector<uint64_t>& signatures, double scene_extent,
                  const ParityTolerance& tolerance, ParityMetrics& m) {
  const double length_tolerance = 1e-4 * scene_extent;
  const auto close = [](glm::vec3 a, glm::vec3 b, double allowed) {
    for (int c = 0; c < 3; ++c)
      if (!(std::abs(double(a[c]) - double(b[c])) <= allowed)) return false;  // (a NaN is not close)
    return true;
  };
  m.aovs_compared = true;
  for (uint32_t y = 0; y < m.height; ++y)
    for (uint32_t x = 0; x < m.width; ++x) {
      const size_t i = size_t(y) * m.width + x;
      const float ref_albedo = std::max({1.0f, reference.albedo[i].r, reference.albedo[i].g, reference.albedo[i].b});
      const bool depth_agrees = std::isinf(reference.depth[i]) ? std::isinf(gpu.depth[i]) && gpu.depth[i] > 0
                                                               : std::abs(double(gpu.depth[i]) - reference.depth[i]) <= length_tolerance;
      // With textures, albedo is judged as the image is, by 8-bit sRGB steps (and relatively past 1,
      // where the encoding clips): it is then a function of the texture coordinate, which each
      // renderer interpolates with its own rounding.
      const bool albedo_differs = tolerance.textured ? srgb_step_difference(gpu.albedo[i], reference.albedo[i]) > 1 ||
                                                           !close(gpu.albedo[i], reference.albedo[i], 1e-2 * ref_albedo)
                                                     : !close(gpu.albedo[i], reference.albedo[i], 1e-4 * ref_albedo);
      const bool differs[kAllAovs.size()] = {
          albedo_differs, !close(gpu.normal[i], reference.normal[i], 1e-3),
          !close(gpu.position[i], reference.position[i], length_tolerance), !depth_agrees, gpu.object[i] != reference.object[i]};
      bool any = false;
      for (size_t pass = 0; pass < kAllAovs.size(); ++pass) {
        m.aov_differing_by_pass[pass] += differs[pass];
        any = any || differs[pass];
      }
      if (!any) continue;
      const bool edge = on_edge(signatures, m.width, m.height, x, y);
      ++m.aov_differing;
      m.aov_edge_differing += edge;
      m.aov_interior_differing += !edge;
    }
  // Camera rays are the same on both renderers (the same random numbers pick the same lens points),
  // so the passes are decided as a deterministic image's are, noisy scene or not: only a ray that
  // grazes an edge may see something else.
  const bool aovs_pass = m.aov_edge_share() <= tolerance.max_edge_share_over_1 &&
                         m.aov_interior_differing <= tolerance.max_interior_over_1;
  m.pass = m.pass && aovs_pass;
}

Image difference_heatmap(const Image& a, const Image& reference, int& max_steps) {
  max_steps = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) max_steps = std::max(max_steps, srgb_step_difference(a.pixels[i], reference.pixels[i]));
  Image heatmap(reference.width, reference.height);
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    const int steps = srgb_step_difference(a.pixels[i], reference.pixels[i]);
    glm::vec3 display;
    if (steps == 0) {  // a faint grey copy of the reference, for orientation
      const glm::vec3 r = reference.pixels[i];
      const float luminance = std::clamp(0.2126f * r.r + 0.7152f * r.g + 0.0722f * r.b, 0.0f, 1.0f);
      display = glm::vec3(0.05f + 0.2f * float(encode_srgb8(luminance)) / 255.0f);
    } else {
      display = heat(max_steps > 1 ? double(steps - 1) / double(max_steps - 1) : 0.0);
    }
    for (int c = 0; c < 3; ++c) heatmap.pixels[i][c] = decode_srgb8(uint8_t(std::lround(display[c] * 255.0f)));
  }
  return heatmap;
}

Image absolute_difference(const Image& a, const Image& b) {
  Image diff(b.width, b.height);
  for (size_t i = 0; i < b.pixels.size(); ++i) diff.pixels[i] = glm::abs(a.pixels[i] - b.pixels[i]);
  return diff;
}

std::string describe_tolerance(const ParityTolerance& t) {
  char text[200];
  if (t.stochastic) {
    std::snprintf(text, sizeof text,
                  "8-bit sRGB values differ by more than 1 on at most %.3g%% of the pixels, and the image means by at "
                  "most %.3g%% in each channel",
                  t.max_share_over_1 * 100.0, t.max_mean_relative * 100.0);
    return text;
  }
  std::snprintf(text, sizeof text,
                "8-bit sRGB values differ by more than 1 on at most %llu pixels away from silhouette and shadow edges, "
                "and on at most %.3g%% of the pixels on them",
                static_cast<unsigned long long>(t.max_interior_over_1), t.max_edge_share_over_1 * 100.0);
  return text;
}

std::string describe_metrics(const ParityMetrics& m) {
  char text[400];
  std::snprintf(text, sizeof text,
                "> 1 step on %llu pixels away from edges and on %llu of %llu edge pixels; > 2 steps on %llu; "
                "max |diff| %.3g at (%u, %u); means differ by %.2g%%",
                static_cast<unsigned long long>(m.interior_over_1), static_cast<unsigned long long>(m.edge_over_1),
                static_cast<unsigned long long>(m.edge_pixels), static_cast<unsigned long long>(m.over_2), m.max_abs,
                m.worst_x, m.worst_y, m.mean_relative * 100.0);
  std::string result = text;
  if (m.non_finite > 0) result += "; " + std::to_string(m.non_finite) + " GPU pixels are NaN or infinite";
  if (m.aovs_compared) {
    result += "; first-hit passes differ on " + std::to_string(m.aov_interior_differing) + " pixels away from edges and " +
              std::to_string(m.aov_edge_differing) + " on them";
    std::string which;
    for (size_t pass = 0; pass < kAllAovs.size(); ++pass)
      if (m.aov_differing_by_pass[pass] > 0)
        which += std::string(which.empty() ? "" : ", ") + aov_name(kAllAovs[pass]) + " " + std::to_string(m.aov_differing_by_pass[pass]);
    if (!which.empty()) result += " (" + which + ")";
  }
  return result;
}

}  // namespace vkray
