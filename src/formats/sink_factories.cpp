// The sinks of the format table's rows (formats/sink_factories.h): a line per format.
#include "formats/sink_factories.h"

#include <algorithm>
#include <cmath>

#include "common/errors.h"
#include "common/message_text.h"
#include "formats/frame_sink.h"

namespace treeanim {

// Each format's sink, and the targets of one that writes more than its path, defined in its own
// file (src/formats/<format>_sink.cpp).
SinkFactory make_hdf5_sink, make_obj_sink, make_gltf_sink, make_glb_sink, make_pc2_sink, make_mdd_sink, make_vat_sink,
    make_skinned_glb_sink, make_usd_sink, make_skinned_usd_sink, make_html_sink;
SinkTargets obj_targets, gltf_targets, pc2_targets, mdd_targets, vat_targets, html_targets;
PlannedBytes html_output_bytes;

namespace {

// The targets of a format that writes one file, at its path (both forms of usd alike).
void file_at_path(const OutputOptions&, const std::filesystem::path& path, const FrameSelection&,
                  const TargetVisitor& visit) {
  visit(path, TargetKind::kFile);
}

// A usd output's writer: the points per frame, or with "skinned" the UsdSkel layer, a writer of
// its own as the skinned GLB is beside the GLB.
std::unique_ptr<FrameSink> make_usd_form_sink(const OutputOptions& options, const std::filesystem::path& path,
                                              const TreeModel& model, const BakeInfo& info) {
  return (options.skinned ? make_skinned_usd_sink : make_usd_sink)(options, path, model, info);
}

struct SinkRow {
  std::string_view format;
  SinkFactory* make;
  SinkTargets* targets;
  PlannedBytes* planned_bytes = nullptr;
};

const SinkRow kSinks[] = {
    {"hdf5", make_hdf5_sink, file_at_path},
    {"obj", make_obj_sink, obj_targets},
    {"gltf", make_gltf_sink, gltf_targets},
    {"glb", make_glb_sink, file_at_path},
    {"pc2", make_pc2_sink, pc2_targets},
    {"mdd", make_mdd_sink, mdd_targets},
    {"vat", make_vat_sink, vat_targets},
    {"skinned_glb", make_skinned_glb_sink, file_at_path},
    {"usd", make_usd_form_sink, file_at_path},
    {"html", make_html_sink, html_targets, html_output_bytes},
};

const SinkRow* find_sink(std::string_view format) {
  for (const SinkRow& row : kSinks)
    if (row.format == format) return &row;
  return nullptr;
}

}  // namespace

SinkFactory* find_sink_factory(std::string_view format) {
  const SinkRow* row = find_sink(format);
  return row ? row->make : nullptr;
}

SinkTargets* find_sink_targets(std::string_view format) {
  const SinkRow* row = find_sink(format);
  return row ? row->targets : nullptr;
}

PlannedBytes* find_planned_bytes(std::string_view format) {
  const SinkRow* row = find_sink(format);
  return row ? row->planned_bytes : nullptr;
}

void check_float32_key_times(const OutputOptions& options, const BakeInfo& info, const char* keys,
                             bool from_zero) {
  const FrameSelection selection{info.frame_start, info.frame_count, options.frame_step};
  if (from_zero && selection.start < 0)
    throw InputError(options.where() + ": " + keys + " start at time 0, and this bake's first frame is at " +
                     number_text(double(selection.start) / info.fps) + " s (time.start " +
                     std::to_string(selection.start) + "): bake from time.start 0 or later");
  const double last = double(selection.start + (selection.written() - 1) * selection.step);
  const double farthest = std::max(std::fabs(double(selection.start)), std::fabs(last)) / info.fps;  // s
  const double float_step = farthest > 0 ? std::ldexp(1.0, std::ilogb(farthest) - 23) : 0;  // float32's, there
  const double frame_step = double(selection.step) / info.fps;
  if (float_step <= frame_step / 2) return;
  throw InputError(options.where() + ": " + keys + " keep their times in float32, whose step at " +
                   number_text(farthest) + " s is " + number_text(float_step) + " s, more than half the " +
                   number_text(frame_step) + " s between written frames: raise frame_step, bake fewer frames (time.frames) or bake nearer time 0 "
                   "(time.start)");
}

}  // namespace treeanim
