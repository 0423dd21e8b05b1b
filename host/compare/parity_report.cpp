#include "compare/parity_report.h"

#include <cmath>

#include "image/image.h"
#include "image/image_file.h"
#include "session/version.h"

namespace vkray {

nlohmann::json parity_json(const ParityResult& r, const std::string& scene, const std::string& device) {
  const ParityMetrics& m = r.metrics;
  const glm::vec3 worst_gpu = r.gpu.image.at(m.worst_x, m.worst_y), worst_cpu = r.cpu.image.at(m.worst_x, m.worst_y);
  nlohmann::json json = {
      {"scene", scene},
      {"width", m.width},
      {"height", m.height},
      {"samples_per_pixel", r.image.samples_per_pixel},
      {"device", device},
      {"gpu_trace_seconds", r.gpu.stats.trace_seconds},
      {"cpu_trace_seconds", r.cpu.stats.trace_seconds},
      {"cpu_threads", r.cpu.stats.threads},
      {"rays", r.cpu.stats.rays},
      {"max_abs_diff", m.max_abs},
      {"mean_abs_diff", m.mean_abs},
      {"psnr_db", std::isinf(m.psnr) ? nlohmann::json(nullptr) : nlohmann::json(m.psnr)},
      {"share_over_1", m.share_over_1()},
      {"share_over_2", m.share_over_2()},
      {"pixels_over_1", m.over_1},
      {"pixels_over_2", m.over_2},
      {"edge_pixels", m.edge_pixels},
      {"edge_pixels_over_1", m.edge_over_1},
      {"interior_pixels_over_1", m.interior_over_1},
      {"interior_pixels_over_2", m.interior_over_2},
      {"mean_relative_diff", std::isinf(m.mean_relative) ? nlohmann::json(nullptr) : nlohmann::json(m.mean_relative)},
      {"non_finite_gpu_pixels", m.non_finite},
      {"stochastic", r.tolerance.stochastic},
      {"worst_pixel", {m.worst_x, m.worst_y}},
      {"worst_gpu", {worst_gpu.r, worst_gpu.g, worst_gpu.b}},
      {"worst_cpu", {worst_cpu.r, worst_cpu.g, worst_cpu.b}},
      {"tolerance", describe_tolerance(r.tolerance)},
      {"pass", m.pass},
      {"vkray_version", version_string()},
  };
  if (m.aovs_compared) {
    json["aov_pixels_differing"] = m.aov_differing;
    json["aov_interior_pixels_differing"] = m.aov_interior_differing;
    json["aov_edge_pixels_differing"] = m.aov_edge_differing;
    nlohmann::json by_pass = nlohmann::json::object();
    for (size_t pass = 0; pass < kAllAovs.size(); ++pass) by_pass[aov_name(kAllAovs[pass])] = m.aov_differing_by_pass[pass];
    json["aov_pixels_differing_by_pass"] = by_pass;
  }
  return json;
}

int write_difference(const ParityResult& r, const std::filesystem::path& file) {
  int max_steps = 0;
  write_image(is_pfm(file) ? absolute_difference(r.gpu.image, r.cpu.image)
                                         : difference_heatmap(r.gpu.image, r.cpu.image, max_steps),
              file);
  return max_steps;
}

}  // namespace vkray
