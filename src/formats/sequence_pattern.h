#pragma once
// The file names of a sequence output (obj, gltf): one file per written frame and one for the rest pose.
#include <filesystem>
#include <string>

namespace treeanim {

// A frame-numbered file name: "<prefix><frame, zero-padded to width><suffix>".
struct SequencePattern {
  std::string prefix;  // folder and name up to the frame number
  std::string suffix;  // after the frame number, e.g. ".obj"
  int width = 4;       // zero padding of the frame number
  std::filesystem::path frame(long long index) const;
  std::filesystem::path rest() const;  // the number replaced by "rest"
};

// An output path => its sequence pattern. A file name with a frame field (common/frame_field.h:
// ####, "%d" or "%0Nd") keeps it; any other path gets ".%04d<extension>" appended (after
// dropping a trailing `extension`). Throws InputError "<pointer>/path: ..." for a name no field
// can be read from, and for a field not followed by a name that ends in `extension`.
SequencePattern sequence_pattern(const std::filesystem::path& path, const std::string& extension,
                                 const std::string& pointer);

struct FrameSelection;
struct SummaryFile;
// The frames' files of `selection` by this pattern, as the run's summary names them.
SummaryFile sequence_summary(const SequencePattern& pattern, const FrameSelection& selection);

}  // namespace treeanim
