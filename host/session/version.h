// Which vkray this is: what `vkray --version` prints and every report a user may attach to a bug
// carries (vkray bench --json, vkray parity --json).
#pragma once

namespace vkray {

// "0.1.0 (commit 0123456789ab)", with " + changes" when built from a tree that differs from it.
const char* version_string();

}  // namespace vkray
