#include "common/read_text_file.h"

#include <fstream>
#include <utility>

#include "common/input_files.h"

namespace treeanim {

bool read_text_file(const std::filesystem::path& path, std::string& text, std::string& reason,
                    std::uintmax_t max_bytes, TextFileRole role) {
  text.clear();
  auto fail = [&](std::string why) {
    text.clear();
    reason = std::move(why);
    return false;
  };
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (!std::filesystem::exists(status)) return fail(why_no_file(status, error));
  std::ifstream in(path, std::ios::binary);
  if (!in || std::filesystem::is_directory(status)) return fail("not a readable file");
  const std::string too_large =
      "larger than " + (max_bytes % (1 << 20) == 0 ? std::to_string(max_bytes >> 20) + " MiB"
                                                   : std::to_string(max_bytes) + " bytes");
  if (std::filesystem::is_regular_file(status) && std::filesystem::file_size(path, error) > max_bytes && !error)
    return fail(too_large);
  // Chunks up to the cap: the size of a device or pipe is not known in advance.
  char chunk[1 << 16];
  while (in.read(chunk, sizeof chunk) || in.gcount() > 0) {
    text.append(chunk, static_cast<size_t>(in.gcount()));
    if (text.size() > max_bytes) return fail(too_large);
  }
  if (in.bad()) return fail("not a readable file");
  if (text.starts_with("\xEF\xBB\xBF")) text.erase(0, 3);
  if (text.find('\r') != std::string::npos) {  // "\r\n" and a "\r" alone (old Mac text) end a line as "\n"
    size_t kept = 0;
    for (size_t i = 0; i < text.size(); ++i)
      if (text[i] != '\r') text[kept++] = text[i];
      else if (i + 1 == text.size() || text[i + 1] != '\n') text[kept++] = '\n';
    text.resize(kept);
  }
  if (role == TextFileRole::kInput) note_input_file(path);
  return true;
}

}  // namespace treeanim
