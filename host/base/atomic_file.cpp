#include "base/atomic_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <vector>

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

void AtomicFile::finish() {
  const bool write_failed = std::ferror(file_) != 0;
  const bool close_failed = std::fclose(file_) != 0;
  file_ = nullptr;
  // mkstemp creates the file 0600; give it the mode a plain open() would (0666 less the umask).
  const mode_t mask = ::umask(0);
  ::umask(mask);
  if (::chmod(temp_.c_str(), 0666 & ~mask) != 0 && !write_failed && !close_failed)
    throw OutputError(target_.string() + ": cannot set file mode: " + std::strerror(errno));
  if (write_failed || close_failed) throw OutputError(target_.string() + ": write failed: " + std::strerror(errno));
}

namespace {

// What a target held before a rename replaced it, so that the rename can be undone.
struct Previous {
  enum { absent, kept, unknown } state = unknown;
  std::filesystem::path kept_as;  // a hard link to the old file, when kept
};

Previous keep_previous(const std::filesystem::path& target, const std::filesystem::path& temp) {
  Previous previous;
  std::filesystem::path link = temp;
  link += ".old";  // unique: the temporary name is
  if (::link(target.c_str(), link.c_str()) == 0) {
    previous.state = Previous::kept;
    previous.kept_as = link;
  } else if (errno == ENOENT) {
    previous.state = Previous::absent;
  }  // else a file system without hard links: the old file cannot be put back
  return previous;
}

void put_back(const std::filesystem::path& target, const Previous& previous) {
  std::error_code ignored;
  if (previous.state == Previous::kept) std::filesystem::rename(previous.kept_as, target, ignored);
  if (previous.state == Previous::absent) std::filesystem::remove(target, ignored);
}

// Removes the second names of the old files (once put back, a name is gone already).
void forget(const std::vector<Previous>& previous) {
  std::error_code ignored;
  for (const Previous& p : previous)
    if (p.state == Previous::kept) std::filesystem::remove(p.kept_as, ignored);
}

}  // namespace

void AtomicFile::commit_together(std::initializer_list<AtomicFile*> files) {
  // Every write is checked first: a full disk or a size limit leaves every target as it was.
  for (AtomicFile* file : files) file->finish();
  std::vector<Previous> previous(files.size());
  const bool undoable = files.size() > 1;
  // Not after an interrupt request: a command stopped by Ctrl-C writes nothing.
  commit_unless_interrupted(files.begin()[0]->temp_, [&] {
    size_t renamed = 0;
    for (; renamed < files.size(); ++renamed) {
      AtomicFile& file = *files.begin()[renamed];
      if (undoable) previous[renamed] = keep_previous(file.target_, file.temp_);
      std::error_code ec;
      std::filesystem::rename(file.temp_, file.target_, ec);
      if (!ec) continue;
      for (size_t i = renamed; i-- > 0;) put_back(files.begin()[i]->target_, previous[i]);
      forget(previous);
      throw OutputError(file.target_.string() + ": cannot rename into place: " + ec.message());
    }
    forget(previous);
  });
  for (AtomicFile* file : files) {
    file->committed_ = true;
    unregister_temporary_file(file->temp_);  // the first one is already
  }
}

void write_file_atomically(const std::filesystem::path& file, std::string_view text) {
  AtomicFile out(file);
  std::fwrite(text.data(), 1, text.size(), out.get());
  out.commit();
}

}  // namespace vkray
