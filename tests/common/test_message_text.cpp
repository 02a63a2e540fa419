// printable_text and excerpt: input quoted in a message shows every byte, moves no cursor.
#include <gtest/gtest.h>

#include <string>

#include "common/message_text.h"

using namespace treeanim;

TEST(MessageText, KeepsTextAndWellFormedUtf8) {
  EXPECT_EQ(printable_text("wind.csv:2: got 'fast'\tand\nmore"), "wind.csv:2: got 'fast'\tand\nmore");
  EXPECT_EQ(printable_text("Kiefer \xc3\xa4 \xe2\x82\xac \xf0\x9f\x8c\xb3"), "Kiefer \xc3\xa4 \xe2\x82\xac \xf0\x9f\x8c\xb3");
}

TEST(MessageText, EscapesControlBytesAndBrokenUtf8) {
  EXPECT_EQ(printable_text(std::string("\x7f" "ELF\x00\x1b[2J\r\a", 11)), "\\x7fELF\\x00\\x1b[2J\\x0d\\x07");
  // A lone continuation byte, a lead without its continuation, an overlong form, a surrogate,
  // a character past U+10FFFF, and a truncated sequence at the end.
  EXPECT_EQ(printable_text("\x80 \xc3x \xc0\xaf \xed\xa0\x80 \xf4\x90\x80\x80 \xe2\x82"),
            "\\x80 \\xc3x \\xc0\\xaf \\xed\\xa0\\x80 \\xf4\\x90\\x80\\x80 \\xe2\\x82");
}

TEST(MessageText, EscapesWhatATerminalActsOn) {
  // CSI as a C1 control (U+009B) and a right-to-left override (U+202E): well-formed, yet acted on.
  EXPECT_EQ(printable_text("a\xc2\x9b" "31m b\xe2\x80\xae" "c \xc2\xa0"), "a\\xc2\\x9b31m b\\xe2\\x80\\xaec \xc2\xa0");
}

TEST(MessageText, AShownMessageKeepsItsStartAndEnd) {
  const std::string key(1000000, 'k');
  const std::string shown = shown_message("scene.json: /" + key + ": unknown key (did you mean /time?)");
  EXPECT_LT(shown.size(), 2100u);
  EXPECT_EQ(shown.rfind("scene.json: /kkk", 0), 0u);
  EXPECT_NE(shown.find(" bytes left out ...] "), std::string::npos);
  EXPECT_EQ(shown.substr(shown.size() - 35), ": unknown key (did you mean /time?)");
  EXPECT_EQ(shown_message("short\x1b"), "short\\x1b");
}

TEST(MessageText, ExcerptCutsLongQuotesBetweenCharacters) {
  EXPECT_EQ(excerpt("short"), "short");
  EXPECT_EQ(excerpt(std::string(60, 'a')), std::string(60, 'a'));
  EXPECT_EQ(excerpt(std::string(61, 'a')), std::string(57, 'a') + "...");
  // The cut falls inside a two-byte character: the character goes with the rest.
  EXPECT_EQ(excerpt(std::string(56, 'a') + "\xc3\xa4" + std::string(10, 'b')), std::string(56, 'a') + "...");
  EXPECT_EQ(excerpt(std::string("\x00\x01", 2)), "\\x00\\x01");
}
