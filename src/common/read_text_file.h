#pragma once
// Whole-file reads of the text inputs (scene, grammar, wind CSV), with one size cap.
#include <cstdint>
#include <filesystem>
#include <string>

namespace treeanim {

// 256 MiB: far above any scene, grammar or wind series (a key per millisecond for an hour is
// ~100 MB), far below what would exhaust memory.
constexpr std::uintmax_t kMaxTextFileBytes = std::uintmax_t(256) << 20;

// path => its whole content in `text`, true; or false with `reason` ("no such file", "not a
// readable file", "larger than 256 MiB"). Reads at most max_bytes + 1 bytes, so a device or
// pipe without end (/dev/zero) fails instead of filling memory; FIFOs and process
// substitution still work. Text saved on Windows or an old Mac reads as on Linux: a UTF-8
// byte-order mark at the start is dropped and each CRLF or lone CR line end becomes LF (lines
// are those an editor shows, and so are columns). A regular file read is noted as an input (common/input_files.h),
// unless it is one of a bake's own outputs read back (kOwnOutput: a forest's parts and pages),
// which the bake may write again.
enum class TextFileRole { kInput, kOwnOutput };
bool read_text_file(const std::filesystem::path& path, std::string& text, std::string& reason,
                    std::uintmax_t max_bytes = kMaxTextFileBytes, TextFileRole role = TextFileRole::kInput);

}  // namespace treeanim
