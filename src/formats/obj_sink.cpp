// OBJ sequence: "<name>.%04d.obj" per written frame plus "<name>.rest.obj", all with the
// TreeModel's vertex order, the same "vt", "usemtl" and "f" lines, so a sequence loader
// (Houdini's $F4, Blender's Mesh Sequence Cache) sees one topology; "<name>.rest.mtl" holds the
// materials every file names.
#include "common/errors.h"
#include "files/staged_files.h"
#include "formats/frame_sink.h"
#include "formats/obj_format.h"
#include "formats/rest_positions_f32.h"
#include "formats/sequence_pattern.h"
#include "formats/sink_factories.h"
#include "formats/vertex_normals.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

const std::vector<float> kNoNormals;

// The materials file, beside the rest OBJ.
fs::path mtl_path(const SequencePattern& pattern) { return fs::path(pattern.rest()).replace_extension(".mtl"); }

class ObjSink final : public FrameSink {
 public:
  ObjSink(const OutputOptions& options, const fs::path& path, const TreeModel& model, const BakeInfo& info)
      : pattern_(sequence_pattern(path, ".obj", options.where())), model_(model), info_(info),
        selection_{info.frame_start, info.frame_count, options.frame_step}, normals_(options.normals),
        mtl_(mtl_path(pattern_)) {}

  std::vector<SummaryFile> summary_paths() const override {
    if (selection_.written() == 0) return {{pattern_.rest()}};
    return {{pattern_.rest()}, sequence_summary(pattern_, selection_)};
  }

  void begin() override {
    shared_ = obj_shared_lines(model_, mtl_.filename().string(), normals_);
    write_mtl_file(staged_.stage(mtl_), mtl_, info_.generator + ", materials", info_.materials);
    const fs::path rest = pattern_.rest();
    write_obj_file(staged_.stage(rest), rest, info_.generator + ", rest pose, metres, Y up",
                   rest_positions_f32(model_), shared_, normals_ ? rest_normals(model_) : kNoNormals);
  }

  void write(const FrameData& frame) override {
    const fs::path target = pattern_.frame(frame.frame);
    write_obj_file(staged_.stage(target), target,
                   info_.generator + ", frame " + std::to_string(frame.frame) + ", metres, Y up",
                   frame.positions, shared_, normals_ ? frame.normals : kNoNormals);
  }


 private:
  SequencePattern pattern_;
  const TreeModel& model_;
  BakeInfo info_;
  FrameSelection selection_;
  bool normals_;        // "vn" lines in every file
  fs::path mtl_;        // the materials file beside the rest OBJ
  std::string shared_;  // "mtllib", "vt", "usemtl" and "f" lines, identical in every file
};

}  // namespace

void obj_targets(const OutputOptions& options, const fs::path& path, const FrameSelection& selection,
                 const TargetVisitor& visit) {
  const SequencePattern pattern = sequence_pattern(path, ".obj", options.where());
  visit(pattern.rest(), TargetKind::kFile);
  visit(mtl_path(pattern), TargetKind::kFile);
  for (long long k = 0; k < selection.written(); ++k)
    visit(pattern.frame(selection.start + k * selection.step), TargetKind::kFrame);
}

std::unique_ptr<FrameSink> make_obj_sink(const OutputOptions& options, const fs::path& path,
                                         const TreeModel& model, const BakeInfo& info) {
  return std::make_unique<ObjSink>(options, path, model, info);
}

}  // namespace treeanim
