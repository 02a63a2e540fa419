#pragma once
// The writers' half of the format table: each format's sink (formats/<format>_sink.cpp), by the
// format's name. The other half, the scene keys and size estimates (output/output_formats.h), has
// no dependencies, so that scene/ reads it without linking a writer.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string_view>

#include "formats/outputs.h"
#include "output/output_options.h"
#include "tree/tree_model.h"

namespace treeanim {

class FrameSink;
struct FrameSelection;

// What a file an output writes is to the bake's locks (files/output_lock.h): a file of its own,
// locked, or one of a sequence's per-frame files, which the lock beside the sequence's first
// frame covers (a lock a frame would be a million lock files).
enum class TargetKind : uint8_t { kFile, kFrame };
// Called with each file an output writes, one at a time: a long sequence needs no list of its
// names.
using TargetVisitor = std::function<void(const std::filesystem::path&, TargetKind)>;

// options, path resolved against the out folder, model, bake => a format's sink
using SinkFactory = std::unique_ptr<FrameSink>(const OutputOptions& options, const std::filesystem::path& path,
                                               const TreeModel& model, const BakeInfo& info);

// options, path resolved against the out folder, the frames it writes, visit => every file its
// sink will create, final names (checked and de-duplicated before simulating). No model: a forest
// checks every tree's targets before it grows the first.
using SinkTargets = void(const OutputOptions& options, const std::filesystem::path& path,
                         const FrameSelection& selection, const TargetVisitor& visit);

// options, mesh size (vertices, triangles, clusters), frames of the bake => an upper bound of all
// the output writes, for a format that plans its size before simulating (a page that reduces its
// frames to fit its limit)
using PlannedBytes = double(const OutputOptions& options, size_t vertices, size_t triangles, size_t clusters,
                            long long frames);

// A format's name => its sink's factory; nullptr when no sink writes that format (a test checks
// that every row of output_formats() has one).
SinkFactory* find_sink_factory(std::string_view format);
// A format's name => its sink's targets; nullptr when no sink writes that format.
SinkTargets* find_sink_targets(std::string_view format);
// A format's name => its sink's size plan; nullptr for a format whose size is its frames' bytes.
PlannedBytes* find_planned_bytes(std::string_view format);

// A format whose frames' times are float32 keys (glTF animations, MDD): InputError naming the
// output unless every written frame's key keeps its place within a quarter of the step between
// written frames (a start of 999999999 at 24 fps made every key 41666668 s), and, where the
// format's times start at 0 (glTF's), none is negative.
void check_float32_key_times(const OutputOptions& options, const BakeInfo& info, const char* keys,
                             bool from_zero);

}  // namespace treeanim
