#include "scene/json_document.h"

#include <algorithm>
#include <set>
#include <vector>

#include "base/errors.h"
#include "base/interrupt.h"

namespace vkray {
namespace {

using json = nlohmann::json;

// Where the parser is: one frame per open object or array, so that a duplicate key or a nesting too
// deep can be named by its JSON pointer.
class Structure {
 public:
  explicit Structure(const std::filesystem::path& file) : file_(file) {}

  bool on_event(json::parse_event_t event, const json& parsed) {
    if (++events_ % 65536 == 0) throw_if_interrupted();  // a 64 MiB file takes a second or two
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start:
        if (frames_.size() >= kMaxJsonDepth)
          fail(frames_.size(), "nesting deeper than " + std::to_string(kMaxJsonDepth) + " levels");
        frames_.push_back({event == json::parse_event_t::object_start, {}, {}, 0});
        break;
      case json::parse_event_t::key: {
        Frame& top = frames_.back();
        top.key = parsed.get<std::string>();
        if (!top.keys.insert(top.key).second)
          fail(frames_.size() - 1, "the key \"" + printable(top.key) + "\" is given twice");
        break;
      }
      case json::parse_event_t::value:
        if (!frames_.empty() && !frames_.back().object) ++frames_.back().index;
        break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        frames_.pop_back();
        if (!frames_.empty() && !frames_.back().object) ++frames_.back().index;
        break;
    }
    return true;  // keep every value
  }

 private:
  struct Frame {
    bool object;
    std::set<std::string> keys;
    std::string key;  // the key whose value is being read
    size_t index;     // in an array: the element being read
  };

  // Fails at the JSON pointer that the first `depth` frames lead to.
  [[noreturn]] void fail(size_t depth, const std::string& what) const {
    std::string pointer;
    for (size_t i = 0; i < depth; ++i) {
      pointer += '/';
      pointer += frames_[i].object ? printable(frames_[i].key) : std::to_string(frames_[i].index);
    }
    throw SceneError(file_.string() + ": " + (pointer.empty() ? "top level" : printable(pointer, 100)) + ": " + what);
  }

  const std::filesystem::path& file_;
  std::vector<Frame> frames_;
  size_t events_ = 0;
};

// "[json.exception.parse_error.101] parse error at line 3, column 5: syntax error ..." -> "syntax error ..."
std::string strip_json_prefix(const std::string& what) {
  const auto column = what.find("column ");
  const auto colon = what.find(": ", column == std::string::npos ? 0 : column);
  return colon == std::string::npos ? what : what.substr(colon + 2);
}

// ":LINE:COLUMN" of the byte at `offset` (0-based) in `text`.
std::string position(std::string_view text, size_t offset) {
  const auto prefix = text.substr(0, std::min(offset, text.size()));
  const size_t line = 1 + static_cast<size_t>(std::count(prefix.begin(), prefix.end(), '\n'));
  const auto newline = prefix.rfind('\n');
  return ":" + std::to_string(line) + ":" +
         std::to_string(prefix.size() - (newline == std::string_view::npos ? 0 : newline + 1) + 1);
}

void append_brief(const json& value, std::string& out, size_t limit) {
  if (out.size() > limit) return;
  if (value.is_array() || value.is_object()) {
    out += value.is_array() ? '[' : '{';
    bool first = true;
    for (auto it = value.begin(); it != value.end() && out.size() <= limit; ++it) {
      out += first ? "" : ", ";
      first = false;
      if (value.is_object()) out += json(it.key()).dump() + ": ";
      append_brief(*it, out, limit);
    }
    out += value.is_array() ? ']' : '}';
  } else {
    out += value.dump();  // a string is quoted with its escapes
  }
}

}  // namespace

json parse_json_document(std::string_view text, const std::filesystem::path& file) {
  Structure structure(file);
  try {
    return json::parse(
        text, [&structure](int, json::parse_event_t event, json& parsed) { return structure.on_event(event, parsed); },
        /*allow_exceptions=*/true, /*ignore_comments=*/true);
  } catch (const json::parse_error& e) {
    // e.byte is the 1-based offset of the character where parsing stopped.
    throw SceneError(file.string() + position(text, e.byte == 0 ? 0 : e.byte - 1) + ": " +
                     printable(strip_json_prefix(e.what()), 200));
  } catch (const json::exception& e) {
    // A number too large for a double ("number overflow parsing '1e400'"): no position is given,
    // so point at the number's first occurrence.
    std::string message = e.what();
    const auto bracket = message.find("] ");
    if (bracket != std::string::npos) message = message.substr(bracket + 2);
    std::string where = file.string();
    const auto quote = message.find('\'');
    if (quote != std::string::npos) {
      const auto end = message.find('\'', quote + 1);
      const auto at = text.find(message.substr(quote + 1, end - quote - 1));
      if (at != std::string_view::npos) where += position(text, at);
    }
    throw SceneError(where + ": " + printable(message, 200));
  }
}

std::string brief(const json& value) {
  constexpr size_t kLimit = 60;
  std::string out;
  append_brief(value, out, kLimit);
  return printable(out, kLimit);
}

}  // namespace vkray
