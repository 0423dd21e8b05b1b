// XXH3's 128-bit hash (libxxhash) as 32 hex digits: the fingerprints parts of a render record (the
// scene's, the shader's, a PFM part's pixels), so that `vkray merge` assembles only what belongs
// together. Not a cryptographic hash: it catches mistakes, not forgeries.
#pragma once

#include <cstddef>
#include <string>
#include <type_traits>

struct XXH3_state_s;

namespace vkray {

// A streaming hash fed values through a 64 KiB buffer, so that millions of small fields cost one
// library call per buffer. Large: keep one on the heap.
class Hasher {
 public:
  Hasher();
  ~Hasher();
  Hasher(const Hasher&) = delete;
  Hasher& operator=(const Hasher&) = delete;

  // A number's bytes as this host lays them out (every machine vkray runs on is little-endian).
  template <typename T>
  void add(const T& value) {
    static_assert(std::is_arithmetic_v<T> || std::is_enum_v<T>);
    bytes(&value, sizeof(T));
  }
  void add(bool value) { add(static_cast<unsigned char>(value)); }
  // Its length, then its characters: "ab","c" and "a","bc" hash apart.
  void add(const std::string& text);
  void bytes(const void* data, size_t size);
  // The hash of everything added so far.
  std::string hex();

 private:
  void flush();
  XXH3_state_s* state_;
  unsigned char buffer_[1 << 16];
  size_t used_ = 0;
};

// The hash of `size` bytes at `data`.
std::string hash_hex(const void* data, size_t size);

}  // namespace vkray
