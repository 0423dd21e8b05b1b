#include "base/hash.h"

#include <cstdint>
#include <cstdio>
#include <cstring>

#include <xxhash.h>

namespace vkray {
namespace {

std::string hex_of(XXH128_hash_t hash) {
  char text[33];
  std::snprintf(text, sizeof(text), "%016llx%016llx", static_cast<unsigned long long>(hash.high64),
                static_cast<unsigned long long>(hash.low64));
  return text;
}

}  // namespace

Hasher::Hasher() : state_(XXH3_createState()) { XXH3_128bits_reset(state_); }
Hasher::~Hasher() { XXH3_freeState(state_); }

void Hasher::add(const std::string& text) {
  add(uint64_t(text.size()));
  bytes(text.data(), text.size());
}

void Hasher::bytes(const void* data, size_t size) {
  if (used_ + size > sizeof(buffer_)) flush();
  if (size > sizeof(buffer_)) {
    XXH3_128bits_update(state_, data, size);
    return;
  }
  std::memcpy(buffer_ + used_, data, size);
  used_ += size;
}

std::string Hasher::hex() {
  flush();
  return hex_of(XXH3_128bits_digest(state_));
}

void Hasher::flush() {
  XXH3_128bits_update(state_, buffer_, used_);
  used_ = 0;
}

std::string hash_hex(const void* data, size_t size) { return hex_of(XXH3_128bits(data, size)); }

}  // namespace vkray
