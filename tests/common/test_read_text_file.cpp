// read_text_file: whole files, the reasons it refuses one, and the size cap (also on a
// device without end).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "common/read_text_file.h"

using namespace treeanim;

namespace {

std::filesystem::path write_temp(const std::string& name, const std::string& content) {
  const auto path = std::filesystem::temp_directory_path() / (name + "-" + std::to_string(::getpid()));
  std::ofstream(path, std::ios::binary) << content;
  return path;
}

}  // namespace

TEST(ReadTextFile, ReadsTheWholeFileBinarySafe) {
  std::string content(200000, 'x');
  content[7] = '\0';
  content += "\rend\n";
  const auto path = write_temp("treeanim-read-whole", content);
  std::string text, reason;
  EXPECT_TRUE(read_text_file(path, text, reason));
  EXPECT_EQ(text, content.substr(0, 200000) + "\nend\n");  // the NUL kept; a lone CR ends a line
  std::filesystem::remove(path);
}

// A file saved on Windows: its byte-order mark goes and its CRLF line ends become LF, so a
// grammar's line ends where a Linux one does; a lone CR (an old Mac's line end) becomes LF too,
// so a scene's errors name the line an editor shows.
TEST(ReadTextFile, ReadsWindowsTextAsLinuxText) {
  const auto path = write_temp("treeanim-read-windows", "\xEF\xBB\xBF" "axiom: F\r\nF --> FF\r\n\r\na\rb\r");
  std::string text, reason;
  EXPECT_TRUE(read_text_file(path, text, reason));
  EXPECT_EQ(text, "axiom: F\nF --> FF\n\na\nb\n");  // a lone CR ends a line, as in old Mac text
  std::filesystem::remove(path);
}

TEST(ReadTextFile, NamesWhyAFileCannotBeRead) {
  std::string text, reason;
  EXPECT_FALSE(read_text_file("/nonexistent/dir/file.csv", text, reason));
  EXPECT_EQ(reason, "no such file");
  EXPECT_FALSE(read_text_file(std::filesystem::temp_directory_path(), text, reason));
  EXPECT_EQ(reason, "not a readable file");
}

TEST(ReadTextFile, RefusesAFileOverTheCap) {
  const auto path = write_temp("treeanim-read-cap", std::string(17, 'a'));
  std::string text = "stale", reason;
  EXPECT_FALSE(read_text_file(path, text, reason, 16));
  EXPECT_EQ(reason, "larger than 16 bytes");
  EXPECT_TRUE(text.empty());
  EXPECT_TRUE(read_text_file(path, text, reason, 17));
  EXPECT_EQ(text.size(), 17u);
  std::filesystem::remove(path);
}

TEST(ReadTextFile, StopsReadingADeviceWithoutEndAtTheCap) {
  if (!std::filesystem::exists("/dev/zero")) GTEST_SKIP() << "no /dev/zero";
  std::string text, reason;
  EXPECT_FALSE(read_text_file("/dev/zero", text, reason, std::uintmax_t(1) << 20));
  EXPECT_EQ(reason, "larger than 1 MiB");
  EXPECT_TRUE(text.empty());
}
