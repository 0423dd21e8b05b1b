// Every error vkray raises, one type per kind of failure, and the process exit code of each kind.
// What a dependency throws through the library (Vulkan-Hpp's vk::SystemError, std::bad_alloc)
// gets one of these kinds' exit codes in session/failure.h. Each face maps them once: the command
// line to a message and an exit code, the Python module to its exception classes.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

namespace vkray {

// Process exit codes, each with the line `vkray --help` shows for it (docs/commands.md lists them too):
// X(name, code, help).
#define VKRAY_EXIT_CODES(X)                                                                                    \
  X(kExitOk, 0, "success")                                                                                     \
  /* a scene, mesh, shader or output file; an input past a limit */                                          \
  X(kExitBadInput, 1,                                                                                          \
    "bad input: scene, mesh or shader file, an output file that cannot be written, or an input past a\n"      \
    "     limit (primitives, sizes, host memory, inotify watches)")                                            \
  X(kExitUsage, 2, "usage: unknown command or option, bad option value")                                      \
  X(kExitDevice, 3, "Vulkan or device failure (no device, failed call, timeout, validation message)")        \
  /* `vkray parity`, `vkray check`: a result, not an error */                                                 \
  X(kExitParityFailed, 4, "parity, check: the GPU and CPU images differ beyond the documented tolerance")            \
  /* an invariant that does not hold (sysexits' EX_SOFTWARE) */                                               \
  X(kExitInternal, 70, "internal error: a bug in vkray (please report it)")                                   \
  /* the shell's convention for Ctrl-C */                                                                     \
  X(kExitInterrupted, 130, "interrupted by SIGINT (Ctrl-C) or SIGTERM; nothing was written")

enum ExitCode : int {
#define VKRAY_EXIT_CODE_ENUM(name, code, help) name = code,
  VKRAY_EXIT_CODES(VKRAY_EXIT_CODE_ENUM)
#undef VKRAY_EXIT_CODE_ENUM
};

// "Exit codes:" and a line for each, as `vkray --help` ends.
inline std::string exit_codes_help() {
  std::string text = "Exit codes:\n";
#define VKRAY_EXIT_CODE_HELP(name, code, help) text += "  " + std::to_string(code) + "  " + help + "\n";
  VKRAY_EXIT_CODES(VKRAY_EXIT_CODE_HELP)
#undef VKRAY_EXIT_CODE_HELP
  return text;
}

// The base of every error vkray raises. The message is complete: it names the file and the key or
// line, or the Vulkan call and its result.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
  virtual ExitCode exit_code() const = 0;
};

// ---- Input: something the user gave cannot be used (exit 1) -------------------------------------
struct InputError : Error {
  using Error::Error;
  ExitCode exit_code() const override { return kExitBadInput; }
};
// A scene file, or a file it references: the message names the scene file and the key.
struct SceneError : InputError {
  using InputError::InputError;
};
// A mesh file; when read for a scene, the message names the scene's key too.
struct MeshError : SceneError {
  using SceneError::SceneError;
};
// A shader file: one "file:line: error: message" line per problem, for the file that has it.
struct ShaderError : InputError {
  using InputError::InputError;
};
// An output file that cannot be written (its folder, its type, the disk).
struct OutputError : InputError {
  using InputError::InputError;
};
// An input past a limit of vkray's (the BVH's primitive count) or of this machine's (sizes past 64
// bits, host memory, inotify watches); the message names the limit.
struct LimitError : InputError {
  using InputError::InputError;
};

// ---- Usage: an option value the command line or a caller gave is out of range (exit 2) ----------
struct UsageError : Error {
  using Error::Error;
  ExitCode exit_code() const override { return kExitUsage; }
};

// ---- Device: Vulkan or the device failed (exit 3) -------------------------------------------------
// No device, a failed call (named with its VkResult), a validation message, a scene or image past a
// device limit.
struct DeviceError : Error {
  using Error::Error;
  ExitCode exit_code() const override { return kExitDevice; }
};
// The device was lost (a driver reset, a GPU watchdog): nothing on it can be used any more, but a
// new session may open it again.
struct DeviceLostError : DeviceError {
  using DeviceError::DeviceError;
};
// A submission did not finish within its timeout. Its work may still be running on the device, so
// what it uses stays alive (the session keeps it until the device is done with it).
struct TimeoutError : DeviceError {
  using DeviceError::DeviceError;
};

// ---- Interrupted: a caller's cancel callback asked to stop (exit 130) ----------------------------
// Raised between units of work (tiles, rows): nothing is left running, nothing was written.
struct Cancelled : Error {
  Cancelled() : Error("interrupted") {}
  ExitCode exit_code() const override { return kExitInterrupted; }
};

// ---- Internal: an invariant of vkray's own does not hold, a bug (exit 70) -----------------------
struct InternalError : Error {
  using Error::Error;
  ExitCode exit_code() const override { return kExitInternal; }
};

// Text from a user's file (or a message quoting it), fit to print on one line: control characters
// (escape sequences, newlines) and bytes that are not UTF-8 become '?', and text past `max_length`
// bytes is cut with "...". Valid UTF-8 (a name with accents) prints as it is.
inline std::string printable(std::string_view text, size_t max_length = 60) {
  std::string out;
  size_t i = 0;
  while (i < text.size() && i < max_length) {
    const auto byte = static_cast<unsigned char>(text[i]);
    // The length of a well-formed UTF-8 sequence starting here (RFC 3629), or 0.
    size_t length = byte < 0x80 ? 1 : byte >= 0xc2 && byte <= 0xdf ? 2 : byte >= 0xe0 && byte <= 0xef ? 3
                  : byte >= 0xf0 && byte <= 0xf4 ? 4 : 0;
    for (size_t k = 1; k < length; ++k)
      if (i + k >= text.size() || (static_cast<unsigned char>(text[i + k]) & 0xc0) != 0x80) length = 0;
    const bool control = byte < 0x20 || byte == 0x7f || (byte == 0xc2 && length == 2 && static_cast<unsigned char>(text[i + 1]) < 0xa0);
    if (length == 0 || control || i + length > max_length) {
      out += '?';
      i += length ? length : 1;
    } else {
      out.append(text.substr(i, length));
      i += length;
    }
  }
  if (text.size() > max_length) out += "...";
  return out;
}

// printable() for a whole message of up to about max_length characters: a longer one loses its
// middle, not its end, so that a long path keeps the file's own name and what is wrong with it
// ("/home/a/very/lo ... /deep/scene.json: not found").
inline std::string printable_middle(std::string_view text, size_t max_length) {
  if (text.size() <= max_length) return printable(text, max_length);
  // Both cuts fall between characters, not inside one (UTF-8 continuation bytes are 10xxxxxx).
  const auto inside = [&](size_t at) { return at < text.size() && (static_cast<unsigned char>(text[at]) & 0xc0) == 0x80; };
  constexpr std::string_view kCut = " ... ";
  const size_t room = max_length > 2 * kCut.size() ? max_length - kCut.size() : max_length;
  size_t head = room / 3;
  while (head > 0 && inside(head)) --head;
  size_t tail_start = text.size() - (room - room / 3);
  while (inside(tail_start)) ++tail_start;
  std::string out = printable(text.substr(0, head), head);
  return out + std::string(kCut) + printable(text.substr(tail_start), max_length);
}

}  // namespace vkray
