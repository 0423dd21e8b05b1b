#include "gpu/shader_includes.h"

#include <algorithm>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "base/errors.h"

namespace vkray::gpu {
namespace {

// Skips blanks and comments from `at`; returns where the next token starts.
size_t skip_blanks(std::string_view text, size_t at) {
  while (at < text.size()) {
    if (text[at] == ' ' || text[at] == '\t' || text[at] == '\r' || text[at] == '\n') {
      ++at;
    } else if (text.substr(at, 2) == "//") {
      at = std::min(text.find('\n', at), text.size());
    } else if (text.substr(at, 2) == "/*") {
      const size_t end = text.find("*/", at + 2);
      at = end == std::string_view::npos ? text.size() : end + 2;
    } else {
      break;
    }
  }
  return at;
}

// Reads "#<directive> <word>" at `at` (blanks allowed after '#'); returns the word, or "" if the
// text there is not that directive.
std::string_view directive_word(std::string_view text, size_t& at, std::string_view directive) {
  at = skip_blanks(text, at);
  if (at >= text.size() || text[at] != '#') return {};
  at = text.find_first_not_of(" \t", at + 1);
  if (at == std::string_view::npos || text.substr(at, directive.size()) != directive) return {};
  at += directive.size();
  const size_t begin = text.find_first_not_of(" \t", at);
  if (begin == at || begin == std::string_view::npos) return {};
  at = std::min(text.find_first_of(" \t\r\n/", begin), text.size());
  return text.substr(begin, at - begin);
}

// A classic include guard: the first directives are "#ifndef X" and "#define X". Inside the file
// X is defined, so including it again from within reads nothing. (A file that #undefs its guard
// and includes itself again ends at kMaxIncludeDepth instead.)
bool has_include_guard(std::string_view text) {
  size_t at = 0;
  const std::string_view guard = directive_word(text, at, "ifndef");
  return !guard.empty() && directive_word(text, at, "define") == guard;
}

// Where a file's #if, #ifdef and #ifndef fail to balance with its #endif (an #elif, #else or #endif
// with none open, or one left open at the end): "line N: ..." for the first, "" when they balance.
// glslang's preprocessor follows conditionals from file to file, and some that begin in one file and
// end in another crash it (Debian 12's glslang, found by fuzzing): vkray asks that each file balance.
std::string unbalanced_conditionals(std::string_view text) {
  std::vector<size_t> open;  // the line of each #if still open
  bool in_comment = false;
  size_t line = 1;
  for (size_t at = 0; at < text.size(); ++line) {
    const size_t end = std::min(text.find('\n', at), text.size());
    std::string_view row = text.substr(at, end - at);
    at = end + 1;
    // A directive is the first token of a line that does not start inside a block comment.
    size_t i = 0;
    if (in_comment) {
      const size_t close = row.find("*/");
      if (close == std::string_view::npos) continue;
      in_comment = false;
      i = close + 2;
    }
    i = row.find_first_not_of(" \t", i);
    const bool directive = i != std::string_view::npos && row[i] == '#';
    // Whether the line leaves a block comment open (strings aside: GLSL has none).
    for (size_t c = 0; c + 1 < row.size(); ++c) {
      if (!in_comment && row.substr(c, 2) == "//") break;
      if (row.substr(c, 2) == (in_comment ? "*/" : "/*")) {
        in_comment = !in_comment;
        ++c;
      }
    }
    if (!directive) continue;
    const size_t word_begin = row.find_first_not_of(" \t", i + 1);
    if (word_begin == std::string_view::npos) continue;
    const std::string_view word = row.substr(word_begin, row.find_first_not_of("abcdefghijklmnopqrstuvwxyz", word_begin) - word_begin);
    if (word == "if" || word == "ifdef" || word == "ifndef") {
      open.push_back(line);
    } else if (word == "elif" || word == "else" || word == "endif") {
      if (open.empty()) return "line " + std::to_string(line) + ": #" + std::string(word) + " with no #if before it in this file";
      if (word == "endif") open.pop_back();
    }
  }
  if (!open.empty()) return "line " + std::to_string(open.back()) + ": an #if with no #endif in this file";
  return {};
}

// An IncludeResult that owns its text.
glslang::TShader::Includer::IncludeResult* result_owning(const std::string& header_name, std::string text) {
  auto owned = std::make_unique<std::string>(std::move(text));
  auto* result = new glslang::TShader::Includer::IncludeResult(header_name, owned->data(), owned->size(), owned.get());
  owned.release();
  return result;
}

}  // namespace

InputFile read_shader_file(const std::filesystem::path& file) { return read_input_file(file, kMaxShaderFileBytes); }

ShaderIncludes::ShaderIncludes(const std::filesystem::path& entry, std::vector<std::filesystem::path> dirs,
                               const std::vector<GeneratedInclude>& generated, ShaderFileReader read)
    : dirs_(std::move(dirs)), generated_(generated), read_(std::move(read)) {
  const std::filesystem::path entry_path = entry.lexically_normal();
  sources_.push_back(entry_path);
  chain_.push_back({nullptr, entry_path.string(), entry_path.filename().string()});
}

glslang::TShader::Includer::IncludeResult* ShaderIncludes::includeLocal(const char* header, const char* includer,
                                                                        size_t depth) {
  IncludeResult* result = include(header, std::filesystem::path(includer).parent_path(), depth);
  local_failed_ = result == nullptr || result->headerName.empty();
  if (local_failed_) local_error_ = result ? std::string(result->headerData, result->headerLength) : "";
  return result;
}

glslang::TShader::Includer::IncludeResult* ShaderIncludes::includeSystem(const char* header, const char*, size_t depth) {
  if (std::exchange(local_failed_, false)) return local_error_.empty() ? nullptr : error(local_error_);
  return include(header, {}, depth);
}

void ShaderIncludes::releaseInclude(IncludeResult* result) {
  if (!result) return;
  // glslang releases an include when it has read to its end (or at once, when it is empty or an
  // error): it leaves the chain then.
  const auto open = std::find_if(chain_.rbegin(), chain_.rend(), [&](const Open& o) { return o.result == result; });
  if (open != chain_.rend()) chain_.erase(std::next(open).base());
  delete static_cast<std::string*>(result->userData);
  delete result;
}

glslang::TShader::Includer::IncludeResult* ShaderIncludes::error(const std::string& message) {
  // An empty header name tells glslang that the text is an error, which it reports at the #include
  // ("'#include' : message for header name: x"; format_log in shader_compiler.cpp keeps the message).
  return result_owning("", message);
}

glslang::TShader::Includer::IncludeResult* ShaderIncludes::include(const std::string& header,
                                                                   const std::filesystem::path& local_dir, size_t depth) {
  // glslang counts the depth from 1 for a file the entry includes.
  // Each name quoted printably and briefly, and a long chain shown by its two ends: the message
  // stays one short line (a log line of many KB would also strain format_log's regular expressions).
  const auto chain_text = [&](const std::string& last) {
    std::string text;
    for (size_t i = 0; i < chain_.size(); ++i) {
      if (chain_.size() > 8 && i == 3) text += "... -> ";
      if (chain_.size() > 8 && i >= 3 && i + 4 < chain_.size()) continue;
      text += printable(chain_[i].name, 60) + " -> ";
    }
    return text + printable(last, 60);
  };
  if (depth > kMaxIncludeDepth)
    return error("#include nested more than " + std::to_string(kMaxIncludeDepth) + " deep: " + chain_text(header));
  if (++includes_ > kMaxIncludes)
    return error("#include \"" + printable(header, 60) + "\": the shader includes more than " +
                 std::to_string(kMaxIncludes) +
                 " files (counting a file each time it is included)");

  std::string key, text;
  bool generated = false;
  if (const auto g = std::find_if(generated_.begin(), generated_.end(), [&](const auto& gi) { return gi.name == header; });
      g != generated_.end()) {
    key = g->name + " (generated)";
    text = g->text;
    generated = true;
  } else {
    std::vector<std::filesystem::path> candidates;
    if (!local_dir.empty()) candidates.push_back(local_dir / header);
    for (const auto& dir : dirs_) candidates.push_back(dir / header);
    for (const auto& candidate : candidates) {
      InputFile input = read_(candidate);
      if (input.error == "not found") continue;
      if (!input.error.empty())
        return error("#include \"" + printable(header, 60) + "\": " +
                     printable(candidate.lexically_normal().string(), 200) + ": " + input.error);
      key = candidate.lexically_normal().string();
      text = std::move(input.text);
      break;
    }
    if (key.empty()) return nullptr;  // glslang reports "Could not process include directive"
  }

  included_bytes_ += text.size();
  if (included_bytes_ > kMaxIncludedBytes)
    return error("#include \"" + printable(header, 60) + "\": the shader's includes pass " + std::to_string(kMaxIncludedBytes >> 20) +
                 " MiB (counting a file each time it is included)");
  if (const std::string where = unbalanced_conditionals(text); !where.empty())
    return error("#include \"" + printable(header, 60) + "\": " + printable(key, 200) + ", " + where +
                 " (each included file's conditionals must balance)");
  const bool open = std::any_of(chain_.begin(), chain_.end(), [&](const Open& o) { return o.key == key; });
  if (open && !has_include_guard(text)) return error("#include cycle: " + chain_text(header));
  if (!generated && std::find(sources_.begin(), sources_.end(), key) == sources_.end())
    sources_.push_back(key);
  // The header name becomes the file name in glslang's messages for code in this file.
  IncludeResult* result = result_owning(key, std::move(text));
  chain_.push_back({result, key, header});
  return result;
}

}  // namespace vkray::gpu
