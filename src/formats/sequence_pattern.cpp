#include "formats/sequence_pattern.h"

#include <cstdio>

#include "common/errors.h"
#include "common/message_text.h"

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
  // Exactly one integer field, "%d" or "%0Nd", and no other '%' in the file name (a plain scan:
  // std::regex matches by recursion, and a path is user input of any length).
  const size_t percent = name.find('%');
  const bool padded = name.size() > percent + 3 && name[percent + 1] == '0' && name[percent + 2] >= '1' &&
                      name[percent + 2] <= '9' && name[percent + 3] == 'd';
  const size_t field_length = padded ? 4 : 2;
  const bool one_field = (padded || (name.size() > percent + 1 && name[percent + 1] == 'd')) &&
                         name.find('%', percent + 1) == std::string::npos;
  if (!one_field)
    throw InputError(pointer + "/path: expected at most one frame-number field \"%d\" or \"%0Nd\" (N 1-9) in "
                     "the file name, got \"" + excerpt(text) + "\"");
  const size_t field_start = text.size() - name.size() + percent;
  SequencePattern pattern{text.substr(0, field_start), text.substr(field_start + field_length),
                          padded ? name[percent + 2] - '0' : 1};
  // The files hold what the extension says: a glTF sequence named "f%d.obj" would write GLBs as .obj.
  if (!pattern.suffix.ends_with(extension))
    throw InputError(pointer + "/path: expected a file name that ends in " + extension + " after its frame field (e.g. \"" +
                     excerpt(name.substr(0, percent + field_length)) + extension + "\"), got \"" + excerpt(text) + "\"");
  return pattern;
}

}  // namespace treeanim
