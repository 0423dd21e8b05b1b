#include "base/atomic_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "base/errors.h"
#include "base/interrupt.h"

namespace vkray {

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
  std::string pattern = (target_.has_parent_path() ? target_.parent_path() / "" : std::filesystem::path())
                            .string() + "." + target_.filename().string() + ".tmp-XXXXXX";
  // Registered, so that even a forced exit after Ctrl-C removes it.
  const int fd = create_temporary_file(pattern);
  if (fd < 0) throw OutputError(target_.string() + ": cannot create file: " + std::strerror(errno));
  temp_ = pattern;
  file_ = fdopen(fd, "wb");
  if (!file_) {
    const int error = errno;
    ::close(fd);
    std::error_code ec;
    std::filesystem::remove(temp_, ec);
    unregister_temporary_file(temp_);
    throw OutputError(target_.string() + ": cannot open file: " + std::strerror(error));
  }
}

AtomicFile::~AtomicFile() {
  if (file_) std::fclose(file_);
  if (!committed_) {
    std::error_code ec;
    std::filesystem::remove(temp_, ec);
    unregister_temporary_file(temp_);
  }
}

void AtomicFile::commit() {
  const bool write_failed = std::ferror(file_) != 0;
  const bool close_failed = std::fclose(file_) != 0;
  file_ = nullptr;
  // mkstemp creates the file 0600; give it the mode a plain open() would (0666 less the umask).
  const mode_t mask = ::umask(0);
  ::umask(mask);
  if (::chmod(temp_.c_str(), 0666 & ~mask) != 0 && !write_failed && !close_failed)
    throw OutputError(target_.string() + ": cannot set file mode: " + std::strerror(errno));
  if (write_failed || close_failed) throw OutputError(target_.string() + ": write failed: " + std::strerror(errno));
  // Not after an interrupt request: a command stopped by Ctrl-C writes nothing.
  commit_unless_interrupted(temp_, [this] {
    std::error_code ec;
    std::filesystem::rename(temp_, target_, ec);
    if (ec) throw OutputError(target_.string() + ": cannot rename into place: " + ec.message());
  });
  committed_ = true;
}

void write_file_atomically(const std::filesystem::path& file, std::string_view text) {
  AtomicFile out(file);
  std::fwrite(text.data(), 1, text.size(), out.get());
  out.commit();
}

}  // namespace vkray
