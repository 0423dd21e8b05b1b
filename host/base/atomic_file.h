// Output files written whole or not at all: under a temporary name in the target's folder, renamed
// into place by commit(), so that a failure (a full disk, Ctrl-C) never leaves a partial file.
#pragma once

#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <string_view>
#include <vector>

#include <unistd.h>

namespace vkray {

// link(2)'s signature: how an old file is kept under a second name (a test passes one that fails
// as a file system without hard links does).
using LinkFunction = int (*)(const char* from, const char* to);

// One rename of rename_together: `from` over `to`, the old `to` kept meanwhile as `keep_as` (a
// name of its own in `to`'s file system).
struct Rename {
  std::filesystem::path from, to, keep_as;
};

// Renames every `from` over its `to`, all or none: files that belong together (an image and its
// record; the frames of one job). Before each rename the old target is kept under its second name:
// a hard link, which leaves the target in place, so that a target that was there is there at every
// moment, as its old file or its new one; on a file system without hard links the old file itself,
// renamed aside until the renames are done (a reader at that moment finds no file there). When a
// rename fails, the targets the earlier ones replaced are put back (and those that were not there
// removed). A folder in a target's place is never replaced. Throws OutputError naming the file whose
// rename failed, or whose old file could be kept neither way (then nothing is replaced), and where
// an old file is that could not be put back.
void rename_together(const std::vector<Rename>& renames, LinkFunction link = ::link);

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

  // Renames every file into place, or none (rename_together): files that belong together (an image
  // and its record). Every write is checked before the first rename, and the renames happen under
  // one interrupt check. Throws OutputError naming the file whose write failed, rename_together's
  // OutputError; Cancelled. `link` as for rename_together.
  static void commit_together(std::initializer_list<AtomicFile*> files, LinkFunction link = ::link);

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
