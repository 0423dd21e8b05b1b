// Watches files for changes with Linux inotify, the way editors actually save: by writing in place
// or by renaming a new file over the old one, so it watches the folders that hold the files.
#pragma once

#include <chrono>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace vkray {

class FileWatcher {
 public:
  FileWatcher();
  ~FileWatcher();
  FileWatcher(const FileWatcher&) = delete;
  FileWatcher& operator=(const FileWatcher&) = delete;

  // Replaces the set of watched files.
  void set_files(const std::vector<std::filesystem::path>& files);
  // Also counts any file directly in `folder` whose extension is one of `extensions` (a shader
  // that includes a file which does not exist yet still recompiles when it appears).
  void set_folder(const std::filesystem::path& folder, std::set<std::string> extensions);

  // Blocks until a watched file changes and then nothing more changes for `settle` (editors often
  // write in several steps), or until `stop_fd` is readable. Returns the changed files, or nothing
  // when stopped.
  std::vector<std::filesystem::path> wait(std::chrono::milliseconds settle, int stop_fd);
  // Without blocking: the files changed since the last call that returned some, once nothing more
  // has changed for `settle`; nothing otherwise (a loop that draws frames calls it every frame).
  std::vector<std::filesystem::path> poll(std::chrono::milliseconds settle);

  size_t file_count() const { return files_.size(); }
  size_t folder_count() const { return watches_.size(); }

 private:
  bool relevant(const std::filesystem::path& file) const;
  void rewatch();

  int fd_ = -1;
  std::set<std::filesystem::path> files_;
  std::filesystem::path folder_;
  std::set<std::string> folder_extensions_;
  std::map<int, std::filesystem::path> watches_;  // inotify watch descriptor -> folder
  // poll()'s changes not yet returned, and when the last of them came.
  std::set<std::filesystem::path> pending_;
  std::chrono::steady_clock::time_point last_change_;
  // Reads the events waiting (without blocking) into `changed`; returns whether any was relevant.
  bool read_events(std::set<std::filesystem::path>& changed);
};

}  // namespace vkray
