// USD ("usd", docs/outputs.md "USD layer"): one .usda text layer. Without "skinned", a Mesh whose
// points carry a time sample per written frame, streamed as the frames come (extents and normals
// follow the points: the extents are kept, the normals' samples go to a scratch file beside the
// output and are copied in at the end). With "skinned", the same tree as UsdSkel: the rest mesh
// bound to a Skeleton of one joint per cluster, animated by the keys the skinned GLB writes
// (io/skin_track.h), the whole layer written at the end.
#include <algorithm>
#include <array>
#include <cstdio>
#include <limits>
#include <optional>

#include "common/errors.h"
#include "formats/frame_sink.h"
#include "formats/rest_positions_f32.h"
#include "files/output_file.h"
#include "formats/skin_fit.h"
#include "formats/skin_track.h"
#include "files/io_failure.h"
#include "files/staged_files.h"
#include "formats/usd_text.h"
#include "tree/surface_materials.h"
#include "formats/vertex_normals.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

// Where a sample's line starts: inside the Mesh, inside the SkelAnimation.
constexpr const char* kSampleIndent = "            ";
constexpr const char* kKeyIndent = "                ";

// The stage's metadata: the frames written are the time codes, one per frame at the bake's rate.
std::string layer_header(const BakeInfo& info, const FrameSelection& selection, const std::string& custom) {
  const long long last = selection.start + (selection.written() - 1) * selection.step;
  std::string out = "#usda 1.0\n(\n";
  if (!custom.empty()) out += "    customLayerData = {\n" + custom + "    }\n";
  out += "    defaultPrim = \"Tree\"\n    doc = " + usd_quoted(info.generator) + "\n";
  out += "    endTimeCode = " + std::to_string(std::max(selection.start, last)) + "\n    framesPerSecond = ";
  append_usd_number(out, info.fps);
  out += "\n    metersPerUnit = 1\n    startTimeCode = " + std::to_string(selection.start) +
         "\n    timeCodesPerSecond = ";
  append_usd_number(out, info.fps);
  out += "\n    upAxis = \"Y\"\n)\n\n";
  return out;
}

// One time sample of an array: "<indent><time code>: [...],\n".
void append_sample(std::string& out, const char* indent, long long code, const float* values, size_t count,
                   int width) {
  out += indent;
  out += std::to_string(code) + ": ";
  append_usd_tuples(out, values, count, width);
  out += ",\n";
}

void append_color(std::string& out, const std::array<float, 3>& linear) {
  out += '(';
  for (size_t c = 0; c < 3; ++c) {
    if (c > 0) out += ", ";
    append_usd_number(out, linear[c]);
  }
  out += ')';
}

// The mesh's topology, texture coordinates, rest points and (with_normals) rest normals: the
// attributes every form shares.
std::string mesh_rest_attributes(const TreeModel& model, bool with_normals) {
  const std::string indent = "        ";
  std::string out = indent + "uniform bool doubleSided = 1\n" + indent + "int[] faceVertexCounts = [";
  for (size_t t = 0; t < model.triangle_count(); ++t) out += t > 0 ? ", 3" : "3";
  out += "]\n" + indent + "int[] faceVertexIndices = ";
  append_usd_ints(out, model.triangles.data(), model.triangles.size());
  out += '\n' + indent + "point3f[] points = ";
  const std::vector<float> rest = rest_positions_f32(model);
  append_usd_tuples(out, rest.data(), model.vertex_count(), 3);
  const std::string vertex_interpolation = " (\n" + indent + "    interpolation = \"vertex\"\n" + indent + ")";
  if (size_t(model.uvs.cols()) == model.vertex_count()) {
    out += '\n' + indent + "texCoord2f[] primvars:st = ";
    append_usd_tuples(out, model.uvs.data(), model.vertex_count(), 2);
    out += vertex_interpolation;
  }
  if (with_normals) {
    out += '\n' + indent + "normal3f[] normals = ";
    const std::vector<float> normals = rest_normals(model);
    append_usd_tuples(out, normals.data(), model.vertex_count(), 3);
    out += vertex_interpolation;
  }
  out += '\n' + indent + "uniform token subdivisionScheme = \"none\"\n" + indent +
         "uniform token subsetFamily:materialBind:familyType = \"partition\"\n";
  return out;
}

// The USD prim names of the materials and their subsets, by TriangleMaterial.
constexpr const char* kMaterialPrims[kMaterialCount] = {"Bark", "Leaf"};
constexpr const char* kSubsetPrims[kMaterialCount] = {"bark", "leaves"};

