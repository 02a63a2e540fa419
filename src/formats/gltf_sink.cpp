// glTF sequence: one self-contained .glb per written frame ("<name>.%04d.glb"), the tree's mesh
// (formats/gltf_mesh.h: positions, UVs, normals unless turned off, materials) at that frame.
#include <cstring>

#include "common/errors.h"
#include "formats/frame_sink.h"
#include "formats/gltf_mesh.h"
#include "formats/rest_positions_f32.h"
#include "formats/sequence_pattern.h"
#include "formats/sink_factories.h"
#include "formats/vertex_normals.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

class GltfSink final : public FrameSink {
 public:
  GltfSink(const OutputOptions& options, const fs::path& path, const TreeModel& model, const BakeInfo& info)
      : pattern_(sequence_pattern(path, ".glb", options.where())), model_(model), info_(info),
        normals_(options.normals), selection_{info.frame_start, info.frame_count, options.frame_step} {}

  std::vector<SummaryFile> summary_paths() const override {
    if (selection_.written() == 0) return {};
    return {sequence_summary(pattern_, selection_)};
  }

  // The rest mesh; write() replaces its positions and normals in the buffer frame by frame.
  void begin() override {
    GltfBuilder add(gltf_);
    std::map<std::string, int> attributes;
    const std::vector<float> rest = rest_positions_f32(model_);
    attributes["POSITION"] = position_ = add.floats(rest, TINYGLTF_TYPE_VEC3, 3, TINYGLTF_TARGET_ARRAY_BUFFER);
    set_bounds(gltf_, position_, rest, 3);
    if (normals_)
      attributes["NORMAL"] = normal_ = add.floats(rest_normals(model_), TINYGLTF_TYPE_VEC3, 3,
                                                  TINYGLTF_TARGET_ARRAY_BUFFER);
    attributes["TEXCOORD_0"] = add.floats(gltf_uvs(model_), TINYGLTF_TYPE_VEC2, 2, TINYGLTF_TARGET_ARRAY_BUFFER);
    add_tree_scene(add, model_, info_, attributes);
  }

  void write(const FrameData& frame) override {
    replace(position_, frame.positions);
    set_bounds(gltf_, position_, frame.positions, 3);
    if (normals_) replace(normal_, frame.normals);
    const fs::path target = pattern_.frame(frame.frame);
    write_glb(gltf_, staged_.stage(target), target);
  }

 private:
  // Overwrites the data of float accessor `accessor` (its own view) with `values`.
  void replace(int accessor, const std::vector<float>& values) {
    const tinygltf::BufferView& view = gltf_.bufferViews[size_t(gltf_.accessors[size_t(accessor)].bufferView)];
    std::memcpy(gltf_.buffers[0].data.data() + view.byteOffset, values.data(), view.byteLength);
  }

  SequencePattern pattern_;
  const TreeModel& model_;
  BakeInfo info_;
  bool normals_;  // NORMAL in every frame
  FrameSelection selection_;
  tinygltf::Model gltf_;  // the mesh; positions and normals replaced per frame
  int position_ = -1, normal_ = -1;  // accessors
};

}  // namespace

void gltf_targets(const OutputOptions& options, const fs::path& path, const FrameSelection& selection,
                  const TargetVisitor& visit) {
  const SequencePattern pattern = sequence_pattern(path, ".glb", options.where());
  for (long long k = 0; k < selection.written(); ++k)
    visit(pattern.frame(selection.start + k * selection.step), TargetKind::kFrame);
}

std::unique_ptr<FrameSink> make_gltf_sink(const OutputOptions& options, const fs::path& path,
                                          const TreeModel& model, const BakeInfo& info) {
  return std::make_unique<GltfSink>(options, path, model, info);
}

}  // namespace treeanim
