#pragma once
// Input quoted in a message, shown as text: a binary file named in an error can neither drive
// the terminal (escape sequences, a bell), cut the message at a NUL, nor fill the screen.
#include <cstddef>
#include <string>
#include <string_view>

namespace treeanim {

// `text` with every byte that is neither printable ASCII, a tab, a line break nor part of
// well-formed UTF-8 written as \xNN.
std::string printable_text(std::string_view text);

// `text` when it has at most `most` bytes, else its first most - 3 (never cutting a UTF-8
// character) and "...", as printable_text: a quote of input in a message (a message is cut at
// its first NUL).
std::string excerpt(std::string_view text, size_t most = 60);

}  // namespace treeanim
