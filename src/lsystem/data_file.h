#pragma once
// Data files a cpfg grammar reads with fopen(name, "r") and fscan(file, "format", &x, ...)
// (CPFG manual 5.4): their text is read when the grammar is, and fscan converts numbers from it
// as C's fscanf does.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace treeanim {

// A file a grammar or view file names (fopen, surface:, curve:) => whether it stands beside it, a
// relative path without '..': a scene from elsewhere reads nothing outside its folders.
bool names_a_file_beside(const std::filesystem::path& name);

// One fopen of a grammar: the file's text and the global variable holding its read offset.
struct DataFile {
  std::string text;           // the whole file
  uint32_t offset_variable;   // variables index: bytes of text read so far
};

// One fscan of a grammar: its format and the global variables its values pass through.
struct ScanCall {
  std::string format;         // the format string, its escapes (\n, \t) undone
  uint32_t first_variable;    // variables index of the first of `values` in a row
  uint32_t values;            // conversions that assign (not %*f)
};

// format => "" when fscan can read it (whitespace, other characters matched as they are, %%,
// and the number conversions %f %e %g %d %i, with l or * before the letter), else what is
// wrong: every cpfg variable is a number.
std::string check_scan_format(std::string_view format);

// text from *offset, a checked format => the number of values converted into values[0, 1, ...]
// (each in turn), or -1 when the text ended before the first conversion (C's EOF); *offset
// moves past what was read.
int scan_values(std::string_view text, size_t* offset, std::string_view format, double* values);

}  // namespace treeanim
