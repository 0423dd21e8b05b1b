#include "cpu/environment.h"

#include <algorithm>
#include <cmath>

#include "cpu/warp.h"

namespace vkray::cpu {
namespace {

// The first of the cumulative shares `cdf` (from 0 to 1) whose interval holds u, and where in it.
std::pair<uint32_t, double> invert(const double* cdf, uint32_t count, double u) {
  // The first share past u; a share of weight 0 (equal bounds) is never the one.
  const double* above = std::upper_bound(cdf + 1, cdf + count + 1, u);
  const auto i = uint32_t(std::min<ptrdiff_t>(above - (cdf + 1), count - 1));
  const double width = cdf[i + 1] - cdf[i];
  return {i, width > 0 ? std::clamp((u - cdf[i]) / width, 0.0, 1.0) : 0.0};
}

}  // namespace

EnvironmentLight::EnvironmentLight(const Environment& environment)
    : map_(*environment.radiance),
      to_world_(environment.to_world),
      to_map_(glm::transpose(glm::dmat3(environment.to_world))),
      width_(map_.width),
      height_(map_.height) {
  rows_.assign(height_ + 1, 0.0);
  columns_.assign(size_t(height_) * (width_ + 1), 0.0);
  weight_.resize(size_t(width_) * height_);
  for (uint32_t y = 0; y < height_; ++y) {
    const double sin_theta = std::sin(kPi * (y + 0.5) / height_);
    double* row = &columns_[size_t(y) * (width_ + 1)];
    for (uint32_t x = 0; x < width_; ++x) {
      const dvec3 l(map_.at(x, y));
      const double w = (0.2126 * l.r + 0.7152 * l.g + 0.0722 * l.b) * sin_theta;
      weight_[size_t(y) * width_ + x] = w;
      row[x + 1] = row[x] + w;
    }
    rows_[y + 1] = rows_[y] + row[width_];
    for (uint32_t x = 1; x <= width_; ++x) row[x] = row[width_] > 0 ? row[x] / row[width_] : double(x) / width_;
  }
  total_ = rows_[height_];
  if (total_ > 0)
    for (double& r : rows_) r /= total_;
}

EnvironmentLight::Lookup EnvironmentLight::texel(uint32_t x, uint32_t y, double sin_theta) const {
  Lookup l;
  l.radiance = dvec3(map_.at(x, y));
  // Density per unit (u, v): the texel's share times the texels in all; per unit solid angle: over the
  // 2 pi^2 sin(theta) of the sphere that a unit of (u, v) covers there.
  const double per_uv = weight_[size_t(y) * width_ + x] / total_ * double(width_) * height_;
  l.pdf = sin_theta > 0 ? per_uv / (2 * kPi * kPi * sin_theta) : 0.0;
  return l;
}

EnvironmentLight::Lookup EnvironmentLight::lookup(const dvec3& dir) const {
  // Mitsuba's envmap: u = atan2(x, -z) / 2 pi, v = acos(y) / pi, in the map's own frame.
  const dvec3 d = to_map_ * dir;
  double u = std::atan2(d.x, -d.z) / (2 * kPi);
  if (u < 0) u += 1;
  // The polar angle from both of its sides: precise near the poles too.
  const double sin_theta = std::hypot(d.x, d.z);
  const double v = std::atan2(sin_theta, d.y) / kPi;
  const auto x = std::min(uint32_t(u * width_), width_ - 1), y = std::min(uint32_t(v * height_), height_ - 1);
  return texel(x, y, sin_theta);
}

EnvironmentLight::Sample EnvironmentLight::sample(double u_row, double u_column) const {
  const auto [y, dv] = invert(rows_.data(), height_, u_row);
  const auto [x, du] = invert(&columns_[size_t(y) * (width_ + 1)], width_, u_column);
  const double theta = (y + dv) / height_ * kPi, phi = (x + du) / width_ * 2 * kPi;
  const double sin_theta = std::sin(theta);
  Sample s;
  s.dir = glm::normalize(to_world_ * dvec3(sin_theta * std::sin(phi), std::cos(theta), -sin_theta * std::cos(phi)));
  const Lookup l = texel(x, y, sin_theta);
  s.radiance = l.radiance;
  s.pdf = l.pdf;
  return s;
}

}  // namespace vkray::cpu
