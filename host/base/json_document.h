// JSON text to a document, with the rules vkray adds to JSON: comments are allowed, nesting stops at
// kMaxJsonDepth levels, and a key given twice in one object is an error (RFC 8259 leaves it to the
// reader; a later value silently replacing an earlier one hides typos). Errors are SceneErrors that
// name the file and the line and column (syntax) or the JSON pointer (depth, duplicate keys).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace vkray {

// No scene needs more than a handful of levels; the limit keeps every recursive walk of the document
// (messages, checks) far from the stack's end.
constexpr size_t kMaxJsonDepth = 64;

nlohmann::json parse_json_document(std::string_view text, const std::filesystem::path& file);

// A value quoted for a one-line message: printable, and cut after about 60 characters however
// large or deep the value is.
std::string brief(const nlohmann::json& value);

}  // namespace vkray