// The bark and leaf subsets of the mesh, each bound to its material.
std::string material_subsets(const TreeModel& model, const std::string& indent) {
  std::string out;
  const auto triangles = material_triangles(model);
  for (size_t kind = 0; kind < kMaterialCount; ++kind) {
    const std::vector<uint32_t>& faces = triangles[kind];
    if (faces.empty()) continue;  // a leafless tree
    out += '\n' + indent + "def GeomSubset \"" + kSubsetPrims[kind] + "\" (\n" + indent +
           "    prepend apiSchemas = [\"MaterialBindingAPI\"]\n" + indent + ")\n" + indent + "{\n";
    out += indent + "    uniform token elementType = \"face\"\n" + indent +
           "    uniform token familyName = \"materialBind\"\n" + indent + "    int[] indices = ";
    append_usd_ints(out, faces.data(), faces.size());
    out += '\n' + indent + "    rel material:binding = </Tree/Materials/" + kMaterialPrims[kind] + ">\n" + indent +
           "}\n";
  }
  return out;
}

// The two UsdPreviewSurface materials under /Tree/Materials.
std::string materials(const std::array<SurfaceMaterial, kMaterialCount>& surfaces) {
  std::string out = "\n    def Scope \"Materials\"\n    {\n";
  for (size_t kind = 0; kind < kMaterialCount; ++kind) {
    const std::string name = kMaterialPrims[kind], path = "/Tree/Materials/" + name;
    out += "        def Material \"" + name + "\"\n        {\n";
    out += "            token outputs:surface.connect = <" + path + "/Surface.outputs:surface>\n\n";
    out += "            def Shader \"Surface\"\n            {\n";
    out += "                uniform token info:id = \"UsdPreviewSurface\"\n";
    out += "                color3f inputs:diffuseColor = ";
    append_color(out, surfaces[kind].base_color);
    out += "\n                float inputs:metallic = 0\n                float inputs:roughness = ";
    append_usd_number(out, float(surfaces[kind].roughness));
    out += "\n                token outputs:surface\n            }\n";
    out += "        }\n";
  }
  return out + "    }\n";
}

class UsdSink final : public FrameSink {
 public:
  UsdSink(const OutputOptions& options, fs::path path, const TreeModel& model, const BakeInfo& info)
      : path_(std::move(path)), model_(model), info_(info),
        selection_{info.frame_start, info.frame_count, options.frame_step}, normals_(options.normals) {
    if (options.skinned)
      skin_.emplace(build_skin(model, options.max_joints > 0 ? options.max_joints : model.cluster_count()));
  }

  void for_each_target(const std::function<void(const fs::path&)>& visit) const override { visit(path_); }
  std::vector<fs::path> summary_paths() const override { return {path_}; }

  void begin() override {
    temporary_ = staged_.stage(path_);
    file_.emplace(temporary_, path_);
    if (skin_) return;
    scratch_path_ = temporary_path(path_.string() + ".normals");
    if (normals_) scratch_.emplace(scratch_path_, path_);
    std::string out = layer_header(info_, selection_, "");
    out += "def Xform \"Tree\" (\n    kind = \"component\"\n)\n{\n";
    out += "    def Mesh \"Mesh\" (\n        prepend apiSchemas = [\"MaterialBindingAPI\"]\n    )\n    {\n";
    out += mesh_rest_attributes(model_, normals_);
    if (normals_) scratch_->write("        normal3f[] normals.timeSamples = {\n");
    out += "        point3f[] points.timeSamples = {\n";
    file_->write(out);
  }

  void write(const FrameData& frame) override {
    if (skin_) {
      add_skin_frame(*skin_, model_, frame.positions.data(), frame.time, track_);
      return;
    }
    std::array<float, 6> extent = {std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
                                   std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(),
                                   -std::numeric_limits<float>::max(), -std::numeric_limits<float>::max()};
    for (size_t i = 0; i < frame.positions.size(); ++i) {
      extent[i % 3] = std::min(extent[i % 3], frame.positions[i]);
      extent[3 + i % 3] = std::max(extent[3 + i % 3], frame.positions[i]);
    }
    extents_.push_back({frame.frame, extent});
    text_.clear();
    append_sample(text_, kSampleIndent, frame.frame, frame.positions.data(), model_.vertex_count(), 3);
    file_->write(text_);
    if (normals_) {
      text_.clear();
      append_sample(text_, kSampleIndent, frame.frame, frame.normals.data(), model_.vertex_count(), 3);
      scratch_->write(text_);
    }
  }

