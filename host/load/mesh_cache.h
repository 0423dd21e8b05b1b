// Mesh files kept between scene loads.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <vector>

namespace vkray {

struct Mesh;
// Mesh files read by earlier scene loads, kept for the next ones (a face that loads edited scenes
// in a loop): a file is read again when its size or modification time changed.
class MeshCache {
 public:
  MeshCache();
  ~MeshCache();
  MeshCache(const MeshCache&) = delete;
  MeshCache& operator=(const MeshCache&) = delete;
  // The mesh in `file`, read now (load_mesh) unless kept. Throws what load_mesh throws.
  std::shared_ptr<const Mesh> get(const std::filesystem::path& file);
  // Forgets every file but these (a scene's referenced_files), so that a long-lived cache holds
  // only what the last scene uses.
  void keep_only(const std::vector<std::filesystem::path>& files);

 private:
  struct Entry;
  std::map<std::filesystem::path, Entry> entries_;
};

}  // namespace vkray
