// tinygltf's implementation, compiled here from Debian's header (libtinygltf-dev) rather than linked
// from Debian's shared library, so that the sanitizer and fuzz builds instrument it like vkray's own
// code.
#define TINYGLTF_IMPLEMENTATION
#include "gltf/tinygltf.h"

namespace vkray {

std::string tinygltf_buffer_request(const std::string& base_dir, const std::string& uri) {
  return tinygltf::JoinPath(base_dir, tinygltf::dlib::urldecode(uri));
}

}  // namespace vkray
