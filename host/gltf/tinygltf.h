// tinygltf (Debian's libtinygltf-dev header) as vkray configures it, for every file that includes it:
// no picture decoding or writing (stb_image), and no picture files read by tinygltf itself
// (gltf/gltf.cpp reads and decodes them). Its implementation is compiled in gltf/tinygltf.cpp.
#pragma once

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>
