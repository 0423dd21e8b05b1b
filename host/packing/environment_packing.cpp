#include "packing/environment_packing.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "shared/scene_layout.h"

namespace vkray::gpu {

float brightest_texel(const Environment& environment) {
  const std::vector<glm::vec3>& pixels = environment.radiance->pixels;
  return tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, pixels.size(), 1 << 16), 0.0f,
      [&](const tbb::blocked_range<size_t>& r, float m) {
        for (size_t i = r.begin(); i < r.end(); ++i) m = std::max({m, pixels[i].r, pixels[i].g, pixels[i].b});
        return m;
      },
      [](float a, float b) { return std::max(a, b); });
}

PackedEnvironment pack_environment(const Environment& environment, int radiance_exponent) {
  const Image& map = *environment.radiance;
  const uint32_t w = map.width, h = map.height;
  PackedEnvironment packed;
  packed.texels.resize(size_t(w) * h);
  packed.cdf.resize(size_t(w) * h + h);
  // Each texel's weight (luminance times sin(theta) at its row's centre), summed along its row in
  // double; the density and the shares once the total is known.
  std::vector<double> row_weight(h);
  tbb::parallel_for(tbb::blocked_range<uint32_t>(0, h), [&](const tbb::blocked_range<uint32_t>& rows) {
    for (uint32_t y = rows.begin(); y < rows.end(); ++y) {
      const double sin_theta = std::sin(M_PI * (y + 0.5) / h);
      double sum = 0.0;
      for (uint32_t x = 0; x < w; ++x) {
        const glm::vec3& l = map.at(x, y);
        sum += double(emission_luminance(l)) * sin_theta;
        // Times 2^radiance_exponent, exactly (shared/types.h).
        packed.texels[size_t(y) * w + x] = glm::vec4(std::ldexp(l.r, radiance_exponent), std::ldexp(l.g, radiance_exponent),
                                                     std::ldexp(l.b, radiance_exponent), 0.0f);
      }
      row_weight[y] = sum;
    }
  });
  std::vector<double> rows_to(h);  // the weight of rows 0 to y
  double total = 0.0;
  for (uint32_t y = 0; y < h; ++y) rows_to[y] = total += row_weight[y];
  if (!(total > 0.0)) return {};
  float* marginal = &packed.cdf[VKRAY_ENVIRONMENT_MARGINAL_CDF(size_t(w), h)];
  for (uint32_t y = 0; y < h; ++y) marginal[y] = float(rows_to[y] / total);
  marginal[h - 1] = 1.0f;
  const double mean = total / (double(w) * h);
  tbb::parallel_for(tbb::blocked_range<uint32_t>(0, h), [&](const tbb::blocked_range<uint32_t>& rows) {
    for (uint32_t y = rows.begin(); y < rows.end(); ++y) {
      const double sin_theta = std::sin(M_PI * (y + 0.5) / h);
      float* cdf = &packed.cdf[VKRAY_ENVIRONMENT_ROW_CDF(size_t(w), y)];
      double sum = 0.0;
      for (uint32_t x = 0; x < w; ++x) {
        const double weight = double(emission_luminance(map.at(x, y))) * sin_theta;
        sum += weight;
        // A row without weight is never picked; equal shares keep its numbers finite.
        cdf[x] = row_weight[y] > 0.0 ? float(sum / row_weight[y]) : float(double(x + 1) / w);
        packed.texels[size_t(y) * w + x].w = float(weight / mean);
      }
      cdf[w - 1] = 1.0f;
    }
  });
  packed.width = w;
  packed.height = h;
  return packed;
}

}  // namespace vkray::gpu
