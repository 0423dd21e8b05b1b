// JUnit XML, the test report CI systems read (Jenkins, GitLab, Mesa's CI): one suite of cases with
// the suite's properties, each case passed, failed or in error.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace vkray {

struct JunitCase {
  std::string classname, name;
  double seconds = 0;
  struct Problem {
    std::string message;  // one line
    std::string details;  // any text
  };
  std::optional<Problem> failure;  // the check ran and found a difference
  std::optional<Problem> error;    // the check could not run
  std::string output;              // <system-out>
};

struct JunitSuite {
  std::string name;
  std::string timestamp;  // ISO 8601
  std::vector<std::pair<std::string, std::string>> properties;
  std::vector<JunitCase> cases;
};

// The suite as an XML document. Text is escaped, and characters XML 1.0 cannot carry (control
// characters, invalid UTF-8) become U+FFFD, so that any message makes a well-formed file.
std::string junit_xml(const JunitSuite& suite);

}  // namespace vkray
