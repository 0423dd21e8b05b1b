#include "base/json_document.h"

#include <algorithm>
#include <vector>

#include "base/errors.h"
#include "base/interrupt.h"

namespace vkray {
namespace {

using json = nlohmann::json;

// Builds the document from the parser's events (nlohmann's SAX interface), with vkray's rules on top.
// Its parser-with-callback is not used: at the end of every object or array it scans the whole
// parent container for discarded values (nlohmann/json 3.11.2, Debian 12), so a scene of N objects
// took N^2 steps. Here each event costs O(log k) at most (a key looked up among its k siblings).
class DocumentBuilder {
 public:
  using string_t = json::string_t;

  explicit DocumentBuilder(const std::filesystem::path& file) : file_(file) {}

  json take() { return std::move(root_); }

  bool null() { return add(nullptr); }
  bool boolean(bool value) { return add(value); }
  bool number_integer(json::number_integer_t value) { return add(value); }
  bool number_unsigned(json::number_unsigned_t value) { return add(value); }
  bool number_float(json::number_float_t value, const string_t&) { return add(value); }
  bool string(string_t& value) { return add(std::move(value)); }
  bool binary(json::binary_t& value) { return add(std::move(value)); }

  bool start_object(size_t) { return open(json::object()); }
  bool start_array(size_t) { return open(json::array()); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }

  bool key(string_t& key) {
    Frame& top = frames_.back();
    if (top.value->contains(key))
      fail(frames_.size() - 1, "the key \"" + printable(key) + "\" is given twice");
    top.key = std::move(key);
    return true;
  }

  // Rethrows the parser's own exception (its type and text), which parse_json_document turns into a
  // SceneError with the position.
  template <class Exception>
  [[noreturn]] bool parse_error(size_t, const std::string&, const Exception& error) {
    throw error;
  }

 private:
  struct Frame {
    json* value;      // the object or array being filled
    string_t key;     // in an object: the key whose value is being read
  };

  // Places a value where the parser is: the root, the next element of an array, or the current key's
  // value. A reference into the parent stays valid while the value is open: nothing is added to the
  // parent before it closes.
  json* place(json&& value) {
    if (++events_ % 65536 == 0) throw_if_interrupted();  // a 64 MiB file takes a second or two
    if (frames_.empty()) {
      root_ = std::move(value);
      return &root_;
    }
    Frame& top = frames_.back();
    if (top.value->is_array()) {
      top.value->push_back(std::move(value));
      return &top.value->back();
    }
    json& slot = (*top.value)[top.key];
    slot = std::move(value);
    return &slot;
  }

  bool add(json&& value) {
    place(std::move(value));
    return true;
  }

  bool open(json&& container) {
    if (frames_.size() >= kMaxJsonDepth)
      fail(frames_.size(), "nesting deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    json* value = place(std::move(container));
    frames_.push_back({value, {}});
    return true;
  }

  bool close() {
    frames_.pop_back();
    return true;
  }

  // Fails at the JSON pointer that the first `depth` frames lead to.
  [[noreturn]] void fail(size_t depth, const std::string& what) const {
    std::string pointer;
    for (size_t i = 0; i < depth; ++i) {
      pointer += '/';
      const Frame& frame = frames_[i];
      // In an array, the element being read is the next one; an open container is already its last.
      const bool open_child = i + 1 < frames_.size();
      pointer += frame.value->is_object() ? printable(frame.key)
                                          : std::to_string(frame.value->size() - (open_child ? 1 : 0));
    }
    throw SceneError(file_.string() + ": " + (pointer.empty() ? "top level" : printable(pointer, 100)) + ": " + what);
  }

  const std::filesystem::path& file_;
  json root_;
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
  DocumentBuilder builder(file);
  try {
    json::sax_parse(text, &builder, json::input_format_t::json, /*strict=*/true, /*ignore_comments=*/true);
    return builder.take();
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
