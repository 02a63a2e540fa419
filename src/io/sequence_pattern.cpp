#include <cstdio>
#include <regex>

#include "common/errors.h"
#include "io/frame_sink.h"

namespace treeanim {

namespace fs = std::filesystem;

fs::path SequencePattern::frame(long long index) const {
  char number[32];
  std::snprintf(number, sizeof number, "%0*lld", width, index);
  return fs::path(prefix + number + suffix);
}

fs::path SequencePattern::rest() const { return fs::path(prefix + "rest" + suffix); }

SequencePattern sequence_pattern(const fs::path& path, const std::string& extension, const std::string& pointer) {
  const std::string text = path.string();
  const std::string name = path.filename().string();
  if (name.find('%') == std::string::npos) {
    const bool has_extension = name.size() > extension.size() && name.ends_with(extension);
    return {has_extension ? text.substr(0, text.size() - extension.size()) + "." : text + ".", extension, 4};
  }
  // Exactly one integer field, "%d" or "%0Nd", and no other '%' in the file name.
  static const std::regex field("%(0([1-9]))?d");
  std::smatch match;
  const bool one_field = std::regex_search(name, match, field) &&
                         name.find('%', size_t(match.position(0)) + 1) == std::string::npos &&
                         name.find('%') == size_t(match.position(0));
  if (!one_field)
    throw InputError(pointer + "/path: expected at most one frame-number field \"%d\" or \"%0Nd\" (N 1-9) in "
                     "the file name, got \"" + text + "\"");
  const size_t field_start = text.size() - name.size() + size_t(match.position(0));
  return {text.substr(0, field_start), text.substr(field_start + size_t(match.length(0))),
          match[2].matched ? std::stoi(match[2].str()) : 1};
}

}  // namespace treeanim
