// The JUnit report `vkray check` writes: well-formed whatever its messages hold. (installed_check.sh
// reads a whole report back with Python's XML parser.)
#include <string>

#include <gtest/gtest.h>

#include "compare/junit.h"

namespace vkray::cli {
namespace {

TEST(JunitTest, CountsCasesAndKeepsTheSuitesProperties) {
  JunitSuite suite{"vkray check", "2026-11-23T12:00:00", {{"device", "llvmpipe"}}, {}};
  suite.cases.push_back({"vkray.check.cornell", "bvh_1spp", 0.25, std::nullopt, std::nullopt, "ok"});
  suite.cases.push_back({"vkray.check.cornell", "bvh_16spp", 0.5, JunitCase::Problem{"differs", "heatmap"}, std::nullopt, ""});
  suite.cases.push_back({"vkray.check.teapot", "run", 0, std::nullopt, JunitCase::Problem{"device lost", "device lost"}, ""});
  const std::string xml = junit_xml(suite);
  EXPECT_EQ(xml.rfind("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n", 0), 0u);
  EXPECT_NE(xml.find("<testsuite name=\"vkray check\" tests=\"3\" failures=\"1\" errors=\"1\" time=\"0.750\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("<property name=\"device\" value=\"llvmpipe\"/>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<failure message=\"differs\">heatmap</failure>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<error message=\"device lost\">device lost</error>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<system-out>ok</system-out>"), std::string::npos) << xml;
}

TEST(JunitTest, EscapesMarkupAndReplacesWhatXmlCannotHold) {
  JunitSuite suite{"s", "t", {{"driver", "a \"b\" <c> & d\ne"}}, {}};
  // Control characters, a lone continuation byte, a truncated sequence, an encoded surrogate, and
  // valid UTF-8 (é, 𝄞) that must pass unchanged.
  const std::string message = std::string("x\x01y\x1b[31m\x80z\xC3") + "\xED\xA0\x80" + " \xC3\xA9 \xF0\x9D\x84\x9E";
  suite.cases.push_back({"c", "n", 0, JunitCase::Problem{message, "1 < 2 && 3 > 2"}, std::nullopt, ""});
  const std::string xml = junit_xml(suite);
  EXPECT_NE(xml.find("value=\"a &quot;b&quot; &lt;c&gt; &amp; d&#10;e\""), std::string::npos) << xml;
  const std::string fffd = "\xEF\xBF\xBD";
  EXPECT_NE(xml.find("message=\"x" + fffd + "y" + fffd + "[31m" + fffd + "z" + fffd + fffd + fffd + fffd +
                     " \xC3\xA9 \xF0\x9D\x84\x9E\""),
            std::string::npos)
      << xml;
  EXPECT_NE(xml.find(">1 &lt; 2 &amp;&amp; 3 &gt; 2</failure>"), std::string::npos) << xml;
  for (const char c : xml) EXPECT_FALSE(static_cast<unsigned char>(c) < 0x20 && c != '\n') << int(c);
}

}  // namespace
}  // namespace vkray::cli
