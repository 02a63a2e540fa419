#include "common/message_text.h"

#include <charconv>
#include <cstdio>
#include <sstream>

namespace treeanim {

namespace {

// The length of the well-formed UTF-8 character at text[i] (RFC 3629: no overlong form, no
// surrogate, nothing past U+10FFFF), 0 when the bytes there are not one.
size_t utf8_length(std::string_view text, size_t i) {
  const auto byte = [&](size_t k) { return k < text.size() ? static_cast<unsigned char>(text[k]) : 0u; };
  const unsigned lead = byte(i);
  size_t n = 0;
  unsigned low = 0x80, high = 0xBF;  // the range of the second byte
  if (lead >= 0xC2 && lead <= 0xDF) n = 2;
  else if (lead >= 0xE0 && lead <= 0xEF) n = 3, low = lead == 0xE0 ? 0xA0 : 0x80, high = lead == 0xED ? 0x9F : 0xBF;
  else if (lead >= 0xF0 && lead <= 0xF4) n = 4, low = lead == 0xF0 ? 0x90 : 0x80, high = lead == 0xF4 ? 0x8F : 0xBF;
  else return 0;
  if (byte(i + 1) < low || byte(i + 1) > high) return 0;
  for (size_t k = 2; k < n; ++k)
    if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
  return n;
}

// Code point of the well-formed UTF-8 character of n bytes at text[i].
char32_t code_point(std::string_view text, size_t i, size_t n) {
  char32_t c = static_cast<unsigned char>(text[i]) & (0xFFu >> (n + 1));
  for (size_t k = 1; k < n; ++k) c = (c << 6) | (static_cast<unsigned char>(text[i + k]) & 0x3Fu);
  return c;
}

// A character a terminal acts on rather than shows: the C1 controls (U+0080-U+009F: CSI is
// U+009B), and the marks and overrides that reorder text (bidirectional controls).
bool acts(char32_t c) {
  return (c >= 0x80 && c <= 0x9F) || c == 0x200E || c == 0x200F || (c >= 0x202A && c <= 0x202E) ||
         (c >= 0x2066 && c <= 0x2069);
}

}  // namespace

std::string printable_text(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    if ((c >= 0x20 && c < 0x7F) || c == '\t' || c == '\n') {
      out += char(c);
      ++i;
    } else if (const size_t n = c >= 0x80 ? utf8_length(text, i) : 0; n && !acts(code_point(text, i, n))) {
      out.append(text.substr(i, n));
      i += n;
    } else {
      for (size_t k = 0; k < std::max<size_t>(n, 1); ++k) {  // each byte of a character that acts
        char escaped[5];
        std::snprintf(escaped, sizeof escaped, "\\x%02x", static_cast<unsigned char>(text[i + k]));
        out += escaped;
      }
      i += std::max<size_t>(n, 1);
    }
  }
  return out;
}

std::string shown_message(std::string_view text, size_t most) {
  if (text.size() <= most) return printable_text(text);
  size_t head = most * 3 / 4, tail = text.size() - most / 4;
  while (head > 0 && continues_character(text[head])) --head;
  while (tail < text.size() && continues_character(text[tail])) ++tail;
  return printable_text(text.substr(0, head)) + " [... " + std::to_string(tail - head) + " bytes left out ...] " +
         printable_text(text.substr(tail));
}

std::string excerpt(std::string_view text, size_t most) {
  if (text.size() <= most) return printable_text(text);
  size_t cut = most >= 3 ? most - 3 : 0;
  while (cut > 0 && continues_character(text[cut])) --cut;
  return printable_text(text.substr(0, cut)) + "...";
}

std::string number_text(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

std::string exact_number_text(double value) {
  char text[32];
  const std::to_chars_result end = std::to_chars(text, text + sizeof text, value);
  return std::string(text, end.ptr);
}

}  // namespace treeanim
