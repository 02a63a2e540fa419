#pragma once
// Input quoted in a message, shown as text: a binary file named in an error can neither drive
// the terminal (escape sequences, a bell), cut the message at a NUL, nor fill the screen.
#include <cstddef>
#include <string>
#include <string_view>

namespace treeanim {

// `text` with every byte that is neither printable ASCII, a tab, a line break nor part of
// well-formed UTF-8, and each byte of a character a terminal acts on (a C1 control, a
// bidirectional override), written as \xNN.
std::string printable_text(std::string_view text);

// A message as the command line prints it: printable_text, and past `most` bytes its middle
// left out (the start names the place and the problem, the end what was expected), so that
// input quoted whole (a megabyte key) cannot flood the terminal.
std::string shown_message(std::string_view text, size_t most = 2000);

// `text` when it has at most `most` bytes, else its first most - 3 (never cutting a UTF-8
// character) and "...", as printable_text: a quote of input in a message (a message is cut at
// its first NUL).
std::string excerpt(std::string_view text, size_t most = 60);

// A byte that continues a UTF-8 character (10xxxxxx): messages count a line's columns in
// characters, as an editor shows them, so such a byte takes its character's column.
inline bool continues_character(char c) { return (static_cast<unsigned char>(c) & 0xC0) == 0x80; }

// A number in a message, as a stream writes it: six significant digits ("0.02", "1e-09", "inf").
std::string number_text(double value);

// A number in a message that must tell it from a near one (the two ends of a loop's wind): the
// shortest text that reads back as the same double ("5", "5.0000001", "0.1").
std::string exact_number_text(double value);

}  // namespace treeanim
