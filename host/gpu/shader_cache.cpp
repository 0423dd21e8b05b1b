#include "gpu/shader_cache.h"

#include <glslang/Public/ShaderLang.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>
#include <system_error>

#include "base/atomic_file.h"

namespace vkray::gpu {
namespace {

namespace fs = std::filesystem;

constexpr char kMagic[8] = {'V', 'K', 'R', 'A', 'Y', 'S', 'C', '1'};
// Past these the folders are not a shader folder (say, --shader-dir /): no caching.
constexpr size_t kMostFiles = 256;
constexpr uintmax_t kMostBytes = uintmax_t(16) << 20;

// FNV-1a, 64 bits: a cache key, not a defence against anyone.
class Hasher {
 public:
  Hasher& bytes(const void* data, size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < size; ++i) hash_ = (hash_ ^ p[i]) * 1099511628211ull;
    return *this;
  }
  Hasher& text(std::string_view s) {  // length first, so that ("ab", "c") and ("a", "bc") differ
    const uint64_t size = s.size();
    return bytes(&size, sizeof size).bytes(s.data(), s.size());
  }
  Hasher& number(uint64_t n) { return bytes(&n, sizeof n); }
  uint64_t value() const { return hash_; }

 private:
  uint64_t hash_ = 14695981039346656037ull;
};

std::optional<std::string> read_whole(const fs::path& file, uintmax_t most) {
  std::error_code error;
  const uintmax_t size = fs::file_size(file, error);
  if (error || size > most) return std::nullopt;
  std::ifstream in(file, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) return std::nullopt;
  return text;
}

std::optional<uint64_t> content_hash(const fs::path& file) {
  const auto text = read_whole(file, kMostBytes);
  if (!text) return std::nullopt;
  return Hasher().text(*text).value();
}

// Everything but the included files' own contents that decides the compile's result, or none when
// that cannot be told (then nothing is cached).
std::optional<uint64_t> cache_key(const fs::path& cache_dir, const fs::path& entry, const std::vector<fs::path>& include_dirs,
                                  const std::vector<GeneratedInclude>& generated) {
  Hasher h;
  std::error_code error;
  // The build that compiles: another vkray may compile otherwise.
  const fs::path exe = fs::read_symlink("/proc/self/exe", error);
  if (error) return std::nullopt;
  const uintmax_t exe_size = fs::file_size(exe, error);
  if (error) return std::nullopt;
  const auto exe_time = fs::last_write_time(exe, error);
  if (error) return std::nullopt;
  h.text(exe.string()).number(exe_size).number(uint64_t(exe_time.time_since_epoch().count()));
  h.text(glslang::GetGlslVersionString());
  h.text(entry.lexically_normal().string());
  for (const GeneratedInclude& g : generated) h.text(g.name).text(g.text);
  // Every file where an #include could find something: a file that appears there may shadow one
  // that was included from further along the search.
  std::vector<fs::path> dirs;
  for (const fs::path& dir : include_dirs) dirs.push_back(dir.lexically_normal());
  dirs.push_back(entry.lexically_normal().parent_path());
  std::sort(dirs.begin(), dirs.end());
  dirs.erase(std::unique(dirs.begin(), dirs.end()), dirs.end());
  const fs::path cache = fs::weakly_canonical(cache_dir, error);
  for (const fs::path& dir : dirs) {
    h.text(dir.string());
    std::vector<fs::path> files;
    for (fs::recursive_directory_iterator it(dir.empty() ? fs::path(".") : dir, error), end; !error && it != end;
         it.increment(error)) {
      if (it->is_directory(error) && fs::weakly_canonical(it->path(), error) == cache) {
        it.disable_recursion_pending();  // a cache kept among the shaders: its own writes would change the key
        continue;
      }
      if (it->is_regular_file(error)) files.push_back(it->path());
      if (files.size() > kMostFiles) return std::nullopt;
    }
    if (error) return std::nullopt;
    std::sort(files.begin(), files.end());
    uintmax_t total = 0;
    for (const fs::path& file : files) {
      const auto text = read_whole(file, kMostBytes - total);
      if (!text) return std::nullopt;
      total += text->size();
      h.text(file.string()).text(*text);
    }
  }
  return h.value();
}

// ---- The entry file: the key, then the sources with their hashes, the bindings, the SPIR-V --------
class Writer {
 public:
  void number(uint64_t n) { bytes_.append(reinterpret_cast<const char*>(&n), sizeof n); }
  void text(std::string_view s) {
    number(s.size());
    bytes_.append(s);
  }
  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
};

class Reader {
 public:
  explicit Reader(std::string_view bytes) : bytes_(bytes) {}
  bool number(uint64_t& n) {
    if (bytes_.size() - at_ < sizeof n) return false;
    std::memcpy(&n, bytes_.data() + at_, sizeof n);
    at_ += sizeof n;
    return true;
  }
  bool text(std::string& s) {
    uint64_t size = 0;
    if (!number(size) || bytes_.size() - at_ < size) return false;
    s.assign(bytes_.substr(at_, size));
    at_ += size;
    return true;
  }
  bool done() const { return at_ == bytes_.size(); }

