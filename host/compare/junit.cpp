#include "compare/junit.h"

#include <cstdio>

namespace vkray {
namespace {

// The length of the valid UTF-8 sequence at text[i] whose code point XML 1.0 allows, or 0.
size_t xml_char_length(const std::string& text, size_t i) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char c = byte(i);
  if (c < 0x80) return (c >= 0x20 || c == '\t' || c == '\n' || c == '\r') ? 1 : 0;
  const size_t length = c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 ? 2 : 0;
  if (length == 0 || c > 0xF4 || i + length > text.size()) return 0;
  uint32_t code = c & (0x7F >> length);
  for (size_t k = 1; k < length; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
    code = (code << 6) | (byte(i + k) & 0x3F);
  }
  const uint32_t smallest[] = {0, 0, 0x80, 0x800, 0x10000};
  if (code < smallest[length] || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF) || code == 0xFFFE ||
      code == 0xFFFF)
    return 0;
  return length;
}

std::string escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size();) {
    const size_t length = xml_char_length(text, i);
    if (length == 0) {
      out += "\xEF\xBF\xBD";  // U+FFFD
      ++i;
      continue;
    }
    switch (text[i]) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out.append(text, i, length);
    }
    i += length;
  }
  return out;
}

// Attribute values: line breaks and tabs as character references, so that a parser keeps them.
std::string attribute(const std::string& text) {
  std::string out;
  for (const char c : escape(text)) {
    if (c == '\n') out += "&#10;";
    else if (c == '\r') out += "&#13;";
    else if (c == '\t') out += "&#9;";
    else out += c;
  }
  return out;
}

std::string seconds(double s) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3f", s);
  return buffer;
}

}  // namespace

std::string junit_xml(const JunitSuite& suite) {
  size_t failures = 0, errors = 0;
  double total = 0;
  for (const auto& c : suite.cases) {
    failures += c.failure.has_value();
    errors += c.error.has_value();
    total += c.seconds;
  }
  const std::string counts = " tests=\"" + std::to_string(suite.cases.size()) + "\" failures=\"" +
                             std::to_string(failures) + "\" errors=\"" + std::to_string(errors) + "\" time=\"" +
                             seconds(total) + "\"";
  std::string xml = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  xml += "<testsuites name=\"" + attribute(suite.name) + "\"" + counts + ">\n";
  xml += "  <testsuite name=\"" + attribute(suite.name) + "\"" + counts + " skipped=\"0\" timestamp=\"" +
         attribute(suite.timestamp) + "\">\n";
  xml += "    <properties>\n";
  for (const auto& [name, value] : suite.properties)
    xml += "      <property name=\"" + attribute(name) + "\" value=\"" + attribute(value) + "\"/>\n";
  xml += "    </properties>\n";
  for (const auto& c : suite.cases) {
    xml += "    <testcase classname=\"" + attribute(c.classname) + "\" name=\"" + attribute(c.name) + "\" time=\"" +
           seconds(c.seconds) + "\">\n";
    for (const auto& [tag, problem] : {std::pair{"failure", &c.failure}, std::pair{"error", &c.error}})
      if (*problem)
        xml += std::string("      <") + tag + " message=\"" + attribute((*problem)->message) + "\">" +
               escape((*problem)->details) + "</" + tag + ">\n";
    if (!c.output.empty()) xml += "      <system-out>" + escape(c.output) + "</system-out>\n";
    xml += "    </testcase>\n";
  }
  xml += "  </testsuite>\n</testsuites>\n";
  return xml;
}

}  // namespace vkray
