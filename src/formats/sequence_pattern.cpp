#include "formats/sequence_pattern.h"

#include <cstdio>

#include "common/errors.h"
#include "common/frame_field.h"
#include "common/message_text.h"
#include "formats/frame_sink.h"

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
  FrameField field;
  if (!read_frame_field(name, field))
    throw InputError(pointer + "/path: expected at most one frame-number field, #### or \"%d\" / \"%0Nd\" (at most " +
                     std::to_string(kMostFrameDigits) + " digits), in the file name, got \"" + excerpt(text) + "\"");
  if (field.begin == std::string::npos) {
    const bool has_extension = name.size() > extension.size() && name.ends_with(extension);
    return {has_extension ? text.substr(0, text.size() - extension.size()) + "." : text + ".", extension, 4};
  }
  const size_t field_start = text.size() - name.size() + field.begin;
  SequencePattern pattern{text.substr(0, field_start), text.substr(field_start + field.length), field.width};
  // The files hold what the extension says: a glTF sequence named "f%d.obj" would write GLBs as .obj.
  if (!pattern.suffix.ends_with(extension))
    throw InputError(pointer + "/path: expected a file name that ends in " + extension + " after its frame field (e.g. \"" +
                     excerpt(name.substr(0, field.begin + field.length)) + extension + "\"), got \"" + excerpt(text) + "\"");
  return pattern;
}

SummaryFile sequence_summary(const SequencePattern& pattern, const FrameSelection& selection) {
  const long long files = selection.written();
  return {pattern.frame(selection.start), files, pattern.frame(selection.start + (files - 1) * selection.step)};
}

}  // namespace treeanim