 private:
  std::string_view bytes_;
  size_t at_ = 0;
};

// The magic, the key, a hash of the rest (a damaged entry must never reach the driver), the rest.
std::string serialize(uint64_t key, const CompiledShader& shader, const std::vector<uint64_t>& source_hashes) {
  Writer w;
  w.number(shader.sources.size());
  for (size_t i = 0; i < shader.sources.size(); ++i) {
    w.text(shader.sources[i].string());
    w.number(source_hashes[i]);
  }
  w.number(shader.bindings.size());
  for (const ShaderBinding& b : shader.bindings) {
    w.number(b.set);
    w.number(b.binding);
    w.number(b.type ? uint64_t(*b.type) : UINT64_MAX);
    w.number(b.count);
    w.text(b.name);
  }
  w.text(std::string_view(reinterpret_cast<const char*>(shader.spirv.data()), shader.spirv.size() * sizeof(uint32_t)));
  Writer head;
  head.bytes().append(kMagic, sizeof kMagic);
  head.number(key);
  head.number(Hasher().text(w.bytes()).value());
  return head.bytes() + w.bytes();
}

// The entry's shader if it is whole, has `key` and every source it names is as it was.
std::optional<CompiledShader> deserialize(std::string_view bytes, uint64_t key) {
  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0) return std::nullopt;
  Reader head(bytes.substr(sizeof kMagic, 2 * sizeof(uint64_t)));
  uint64_t stored_key = 0, checksum = 0;
  if (!head.number(stored_key) || stored_key != key || !head.number(checksum)) return std::nullopt;
  const std::string_view rest = bytes.substr(std::min(bytes.size(), sizeof kMagic + 2 * sizeof(uint64_t)));
  if (Hasher().text(rest).value() != checksum) return std::nullopt;  // damaged
  Reader r(rest);
  CompiledShader shader;
  uint64_t count = 0;
  if (!r.number(count) || count > kMostFiles) return std::nullopt;
  for (uint64_t i = 0; i < count; ++i) {
    std::string path;
    uint64_t hash = 0;
    if (!r.text(path) || !r.number(hash)) return std::nullopt;
    if (content_hash(path) != hash) return std::nullopt;  // an included file changed
    shader.sources.emplace_back(path);
  }
  if (!r.number(count) || count > 1024) return std::nullopt;
  for (uint64_t i = 0; i < count; ++i) {
    uint64_t set = 0, binding = 0, type = 0, descriptors = 0;
    std::string name;
    if (!r.number(set) || !r.number(binding) || !r.number(type) || !r.number(descriptors) || !r.text(name)) return std::nullopt;
    shader.bindings.push_back({uint32_t(set), uint32_t(binding),
                               type == UINT64_MAX ? std::nullopt : std::optional(vk::DescriptorType(type)),
                               uint32_t(descriptors), name});
  }
  std::string spirv;
  if (!r.text(spirv) || !r.done() || spirv.size() < 20 || spirv.size() % sizeof(uint32_t) != 0) return std::nullopt;
  shader.spirv.resize(spirv.size() / sizeof(uint32_t));
  std::memcpy(shader.spirv.data(), spirv.data(), spirv.size());
  if (shader.spirv[0] != 0x07230203u) return std::nullopt;  // SPIR-V's magic number
  return shader;
}

// Removes the oldest entries past kShaderCacheEntries (a hit refreshes an entry's time).
void evict(const fs::path& dir) {
  std::error_code error;
  std::vector<std::pair<fs::file_time_type, fs::path>> entries;
  for (fs::directory_iterator it(dir, error), end; !error && it != end; it.increment(error))
    if (it->path().extension() == ".spvc") entries.emplace_back(it->last_write_time(error), it->path());
  if (entries.size() <= kShaderCacheEntries) return;
  std::sort(entries.begin(), entries.end());
  for (size_t i = 0; i + kShaderCacheEntries < entries.size(); ++i) fs::remove(entries[i].second, error);
}

}  // namespace

std::optional<fs::path> shader_cache_dir() {
  if (const char* setting = std::getenv("VKRAY_SHADER_CACHE")) {
    const std::string_view dir = setting;
    if (dir.empty() || dir == "off") return std::nullopt;
    return fs::path(dir);
  }
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return fs::path(xdg) / "vkray" / "shaders";
  if (const char* home = std::getenv("HOME"); home && *home) return fs::path(home) / ".cache" / "vkray" / "shaders";
  return std::nullopt;
}

CompiledShader compile_compute_shader_cached(const std::optional<fs::path>& cache_dir, const fs::path& entry,
                                             const std::vector<fs::path>& include_dirs,
                                             const std::vector<GeneratedInclude>& generated) {
  const std::optional<uint64_t> key = cache_dir ? cache_key(*cache_dir, entry, include_dirs, generated) : std::nullopt;
  if (!key) return compile_compute_shader(entry, include_dirs, generated);
  char name[32];
  std::snprintf(name, sizeof name, "%016llx.spvc", static_cast<unsigned long long>(*key));
  const fs::path file = *cache_dir / name;
  std::error_code error;
  if (const auto bytes = read_whole(file, kMostBytes)) {
    if (auto shader = deserialize(*bytes, *key)) {
      fs::last_write_time(file, fs::file_time_type::clock::now(), error);  // recently used
      return std::move(*shader);
    }
  }
  CompiledShader shader = compile_compute_shader(entry, include_dirs, generated);  // errors are never cached
  std::vector<uint64_t> hashes;
  for (const fs::path& source : shader.sources) {
    const auto hash = content_hash(source);
    if (!hash) return shader;
    hashes.push_back(*hash);
  }
  try {
    fs::create_directories(*cache_dir, error);
    write_file_atomically(file, serialize(*key, shader, hashes));
    evict(*cache_dir);
  } catch (const std::exception&) {  // a folder that cannot be written: no cache, same result
  }
  return shader;
}

}  // namespace vkray::gpu
