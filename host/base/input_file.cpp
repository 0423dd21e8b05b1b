#include "base/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <new>

#include "base/errors.h"
#include "base/interrupt.h"

namespace vkray {
namespace {

// Closes the descriptor on every path out.
struct Descriptor {
  int fd;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

std::string kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "is a directory";
  if (S_ISFIFO(mode)) return "is a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "is a character device";
  if (S_ISBLK(mode)) return "is a block device";
  if (S_ISSOCK(mode)) return "is a socket";
  return "is not a regular file";
}

// "64 MiB" for a whole number of MiB, else the bytes: a file just past a limit of 64 MiB is not
// "64 MiB" too.
std::string size_text(uint64_t bytes) {
  constexpr uint64_t kMiB = uint64_t(1) << 20;
  return bytes >= kMiB && bytes % kMiB == 0 ? std::to_string(bytes / kMiB) + " MiB" : std::to_string(bytes) + " bytes";
}

}  // namespace

InputFile read_input_file(const std::filesystem::path& file, uint64_t max_bytes) {
  InputFile result;
  // O_NONBLOCK: opening a FIFO must not wait for a writer; it is refused below by its type.
  const Descriptor in{::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)};
  if (in.fd < 0) {
    result.error = errno == ENOENT ? "not found" : std::strerror(errno);
    return result;
  }
  struct stat info {};
  if (::fstat(in.fd, &info) != 0) {
    result.error = std::strerror(errno);
    return result;
  }
  if (!S_ISREG(info.st_mode)) {
    result.error = kind_of(info.st_mode) + ", not a regular file";
    return result;
  }
  const uint64_t size = uint64_t(info.st_size);
  if (size > max_bytes) {
    result.error = "is " + size_text(size) + "; vkray reads files of at most " + size_text(max_bytes);
    return result;
  }
  try {
    result.text.resize(size_t(size));
  } catch (const std::bad_alloc&) {
    throw LimitError(file.string() + ": not enough host memory to read its " + size_text(size));
  }
  // In chunks, so that a Ctrl-C is seen while a large mesh is read from a slow disk.
  constexpr size_t kChunk = size_t(8) << 20;
  size_t done = 0;
  while (done < result.text.size()) {
    throw_if_interrupted();
    const ssize_t got = ::read(in.fd, result.text.data() + done, std::min(kChunk, result.text.size() - done));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) {
      result.error = std::string("read error: ") + std::strerror(errno);
      return result;
    }
    if (got == 0) break;  // the file shrank while it was read: take what is there
    done += size_t(got);
  }
  result.text.resize(done);
  return result;
}

}  // namespace vkray
