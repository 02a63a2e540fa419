// parse_json_text: nesting refused at the limit with line and column, without recursion at any
// depth; repeated keys refused with their pointer and both lines.
#include <gtest/gtest.h>

#include "common/json_text.h"

namespace treeanim {
namespace {

std::string error_of(const std::string& text, const std::string& at = "") {
  try {
    parse_json_text(text, "s.json", at);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string nested(size_t depth, const std::string& inner = "") {
  return std::string(depth, '[') + inner + std::string(depth, ']');
}

TEST(JsonText, NestingUpToTheLimitIsRead) {
  const Json document = parse_json_text(nested(kMaxJsonDepth, "7"), "s.json");
  const Json* node = &document;
  for (int i = 0; i < kMaxJsonDepth; ++i) node = &(*node)[0];
  EXPECT_EQ(*node, 7);
}

TEST(JsonText, NestingPastTheLimitIsRefusedWhereItStarts) {
  const std::string message =
      "JSON nested deeper than 256 levels of arrays and objects; no scene needs more";
  EXPECT_EQ(error_of(nested(kMaxJsonDepth + 1)), "s.json:1:257: " + message);
  EXPECT_EQ(error_of("{\n  \"tree\": {\"a\": " + nested(300) + "}\n}"), "s.json:2:271: " + message);
  // Far past any stack: a scan with its own stack, and nothing parses it.
  EXPECT_EQ(error_of("{\"tree\": " + nested(1'000'000) + "}"), "s.json:1:265: " + message);
  EXPECT_EQ(error_of(std::string(1'000'000, '{')), "s.json:1:257: " + message);
}

TEST(JsonText, AValueBelowAPointerHasLessRoom) {
  EXPECT_EQ(error_of(nested(kMaxJsonDepth - 1), "/a/b"),
            "s.json:1:255: JSON nested deeper than 256 levels of arrays and objects (counted from the scene's "
            "root; /a/b takes 2 of them); no scene needs more");
  EXPECT_EQ(error_of(nested(kMaxJsonDepth - 2), "/a/b"), "");
}

TEST(JsonText, BracketsInStringsDoNotNest) {
  EXPECT_EQ(error_of("{\"a\": \"" + std::string(1000, '[') + "\\\"{\"}"), "");
}

// The parser would end the text at a NUL byte and take the scene before it, garbage after.
TEST(JsonText, ANulByteIsRefusedWhereItStands) {
  EXPECT_EQ(error_of(std::string("{\"seed\": 3}\n\0garbage{{", 22)),
            "s.json:2:1: JSON syntax error: a NUL byte, which JSON text cannot hold");
  EXPECT_EQ(error_of(std::string("{\"seed\": \0 3}", 14)),
            "s.json:1:10: JSON syntax error: a NUL byte, which JSON text cannot hold");
}

TEST(JsonText, RepeatedKeysAreRefusedWithTheirPointerAndLines) {
  EXPECT_EQ(error_of("{\"seed\": 3,\n \"time\": {},\n \"seed\": 7}"),
            "s.json:3:2: /seed: duplicate key (first at line 1, again at line 3); keep one of them");
  EXPECT_EQ(error_of("{\"outputs\": [{}, {\"path\": \"a\",\n\"path\": \"b\"}]}"),
            "s.json:2:1: /outputs/1/path: duplicate key (first at line 1, again at line 2); keep one of them");
  // One key however it is spelled; pointer tokens escaped.
  EXPECT_EQ(error_of("{\"a/b\": 1, \"a\\u002fb\": 2}"),
            "s.json:1:12: /a~1b: duplicate key (first at line 1, again at line 1); keep one of them");
  // The same key in sibling objects, or as a string value, is no repeat.
  EXPECT_EQ(error_of("{\"a\": {\"k\": 1}, \"b\": {\"k\": \"a\"}, \"c\": [\"a\", \"a\"]}"), "");
  EXPECT_EQ(error_of("{\"x\": 1, \"y\": 2}", "/wind"), "");
  EXPECT_EQ(error_of("{\"x\": 1, \"x\": 2}", "/wind"),
            "s.json:1:10: /wind/x: duplicate key (first at line 1, again at line 1); keep one of them");
}

TEST(JsonText, SyntaxErrorsComeFirstAndHaveTheirOwnType) {
  EXPECT_THROW(parse_json_text("{\"a\": 1,}", "s.json"), JsonSyntaxError);
  EXPECT_EQ(error_of("{\"a\": 1, \"a\": }"), "s.json:1:15: JSON syntax error: syntax error while parsing value - "
                                              "unexpected '}'; expected '[', '{', or a literal");
  EXPECT_EQ(error_of("[1e400]"), "s.json:1:2: JSON number out of range: 1e400 (expected a finite double)");
}

TEST(JsonText, LineColumnCountsFromOne) {
  EXPECT_EQ(line_column("ab\ncd", 0), "1:1");
  EXPECT_EQ(line_column("ab\ncd", 2), "1:3");
  EXPECT_EQ(line_column("ab\ncd", 3), "2:1");
  EXPECT_EQ(line_column("ab\ncd", 4), "2:2");
}

// Columns count characters, as an editor shows them, not the bytes of their UTF-8.
TEST(JsonText, LineColumnCountsCharacters) {
  EXPECT_EQ(line_column("\"\xC3\xA9t\xC3\xA9\" x", 8), "1:7");
  EXPECT_EQ(line_column("a\n\xE2\x86\x92\xF0\x9F\x8C\xB3 x", 10), "2:4");
  EXPECT_EQ(error_of("{\"name\": \"\xC3\xA9t\xC3\xA9\", }"), "s.json:1:17: JSON syntax error: syntax error while parsing "
            "object key - unexpected '}'; expected string literal");
}

}  // namespace
}  // namespace treeanim
