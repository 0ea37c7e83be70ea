// Escaping: text from a scene or the command line cannot change the structure of HTML,
// a gnuplot script or a CSV row.
#include "validate/io/escape.hpp"

#include <gtest/gtest.h>

namespace rdyn::validate {
namespace {

TEST(Escape, HtmlHasNoMarkupLeft) {
  const std::string hostile = "<script>alert('x')</script> & \"q\"";
  const std::string e = html_escape(hostile);
  EXPECT_EQ(e.find_first_of("<>\"'"), std::string::npos) << e;
  EXPECT_EQ(e, "&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt; &amp; &quot;q&quot;");
  EXPECT_EQ(html_escape("m1 [kg·m²]"), "m1 [kg·m²]");  // UTF-8 passes unchanged
}

TEST(Escape, GnuplotStringCannotBeLeft) {
  // In a single-quoted gnuplot string only '' stands for a quote; a line break would end the
  // command, so it becomes a space: `system` can never follow.
  EXPECT_EQ(gnuplot_quoted("knee"), "'knee'");
  EXPECT_EQ(gnuplot_quoted("a'; system 'touch PWNED"), "'a''; system ''touch PWNED'");
  EXPECT_EQ(gnuplot_quoted("a\nsystem 'x'"), "'a system ''x'''");
}

TEST(Escape, CsvFieldsFollowRfc4180) {
  EXPECT_EQ(csv_field("plain"), "plain");
  EXPECT_EQ(csv_field("a,b"), "\"a,b\"");
  EXPECT_EQ(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
  EXPECT_EQ(csv_field("two\nlines"), "\"two\nlines\"");
}

// RFC 4648 §10's test vectors, and bytes above 0x7f (an SVG's UTF-8 "°").
TEST(Escape, Base64IsRfc4648) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foob"), "Zm9vYg==");
  EXPECT_EQ(base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64("\xc2\xb0"), "wrA=");
}

}  // namespace
}  // namespace rdyn::validate
