#include "base/file_watcher.h"

#include <poll.h>
#include <sys/inotify.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "base/errors.h"

namespace vkray {
namespace {

std::filesystem::path absolute_normal(const std::filesystem::path& p) {
  return std::filesystem::absolute(p).lexically_normal();
}

// Writes in place (MODIFY, CLOSE_WRITE), saves by rename (MOVED_TO), new and deleted files.
constexpr uint32_t kEvents = IN_MODIFY | IN_CLOSE_WRITE | IN_MOVED_TO | IN_CREATE | IN_DELETE;

}  // namespace

FileWatcher::FileWatcher() : fd_(inotify_init1(IN_NONBLOCK | IN_CLOEXEC)) {
  if (fd_ < 0) {
    const int error = errno;
    throw LimitError(std::string("cannot watch files: inotify_init1: ") + std::strerror(error) +
                     (error == EMFILE ? " (the limit is fs.inotify.max_user_instances)" : ""));
  }
}

FileWatcher::~FileWatcher() { ::close(fd_); }

void FileWatcher::set_files(const std::vector<std::filesystem::path>& files) {
  files_.clear();
  for (const auto& f : files) files_.insert(absolute_normal(f));
  rewatch();
}

void FileWatcher::set_folder(const std::filesystem::path& folder, std::set<std::string> extensions) {
  folder_ = absolute_normal(folder);
  folder_extensions_ = std::move(extensions);
  rewatch();
}

void FileWatcher::rewatch() {
  std::set<std::filesystem::path> folders;
  for (const auto& f : files_) folders.insert(f.parent_path());
  if (!folder_.empty()) folders.insert(folder_);
  for (auto it = watches_.begin(); it != watches_.end();) {
    if (folders.count(it->second)) {
      folders.erase(it->second);
      ++it;
    } else {
      inotify_rm_watch(fd_, it->first);
      it = watches_.erase(it);
    }
  }
  for (const auto& folder : folders) {
    const int wd = inotify_add_watch(fd_, folder.c_str(), kEvents);
    if (wd >= 0) {
      watches_[wd] = folder;
    } else if (const int error = errno; error != ENOENT && error != ENOTDIR) {  // a missing folder cannot change
      throw LimitError("cannot watch " + folder.string() + ": inotify_add_watch: " + std::strerror(error) +
                       (error == ENOSPC ? " (the limit is fs.inotify.max_user_watches)" : ""));
    }
  }
}

bool FileWatcher::relevant(const std::filesystem::path& file) const {
  if (files_.count(file)) return true;
  return file.parent_path() == folder_ && folder_extensions_.count(file.extension().string()) > 0;
}

std::vector<std::filesystem::path> FileWatcher::wait(std::chrono::milliseconds settle, int stop_fd) {
  std::set<std::filesystem::path> changed;
  for (;;) {
    pollfd fds[] = {{fd_, POLLIN, 0}, {stop_fd, POLLIN, 0}};
    // Block until the first change; after it, wait only `settle` for more.
    const int timeout = changed.empty() ? -1 : static_cast<int>(settle.count());
    const int ready = ::poll(fds, 2, timeout);
    if (ready < 0 && errno == EINTR) continue;
    if (ready < 0 && errno == ENOMEM) throw LimitError("cannot wait for file changes: poll: out of memory");
    if (ready < 0) throw InternalError(std::string("cannot wait for file changes: poll: ") + std::strerror(errno));
    if (fds[1].revents & POLLIN) return {};
    if (ready == 0) return {changed.begin(), changed.end()};  // settled
    read_events(changed);
  }
}

bool FileWatcher::read_events(std::set<std::filesystem::path>& changed) {
  alignas(inotify_event) char buffer[16384];
  bool any = false;
  for (;;) {
    const ssize_t n = ::read(fd_, buffer, sizeof buffer);
    if (n <= 0) break;
    for (ssize_t at = 0; at < n;) {
      const auto* event = reinterpret_cast<const inotify_event*>(buffer + at);
      at += static_cast<ssize_t>(sizeof(inotify_event) + event->len);
      const auto folder = watches_.find(event->wd);
      if (folder == watches_.end() || event->len == 0) continue;
      const std::filesystem::path file = folder->second / event->name;
      if (relevant(file)) {
        changed.insert(file);
        any = true;
      }
    }
  }
  return any;
}

std::vector<std::filesystem::path> FileWatcher::poll(std::chrono::milliseconds settle) {
  const auto now = std::chrono::steady_clock::now();
  if (read_events(pending_)) last_change_ = now;
  if (pending_.empty() || now - last_change_ < settle) return {};
  std::vector<std::filesystem::path> changed(pending_.begin(), pending_.end());
  pending_.clear();
  return changed;
}

}  // namespace vkray
