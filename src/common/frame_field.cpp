#include "common/frame_field.h"

#include <algorithm>
#include <cstdio>

namespace treeanim {

bool read_frame_field(const std::string& name, FrameField& field) {
  field = {};
  const size_t hash = name.find('#'), percent = name.find('%');
  if (hash != std::string::npos && percent != std::string::npos) return false;
  if (hash != std::string::npos) {
    const size_t end = std::min(name.find_first_not_of('#', hash), name.size());
    field = {hash, end - hash, int(end - hash)};
    return field.width <= kMostFrameDigits && name.find('#', end) == std::string::npos;
  }
  if (percent == std::string::npos) return true;
  // A plain scan, not std::regex (it matches by recursion, and a path is user input of any length).
  size_t i = percent + 1;
  int width = 1;
  if (i + 1 < name.size() && name[i] == '0' && name[i + 1] >= '1' && name[i + 1] <= '9') {
    width = 0;
    for (++i; i < name.size() && name[i] >= '0' && name[i] <= '9' && width <= kMostFrameDigits; ++i)
      width = 10 * width + (name[i] - '0');
  }
  if (i >= name.size() || name[i] != 'd' || width > kMostFrameDigits) return false;
  field = {percent, i + 1 - percent, width};
  return name.find('%', i) == std::string::npos;
}

std::string with_frame_number(const std::string& name, const FrameField& field, long long number) {
  if (field.begin == std::string::npos) return name;
  char digits[32];
  std::snprintf(digits, sizeof digits, "%0*lld", field.width, number);
  return name.substr(0, field.begin) + digits + name.substr(field.begin + field.length);
}

}  // namespace treeanim
