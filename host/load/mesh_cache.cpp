#include "load/mesh_cache.h"

#include <set>

#include "load/mesh_file.h"
#include "mesh/mesh.h"

namespace vkray {

struct MeshCache::Entry {
  uintmax_t size = 0;
  std::filesystem::file_time_type modified;
  std::shared_ptr<const Mesh> mesh;
};

MeshCache::MeshCache() = default;
MeshCache::~MeshCache() = default;

std::shared_ptr<const Mesh> MeshCache::get(const std::filesystem::path& file) {
  std::error_code size_error, time_error;
  const uintmax_t size = std::filesystem::file_size(file, size_error);
  const auto modified = std::filesystem::last_write_time(file, time_error);
  const auto found = entries_.find(file);
  if (!size_error && !time_error && found != entries_.end() && found->second.size == size && found->second.modified == modified)
    return found->second.mesh;
  auto mesh = std::make_shared<const Mesh>(load_mesh(file));
  if (!size_error && !time_error) entries_[file] = Entry{size, modified, mesh};
  return mesh;
}

void MeshCache::keep_only(const std::vector<std::filesystem::path>& files) {
  const std::set<std::filesystem::path> kept(files.begin(), files.end());
  std::erase_if(entries_, [&](const auto& entry) { return !kept.count(entry.first); });
}

}  // namespace vkray
