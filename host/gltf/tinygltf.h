// tinygltf (Debian's libtinygltf-dev header) as vkray configures it, for every file that includes it:
// no picture decoding or writing (stb_image), and no picture files read by tinygltf itself
// (gltf/gltf.cpp reads and decodes them). Its implementation is compiled in gltf/tinygltf.cpp.
#pragma once

#include <string>

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

namespace vkray {

// The path tinygltf asks its file callbacks for when it reads a buffer whose uri is not a data: URI
// it decodes itself: `uri` decoded by tinygltf's own rules ('+' read as a space, as in a web form; a
// bad escape read as a NUL) and joined to `base_dir`. vkray decodes URIs by RFC 3986 and answers
// that request with the file (or data) it resolved, so tinygltf's rules never choose a file.
std::string tinygltf_buffer_request(const std::string& base_dir, const std::string& uri);

}  // namespace vkray
