#include "scene/digest.h"

#include <cstdio>
#include <cstring>
#include <memory>
#include <type_traits>

#include <xxhash.h>

namespace vkray {
namespace {

// A new field in one of these must be hashed below (or said not to matter to a pixel), and the size
// here updated: the build stops until it is.
static_assert(sizeof(Camera) == 48, "a Camera field is not in scene_digest");
static_assert(sizeof(Integrator) == 12, "an Integrator field is not in scene_digest");
static_assert(sizeof(PointLight) == 24, "a PointLight field is not in scene_digest");
static_assert(sizeof(Sphere) == 28, "a Sphere field is not in scene_digest");
static_assert(sizeof(Triangle) == 108, "a Triangle field is not in scene_digest");
static_assert(sizeof(TextureRef) == 16, "a TextureRef field is not in scene_digest");
static_assert(sizeof(Material) == 96, "a Material field is not in scene_digest");
static_assert(sizeof(Scene) == 376, "a Scene field is not in scene_digest");

// XXH3's streaming state, fed values through a buffer, so that millions of small fields cost one
// call per 64 KiB.
class Hasher {
 public:
  Hasher() : state_(XXH3_createState()) { XXH3_128bits_reset(state_); }
  ~Hasher() { XXH3_freeState(state_); }
  Hasher(const Hasher&) = delete;
  Hasher& operator=(const Hasher&) = delete;

  template <typename T>
  void add(const T& value) {
    static_assert(std::is_arithmetic_v<T> || std::is_enum_v<T>);
    bytes(&value, sizeof(T));
  }
  void add(bool value) { add(uint8_t(value)); }
  template <int N, typename T, glm::qualifier Q>
  void add(const glm::vec<N, T, Q>& v) {
    for (int i = 0; i < N; ++i) add(v[i]);
  }
  void add(const std::string& text) {
    add(uint64_t(text.size()));
    bytes(text.data(), text.size());
  }
  void bytes(const void* data, size_t size) {
    if (used_ + size > sizeof(buffer_)) flush();
    if (size > sizeof(buffer_)) {
      XXH3_128bits_update(state_, data, size);
      return;
    }
    std::memcpy(buffer_ + used_, data, size);
    used_ += size;
  }
  std::string hex() {
    flush();
    const XXH128_hash_t hash = XXH3_128bits_digest(state_);
    char text[33];
    std::snprintf(text, sizeof(text), "%016llx%016llx", static_cast<unsigned long long>(hash.high64),
                  static_cast<unsigned long long>(hash.low64));
    return text;
  }

 private:
  void flush() {
    XXH3_128bits_update(state_, buffer_, used_);
    used_ = 0;
  }
  XXH3_state_t* state_;
  unsigned char buffer_[1 << 16];
  size_t used_ = 0;
};

void add(Hasher& h, const TextureRef& t) {
  h.add(t.texture);
  h.add(t.wrap_s);
  h.add(t.wrap_t);
  h.add(t.filter);
}

}  // namespace

std::string scene_digest(const Scene& scene) {
  auto h = std::make_unique<Hasher>();  // its buffer is too large for a thread's stack to hold lightly
  // A version of this layout: bump it when the order or the meaning of what is hashed changes.
  h->add(std::string("vkray scene digest 1"));
  const Camera& c = scene.camera;
  h->add(c.position), h->add(c.forward), h->add(c.up), h->add(c.focal_length), h->add(c.aperture_radius),
      h->add(c.focus_distance);
  h->add(scene.integrator.type), h->add(scene.integrator.max_depth), h->add(scene.integrator.rr_depth);
  h->add(scene.background), h->add(scene.ambient);
  h->add(uint64_t(scene.materials.size()));
  for (const Material& m : scene.materials) {
    h->add(m.type), h->add(m.albedo), h->add(m.ior), h->add(m.emission);
    add(*h, m.albedo_texture);
    add(*h, m.emission_texture);
  }
  h->add(uint64_t(scene.textures.size()));
  for (const auto& t : scene.textures) {
    h->add(t->width), h->add(t->height);
    h->bytes(t->texels.data(), t->texels.size() * sizeof(uint16_t));
  }
  h->add(uint64_t(scene.lights.size()));
  for (const PointLight& l : scene.lights) h->add(l.position), h->add(l.intensity);
  h->add(uint64_t(scene.spheres.size()));
  for (const Sphere& s : scene.spheres) h->add(s.center), h->add(s.radius), h->add(s.material), h->add(s.object), h->add(s.inward);
  h->add(uint64_t(scene.triangles.size()));
  for (const Triangle& t : scene.triangles) {
    for (const glm::vec3& v : t.v) h->add(v);
    h->add(t.material), h->add(t.object), h->add(t.smooth);
    for (const glm::vec3& n : t.normals) h->add(n);
    for (const glm::vec2& uv : t.uv) h->add(uv);
  }
  return h->hex();
}

}  // namespace vkray
