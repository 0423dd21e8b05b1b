// tinygltf's implementation, compiled here from Debian's header (libtinygltf-dev) rather than linked
// from Debian's shared library, so that the sanitizer and fuzz builds instrument it like vkray's own
// code.
#define TINYGLTF_IMPLEMENTATION
#include "gltf/tinygltf.h"
