// Ctrl-C and SIGTERM as the library sees them: one process-wide request to stop. A face turns the
// process's signals into a request here (the command line in cli/stop_signals.h); every long loop
// of the library (reading files, parsing meshes, building the BVH, packing, both renderers, writing
// images) polls it and throws Cancelled, so whatever stage a signal arrives in ends within a
// fraction of a second, unwinding normally and writing nothing.
//
// A child made by fork() starts with no request, no work in flight and no temporary files of its
// own: the parent's threads did not come along, and what they held must not stall or remove anything
// in the child.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

namespace vkray {

// Async-signal-safe: a lock-free atomic store.
void request_interrupt() noexcept;
bool interrupt_requested() noexcept;
// Forgets a request (a face or a test that goes on after one).
void clear_interrupt() noexcept;
// A descriptor that polls readable while a request stands, for a face that waits in poll() (the
// file watcher of `vkray watch`).
int interrupt_fd() noexcept;
// Throws Cancelled when a stop was requested.
void throw_if_interrupted();

// ---- Work in flight ------------------------------------------------------------------------------
// A face that runs several pieces of work at once (the Python module: a render on each of several
// threads) marks each with a WorkInFlight while it runs. A request then stands until every piece in
// flight when it came has ended, and a piece that starts meanwhile waits for that first: no piece's
// end can hide the request from another, and none starts already stopped. A request that finds
// nothing in flight (a Ctrl-C between renders) is forgotten when the next piece starts. A face that
// runs one piece and then exits (the command line) needs none of this.
class WorkInFlight {
 public:
  WorkInFlight();
  ~WorkInFlight();
  WorkInFlight(const WorkInFlight&) = delete;
  WorkInFlight& operator=(const WorkInFlight&) = delete;
};
// Requests a stop when work is in flight and waits until none is (a process about to end).
void stop_work_in_flight() noexcept;

// ---- Files that must not outlive a forced exit -----------------------------------------------------
// A temporary output is created here and registered while it exists. If a stage cannot stop in time
// and the face ends the process without unwinding (cli/stop_signals.h), it first removes these
// files, so even then nothing is left behind.
// Creates a file from a mkstemp() pattern (rewritten to the name made) and returns its descriptor,
// or -1 with errno set; throws Cancelled after an interrupt request, under the same lock as the
// removal, so no file can appear after it.
int create_temporary_file(std::string& pattern);
void unregister_temporary_file(const std::filesystem::path& file);
// Runs `commit` (the rename of a temporary file into place) unless a stop was requested, and
// unregisters `file`; atomic with respect to remove_temporary_files(). Throws Cancelled.
void commit_unless_interrupted(const std::filesystem::path& file, const std::function<void()>& commit);
// Removes every registered file and blocks later commits: the first step of a forced exit.
void remove_temporary_files() noexcept;

}  // namespace vkray
