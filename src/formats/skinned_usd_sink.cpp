// USD as UsdSkel ("usd" with "skinned", docs/outputs.md "USD layer"): one .usda text layer, the
// rest mesh bound to a Skeleton of one joint per cluster (or per limb, option max_joints),
// animated by the keys the skinned GLB writes (formats/skin_track.h); the fit's error goes into
// the layer's customLayerData and the run's summary. The whole layer is written at the end: the
// keys of every frame are kept until then.
#include <memory>
#include <optional>
#include <vector>

#include "files/output_file.h"
#include "formats/frame_sink.h"
#include "formats/skin_fit.h"
#include "formats/skin_track.h"
#include "formats/usd_layer.h"
#include "formats/usd_text.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

// Where a key's line starts: inside the SkelAnimation.
constexpr const char* kKeyIndent = "                ";

class SkinnedUsdSink final : public FrameSink {
 public:
  SkinnedUsdSink(const OutputOptions& options, fs::path path, const TreeModel& model, const BakeInfo& info)
      : path_(std::move(path)), model_(model), info_(info),
        selection_{info.frame_start, info.frame_count, options.frame_step}, normals_(options.normals),
        skin_(build_skin(model, options.max_joints > 0 ? options.max_joints : model.cluster_count())) {}

  std::vector<SummaryFile> summary_paths() const override { return {{path_}}; }

  void begin() override { file_.emplace(staged_.stage(path_), path_); }

  void write(const FrameData& frame) override {
    add_skin_frame(skin_, model_, frame.positions.data(), frame.cluster_motions, frame.time, track_);
  }

  void finish() override {
    error_ = skin_error(track_, model_.vertex_count());
    file_->write(skinned_layer());
    file_->close();
  }

  std::string report() const override { return skin_error_report(error_, skin_.joint_count()); }

  void abort() noexcept override {
    file_.reset();
    staged_.discard();
  }

 private:
  // "j0", "j0/j3", ...: each joint's path through its ancestors (parents come first).
  std::vector<std::string> joint_paths() const {
    std::vector<std::string> paths(skin_.joint_count());
    for (size_t j = 0; j < paths.size(); ++j) {
      const int32_t parent = skin_.joint_parent[j];
      paths[j] = (parent < 0 ? "" : paths[size_t(parent)] + "/") + "j" + std::to_string(j);
    }
    return paths;
  }

  // The error the fit reports, in the layer's customLayerData (relative values of the RMS displacement).
  std::string error_metadata() const {
    std::string out = "        dictionary treeanim_skinning = {\n            double largest_error_m = ";
    append_usd_number(out, track_.largest_error);
    out += "\n            double rms_displacement_m = ";
    append_usd_number(out, error_.rms_displacement);
    out += "\n            double rms_error_m = ";
    append_usd_number(out, error_.rms_error);
    out += "\n            double skinning_error_max = ";
    append_usd_number(out, error_.relative_max);
    out += "\n            double skinning_error_rms = ";
    append_usd_number(out, error_.relative_rms);
    out += "\n            double[] frame_rms_error_m = [";
    for (size_t f = 0; f < track_.frame_rms_error.size(); ++f) {
      if (f > 0) out += ", ";
      append_usd_number(out, track_.frame_rms_error[f]);
    }
    return out + "]\n        }\n";
  }