  void finish() override {
    if (skin_) {
      error_ = skin_error(track_, model_.vertex_count());
      file_->write(skinned_layer());
    } else {
      std::string out = "        }\n        float3[] extent.timeSamples = {\n";
      for (const auto& [frame, extent] : extents_) append_sample(out, kSampleIndent, frame, extent.data(), 2, 3);
      file_->write(out + "        }\n");
      if (normals_) {
        scratch_->write("        }\n");
        scratch_->close();
        copy_scratch();
      }
      file_->write(material_subsets(model_, "        ") + "    }\n" + materials(info_.materials) + "}\n");
    }
    file_->close();
  }

  std::string report() const override { return skin_ ? skin_error_report(error_, skin_->joint_count()) : ""; }

  void abort() noexcept override {
    file_.reset();
    scratch_.reset();
    std::error_code ignored;
    if (!scratch_path_.empty()) fs::remove(scratch_path_, ignored);
    staged_.discard();
  }

 private:
  // The normals' samples, written to the scratch file beside the output, appended to the layer.
  void copy_scratch() {
    std::FILE* in = std::fopen(scratch_path_.c_str(), "rb");
    if (!in) throw OutputError(io_failure(path_, "cannot reopen the normals' scratch file"));
    std::vector<char> buffer(1 << 20);
    size_t bytes = 0;
    while ((bytes = std::fread(buffer.data(), 1, buffer.size(), in)) > 0) file_->write(buffer.data(), bytes);
    const bool failed = std::ferror(in);
    std::fclose(in);
    if (failed) throw OutputError(io_failure(path_, "cannot read the normals' scratch file"));
    std::error_code ignored;
    fs::remove(scratch_path_, ignored);
  }

  // "j0", "j0/j3", ...: each joint's path through its ancestors (parents come first).
  std::vector<std::string> joint_paths() const {
    std::vector<std::string> paths(skin_->joint_count());
    for (size_t j = 0; j < paths.size(); ++j) {
      const int32_t parent = skin_->joint_parent[j];
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
    const Skin& skin = *skin_;
    const size_t joints = skin.joint_count(), n = model_.vertex_count();
    std::string joint_list = "[";
    for (const std::string& joint : joint_paths())
      joint_list += (joint_list.size() > 1 ? ", " : "") + usd_quoted(joint);
    joint_list += ']';
    std::string out = layer_header(info_, selection_, error_metadata());
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
      append_sample(out, kKeyIndent, code(f), track_.translations.data() + 3 * joints * f, joints, 3);
    out += "            }\n            quatf[] rotations.timeSamples = {\n";
    std::vector<float> wxyz(4 * joints);
    for (size_t f = 0; f < frames; ++f) {
      const float* xyzw = track_.rotations.data() + 4 * joints * f;
      for (size_t j = 0; j < joints; ++j)
        for (size_t c = 0; c < 4; ++c) wxyz[4 * j + c] = xyzw[4 * j + (c + 3) % 4];  // USD's real part first
      append_sample(out, kKeyIndent, code(f), wxyz.data(), joints, 4);
    }
    const std::vector<float> ones(3 * joints, 1.0f);
    out += "            }\n            half3[] scales = ";
    append_usd_tuples(out, ones.data(), joints, 3);
    out += "\n        }\n    }\n\n";
    out += "    def Mesh \"Mesh\" (\n        prepend apiSchemas = [\"SkelBindingAPI\", \"MaterialBindingAPI\"]\n"
           "    )\n    {\n";
    out += mesh_rest_attributes(model_, normals_);
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
    return out + material_subsets(model_, "        ") + "    }\n" + materials(info_.materials) + "}\n";
  }

  fs::path path_;
  fs::path temporary_;
  fs::path scratch_path_;                 // the normals' samples until finish()
  const TreeModel& model_;
  BakeInfo info_;
  FrameSelection selection_;
  bool normals_ = false;
  std::optional<OutputFile> file_;
  std::optional<OutputFile> scratch_;
  std::string text_;                      // scratch: one sample's text
  std::vector<std::pair<long long, std::array<float, 6>>> extents_;  // (F) time code, min and max
  std::optional<Skin> skin_;              // "skinned": the joints
  SkinTrack track_;                       // "skinned": every written frame's keys and errors
  SkinError error_;                       // "skinned": after finish()
};

}  // namespace

std::unique_ptr<FrameSink> make_usd_sink(const OutputOptions& options, const fs::path& path, const TreeModel& model,
                                         const BakeInfo& info) {
  if (options.path.extension() != ".usda")
    throw InputError(options.pointer + "/path: a usd output is a text layer whose name ends in .usda (e.g. \"" +
                     fs::path(options.path).replace_extension(".usda").string() + "\"), got \"" +
                     options.path.string() + "\"");
  return std::make_unique<UsdSink>(options, path, model, info);
}

}  // namespace treeanim
