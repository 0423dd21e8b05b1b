#include "packing/environment_packing.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "shared/scene_layout.h"

namespace vkray::gpu {

PackedEnvironment pack_environment(const Environment& environment, int radiance_exponent) {
  const Image& map = *environment.radiance;
  const uint32_t w = map.width, h = map.height;
  PackedEnvironment packed;
  packed.texels.resize(size_t(w) * h);
  packed.cdf.resize(size_t(w) * h + h);
  // One pass over the rows, on every core: each texel's radiance, times 2^radiance_exponent (exact:
  // a power of two, and the brightest texel is brought near 2^20), and its weight, luminance times
  // sin(theta) at its row's centre (kept in the texel's w for now), summed along the row in double;
  // the row's shares once its sum is known. Then the density, the weight over the mean.
  const float scale = std::ldexp(1.0f, radiance_exponent);
  std::vector<double> row_weight(h);
  tbb::parallel_for(tbb::blocked_range<uint32_t>(0, h), [&](const tbb::blocked_range<uint32_t>& rows) {
    for (uint32_t y = rows.begin(); y < rows.end(); ++y) {
      const double sin_theta = std::sin(M_PI * (y + 0.5) / h);
      const glm::vec3* in = &map.pixels[size_t(y) * w];
      glm::vec4* out = &packed.texels[size_t(y) * w];
      float* cdf = &packed.cdf[VKRAY_ENVIRONMENT_ROW_CDF(size_t(w), y)];
      double sum = 0.0;
      for (uint32_t x = 0; x < w; ++x) {
        const double weight = double(emission_luminance(in[x])) * sin_theta;
        sum += weight;
        cdf[x] = float(sum);
        out[x] = glm::vec4(in[x] * scale, float(weight));
      }
      row_weight[y] = sum;
      // A row without weight is never picked; equal shares keep its numbers finite.
      const float inverse = sum > 0.0 ? float(1.0 / sum) : 0.0f;
      for (uint32_t x = 0; x < w; ++x) cdf[x] = sum > 0.0 ? cdf[x] * inverse : float(double(x + 1) / w);
      cdf[w - 1] = 1.0f;
    }
  });
  double total = 0.0;
  float* marginal = &packed.cdf[VKRAY_ENVIRONMENT_MARGINAL_CDF(size_t(w), h)];
  for (uint32_t y = 0; y < h; ++y) marginal[y] = float(total += row_weight[y]);
  if (!(total > 0.0)) return {};
  for (uint32_t y = 0; y < h; ++y) marginal[y] = float(double(marginal[y]) / total);
  marginal[h - 1] = 1.0f;
  const float inverse_mean = float(double(w) * h / total);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, packed.texels.size(), 1 << 16), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) packed.texels[i].w *= inverse_mean;
  });
  packed.width = w;
  packed.height = h;
  return packed;
}

}  // namespace vkray::gpu
