#include "mesh/normals.h"

#include <cstring>
#include <unordered_map>

namespace vkray {

std::vector<std::array<glm::vec3, 3>> area_weighted_normals(const std::vector<std::array<glm::vec3, 3>>& triangles) {
  struct Key {
    uint32_t x, y, z;
    bool operator==(const Key&) const = default;
  };
  struct Hash {
    size_t operator()(const Key& k) const { return (size_t(k.x) * 73856093u) ^ (size_t(k.y) * 19349663u) ^ (size_t(k.z) * 83492791u); }
  };
  auto key = [](const glm::vec3& p) {
    Key k;
    std::memcpy(&k, &p, sizeof k);
    return k;
  };
  std::unordered_map<Key, glm::vec3, Hash> sum;
  sum.reserve(triangles.size());
  for (const auto& t : triangles) {
    const glm::vec3 n = glm::cross(t[1] - t[0], t[2] - t[0]);  // length = 2 * area: area-weighted
    for (const auto& p : t) sum[key(p)] += n;
  }
  std::vector<std::array<glm::vec3, 3>> normals(triangles.size());
  for (size_t i = 0; i < triangles.size(); ++i)
    for (size_t k = 0; k < 3; ++k) {
      const glm::vec3 n = sum[key(triangles[i][k])];
      const float length = glm::length(n);
      normals[i][k] = length > 0 ? n / length : glm::vec3(0.0f);
    }
  return normals;
}

}  // namespace vkray
