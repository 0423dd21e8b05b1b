// Output files written whole or not at all: under a temporary name in the target's folder, renamed
// into place by commit(), so that a failure (a full disk, Ctrl-C) never leaves a partial file.
#pragma once

#include <cstdio>
#include <filesystem>
#include <initializer_list>
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
  void commit() { commit_together({this}); }

  // Renames every file into place, or none: files that belong together (an image and its record).
  // Every write is checked before the first rename, the renames happen under one interrupt check,
  // and when a rename fails the files the earlier ones replaced are put back. Each is kept meanwhile
  // under a second name beside it: a hard link, or on a file system without hard links the old file
  // itself, renamed aside until the renames are done (a reader at that moment finds no file there).
  // Throws OutputError naming the file whose write or rename failed, or whose old file could be kept
  // neither way (then nothing is replaced); Cancelled.
  static void commit_together(std::initializer_list<AtomicFile*> files);
  // The same, keeping an old file by `link` (link(2)'s signature): a test passes one that fails as
  // a file system without hard links does.
  using LinkFunction = int (*)(const char* from, const char* to);
  static void commit_together(std::initializer_list<AtomicFile*> files, LinkFunction link);

 private:
  // Closes the file and gives it its mode. Throws OutputError when a write failed.
  void finish();

  std::filesystem::path target_, temp_;
  FILE* file_ = nullptr;
  bool committed_ = false;
};

// `text` as the whole of `file`, through an AtomicFile. Throws OutputError.
void write_file_atomically(const std::filesystem::path& file, std::string_view text);

}  // namespace vkray