  std::string skinned_layer() const {
    const Skin& skin = skin_;
    const size_t joints = skin.joint_count(), n = model_.vertex_count();
    std::string joint_list = "[";
    for (const std::string& joint : joint_paths())
      joint_list += (joint_list.size() > 1 ? ", " : "") + usd_quoted(joint);
    joint_list += ']';
    std::string out = usd_layer_header(info_, selection_, error_metadata());
    out += "def SkelRoot \"Tree\" (\n    kind = \"component\"\n)\n{\n";
    out += "    def Skeleton \"Skeleton\" (\n        prepend apiSchemas = [\"SkelBindingAPI\"]\n    )\n    {\n";
    out += "        uniform token[] joints = " + joint_list + "\n        uniform matrix4d[] bindTransforms = [";
    for (size_t j = 0; j < joints; ++j) {
      out += j > 0 ? ", " : "";
      append_usd_matrix(out, Eigen::Matrix3d::Identity(), skin.joint_pivot[j]);
    }
    out += "]\n        uniform matrix4d[] restTransforms = [";
    for (size_t j = 0; j < joints; ++j) {
      const int32_t parent = skin.joint_parent[j];
      out += j > 0 ? ", " : "";
      const Eigen::Vector3d local =
          parent < 0 ? skin.joint_pivot[j] : Eigen::Vector3d(skin.joint_pivot[j] - skin.joint_pivot[size_t(parent)]);
      append_usd_matrix(out, Eigen::Matrix3d::Identity(), local);
    }
    out += "]\n        rel skel:animationSource = </Tree/Skeleton/Wind>\n\n";
    out += "        def SkelAnimation \"Wind\"\n        {\n            uniform token[] joints = " + joint_list + "\n";
    out += "            float3[] translations.timeSamples = {\n";
    const size_t frames = track_.times.size();
    const auto code = [&](size_t f) { return selection_.start + (long long)f * selection_.step; };
    for (size_t f = 0; f < frames; ++f)
      append_usd_sample(out, kKeyIndent, code(f), track_.translations.data() + 3 * joints * f, joints, 3);
    out += "            }\n            quatf[] rotations.timeSamples = {\n";
    std::vector<float> wxyz(4 * joints);
    for (size_t f = 0; f < frames; ++f) {
      const float* xyzw = track_.rotations.data() + 4 * joints * f;
      for (size_t j = 0; j < joints; ++j)
        for (size_t c = 0; c < 4; ++c) wxyz[4 * j + c] = xyzw[4 * j + (c + 3) % 4];  // USD's real part first
      append_usd_sample(out, kKeyIndent, code(f), wxyz.data(), joints, 4);
    }
    const std::vector<float> ones(3 * joints, 1.0f);
    out += "            }\n            half3[] scales = ";
    append_usd_tuples(out, ones.data(), joints, 3);
    out += "\n        }\n    }\n\n";
    out += "    def Mesh \"Mesh\" (\n        prepend apiSchemas = [\"SkelBindingAPI\", \"MaterialBindingAPI\"]\n"
           "    )\n    {\n";
    out += usd_mesh_rest_attributes(model_, normals_);
    std::vector<uint32_t> indices(kSkinInfluences * n);
    std::vector<float> weights(kSkinInfluences * n);
    for (size_t v = 0; v < n; ++v)
      for (size_t k = 0; k < size_t(kSkinInfluences); ++k) {
        indices[kSkinInfluences * v + k] = skin.vertex_joints[v][k];
        weights[kSkinInfluences * v + k] = skin.vertex_weights[v][k];
      }
    const std::string element = " (\n            elementSize = " + std::to_string(kSkinInfluences) +
                                "\n            interpolation = \"vertex\"\n        )\n";
    out += "        int[] primvars:skel:jointIndices = ";
    append_usd_ints(out, indices.data(), indices.size());
    out += element + "        float[] primvars:skel:jointWeights = ";
    append_usd_tuples(out, weights.data(), weights.size(), 1);
    out += element + "        matrix4d primvars:skel:geomBindTransform = ";
    append_usd_matrix(out, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
    out += "\n        rel skel:skeleton = </Tree/Skeleton>\n";
    return out + usd_material_subsets(model_, "        ") + "    }\n" + usd_materials(info_.materials) + "}\n";
  }

  fs::path path_;
  const TreeModel& model_;
  BakeInfo info_;
  FrameSelection selection_;
  bool normals_ = false;
  Skin skin_;
  std::optional<OutputFile> file_;
  SkinTrack track_;  // every written frame's keys and errors
  SkinError error_;  // after finish()
};

}  // namespace

std::unique_ptr<FrameSink> make_skinned_usd_sink(const OutputOptions& options, const fs::path& path,
                                                 const TreeModel& model, const BakeInfo& info) {
  return std::make_unique<SkinnedUsdSink>(options, path, model, info);
}

}  // namespace treeanim
