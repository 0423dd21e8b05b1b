#include "session/parity.h"

#include "bvh/bvh.h"
#include "session/cpu_render.h"

namespace vkray {

ParityResult compare_with_reference(Session& session, std::shared_ptr<const Scene> scene, const RenderOptions& options) {
  ParityResult result;
  result.image = image_settings(*scene, options);
  const Bvh bvh = build_bvh(primitive_boxes(*scene));  // one hierarchy, traversed by both
  {
    const DeviceScene on_device = session.upload(scene, &bvh);
    result.gpu = session.render(on_device, options);
  }
  result.cpu = render_on_cpu(*scene, options, &bvh, &result.signatures);
  result.metrics = compare_images(result.gpu.image, result.cpu.image, result.signatures, result.tolerance);
  return result;
}

}  // namespace vkray
