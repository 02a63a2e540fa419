// fscan's conversions (CPFG manual 5.4), with the semantics of C's fscanf for numbers.
#include "lsystem/data_file.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <string>

namespace treeanim {

bool names_a_file_beside(const std::filesystem::path& name) {
  return !name.empty() && !name.is_absolute() &&
         std::none_of(name.begin(), name.end(), [](const std::filesystem::path& part) { return part == ".."; });
}

namespace {

bool is_space(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }

// The conversion letter after '%' at format[k] (past '*' and 'l'); *suppress set for '*'.
size_t conversion_letter(std::string_view format, size_t k, bool* suppress) {
  *suppress = k < format.size() && format[k] == '*';
  if (*suppress) ++k;
  while (k < format.size() && format[k] == 'l') ++k;
  return k;
}

bool is_number_conversion(char c) { return c == 'f' || c == 'e' || c == 'g' || c == 'd' || c == 'i'; }

}  // namespace

std::string check_scan_format(std::string_view format) {
  for (size_t k = 0; k < format.size(); ++k) {
    if (format[k] != '%') continue;
    if (k + 1 < format.size() && format[k + 1] == '%') {
      ++k;
      continue;
    }
    bool suppress = false;
    k = conversion_letter(format, k + 1, &suppress);
    if (k >= format.size()) return "the format ends inside a conversion";
    if (!is_number_conversion(format[k]))
      return std::string("'%") + format[k] + "' reads no number (fscan reads %f, %e, %g, %d or %i: every variable is a number)";
  }
  return "";
}

int scan_values(std::string_view text, size_t* offset, std::string_view format, double* values) {
  size_t at = *offset;
  int assigned = 0;
  bool converted = false;  // a conversion succeeded (C's EOF only before the first)
  const auto skip_spaces = [&] { while (at < text.size() && is_space(text[at])) ++at; };
  for (size_t k = 0; k < format.size(); ++k) {
    const char c = format[k];
    if (is_space(c)) {
      skip_spaces();
      continue;
    }
    if (c != '%' || (k + 1 < format.size() && format[k + 1] == '%')) {
      if (c == '%') ++k;
      if (at >= text.size() || text[at] != format[k]) break;
      ++at;
      continue;
    }
    bool suppress = false;
    k = conversion_letter(format, k + 1, &suppress);
    skip_spaces();
    if (at >= text.size()) {
      *offset = at;
      return converted ? assigned : -1;
    }
    const std::string rest(text.substr(at, 64));  // a number is never longer
    char* end = nullptr;
    // %d is decimal, %i takes C's prefixes (0x16 hexadecimal, 010 octal), as fscanf reads them.
    const double value = format[k] == 'd' || format[k] == 'i'
                             ? static_cast<double>(std::strtoll(rest.c_str(), &end, format[k] == 'i' ? 0 : 10))
                             : std::strtod(rest.c_str(), &end);
    if (end == rest.c_str()) break;
    at += static_cast<size_t>(end - rest.c_str());
    converted = true;
    if (!suppress) values[assigned++] = value;
  }
  *offset = at;
  return assigned;
}

}  // namespace treeanim
