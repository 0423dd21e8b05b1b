// Output files written whole or not at all: under a temporary name in the target's folder, renamed
// into place by commit(), so that a failure (a full disk, Ctrl-C) never leaves a partial file.
#pragma once

#include <cstdio>
#include <filesystem>
#include <string_view>

namespace vkray {

class AtomicFile {
 public:
  // Creates the temporary file. Throws OutputError.
  explicit AtomicFile(std::filesystem::path target);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();  // removes the temporary file unless committed
  FILE* get() { return file_; }
  // Renames the file into place, unless an interrupt was requested (base/interrupt.h): then it is
  // removed. Throws OutputError when a write failed.
  void commit();

 private:
  std::filesystem::path target_, temp_;
  FILE* file_ = nullptr;
  bool committed_ = false;
};

// `text` as the whole of `file`, through an AtomicFile. Throws OutputError.
void write_file_atomically(const std::filesystem::path& file, std::string_view text);

}  // namespace vkray
