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
  enum { absent, kept, moved_aside, unknown } state = unknown;
  std::filesystem::path kept_as;  // the old file's second name, when kept or moved aside
};

// Keeps what `target` holds as `keep_as`: a hard link, which leaves the target in place; or, on a
// file system without hard links (FAT, some network and FUSE file systems), the old file itself,
// renamed there for the moment of the renames. A folder in the target's place is left where it is:
// no rename replaces it. Throws OutputError when an old file can be kept neither way, before
// anything was replaced.
Previous keep_previous(const std::filesystem::path& target, const std::filesystem::path& keep_as, LinkFunction link) {
  Previous previous;
  previous.kept_as = keep_as;
  struct stat status {};
  if (::lstat(target.c_str(), &status) != 0 && errno == ENOENT) {
    previous.state = Previous::absent;
  } else if (S_ISDIR(status.st_mode)) {
    previous.state = Previous::unknown;
  } else if (link(target.c_str(), previous.kept_as.c_str()) == 0) {
    previous.state = Previous::kept;
  } else if (errno == ENOENT) {
    previous.state = Previous::absent;
  } else if (::rename(target.c_str(), previous.kept_as.c_str()) == 0) {
    previous.state = Previous::moved_aside;
  } else if (errno == ENOENT) {
    previous.state = Previous::absent;
  } else {
    throw OutputError(target.string() + ": cannot keep the old file while the files that change with it are renamed into place: " +
                      std::strerror(errno));
  }
  return previous;
}

// Puts back what the first `count` renames replaced, the last first. Returns what could not be put
// back ("; the old FILE is kept as NAME" for each), for the error's message: an old file whose rename
// back fails stays under its second name.
std::string put_back(const std::vector<Rename>& renames, std::vector<Previous>& previous, size_t count) {
  std::string stranded;
  for (size_t i = count; i-- > 0;) {
    Previous& p = previous[i];
    std::error_code ec;
    if (p.state == Previous::absent) std::filesystem::remove(renames[i].to, ec);
    if (p.state != Previous::kept && p.state != Previous::moved_aside) continue;
    std::filesystem::rename(p.kept_as, renames[i].to, ec);
    if (ec) stranded += "; the old " + renames[i].to.string() + " is kept as " + p.kept_as.string();
    p.state = Previous::unknown;  // put back, or left where it is
  }
  return stranded;
}

// Removes the second names of the old files that were not put back: links, or (after a rename over
// the target) the old files themselves.
void forget(const std::vector<Previous>& previous) {
  std::error_code ignored;
  for (const Previous& p : previous)
    if (p.state == Previous::kept || p.state == Previous::moved_aside) std::filesystem::remove(p.kept_as, ignored);
}

}  // namespace

void rename_together(const std::vector<Rename>& renames, LinkFunction link) {
  std::vector<Previous> previous(renames.size());
  const bool undoable = renames.size() > 1;  // a single rename that fails has replaced nothing
  for (size_t renamed = 0; renamed < renames.size(); ++renamed) {
    const Rename& r = renames[renamed];
    try {
      if (undoable) previous[renamed] = keep_previous(r.to, r.keep_as, link);
    } catch (const OutputError& e) {
      const std::string stranded = put_back(renames, previous, renamed);
      forget(previous);
      throw OutputError(e.what() + stranded);
    }
    std::error_code ec;
    std::filesystem::rename(r.from, r.to, ec);
    if (!ec) continue;
    // The earlier targets as they were, and this one too if its old file was moved aside.
    const size_t changed = renamed + (previous[renamed].state == Previous::moved_aside ? 1 : 0);
    const std::string stranded = put_back(renames, previous, changed);
    forget(previous);
    throw OutputError(r.to.string() + ": cannot rename into place: " + ec.message() + stranded);
  }
  forget(previous);
}

void AtomicFile::commit_together(std::initializer_list<AtomicFile*> files, LinkFunction link) {
  // Every write is checked first: a full disk or a size limit leaves every target as it was.
  for (AtomicFile* file : files) file->finish();
  std::vector<Rename> renames;
  for (AtomicFile* file : files) {
    std::filesystem::path keep_as = file->temp_;
    keep_as += ".old";  // as unique as the temporary file's own name
    renames.push_back({file->temp_, file->target_, keep_as});
  }
  // Not after an interrupt request: a command stopped by Ctrl-C writes nothing.
  commit_unless_interrupted(files.begin()[0]->temp_, [&] { rename_together(renames, link); });
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
