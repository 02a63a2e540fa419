#pragma once
// The frame number's place in a file name, one rule for what the program reads (a volume's
// frames) and what it writes (OBJ and glTF sequences): "####" (as many digits as '#', Houdini's
// $F4) or printf's "%d" / "%0Nd".
#include <cstddef>
#include <string>

namespace treeanim {

struct FrameField {
  size_t begin = std::string::npos;  // npos: the name holds no field
  size_t length = 0;                 // bytes the field takes in the name
  int width = 1;                     // the number zero-padded to this many digits (a sign counts)
};

inline constexpr int kMostFrameDigits = 18;  // a long long's

// A file name => its one frame field, or no field (begin npos). Returns false for a name that a
// frame field cannot be read from: two fields, '#' and '%' mixed, a '%' other than "%d" or
// "%0Nd" (N 1 … kMostFrameDigits), or more '#' than kMostFrameDigits.
bool read_frame_field(const std::string& name, FrameField& field);

// `name` with its field replaced by `number`, zero-padded (a negative frame -001, as $F4 writes it).
std::string with_frame_number(const std::string& name, const FrameField& field, long long number);

}  // namespace treeanim
