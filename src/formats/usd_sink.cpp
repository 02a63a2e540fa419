// USD ("usd", docs/outputs.md "USD layer"): one .usda text layer, a Mesh whose points carry a
// time sample per written frame, streamed as the frames come (extents and normals follow the
// points: the extents are kept, the normals' samples go to a scratch file beside the output and
// are copied in at the end). With "skinned" the layer is UsdSkel, a writer of its own
// (formats/skinned_usd_sink.cpp), as the skinned GLB is beside the GLB.
#include <algorithm>
#include <array>
#include <cstdio>
#include <limits>
#include <optional>

#include "common/errors.h"
#include "files/io_failure.h"
#include "files/output_file.h"
#include "files/staged_files.h"
#include "formats/frame_sink.h"
#include "formats/usd_layer.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

// Where a sample's line starts: inside the Mesh.
constexpr const char* kSampleIndent = "            ";

class UsdSink final : public FrameSink {
 public:
  UsdSink(const OutputOptions& options, fs::path path, const TreeModel& model, const BakeInfo& info)
      : path_(std::move(path)), model_(model), info_(info),
        selection_{info.frame_start, info.frame_count, options.frame_step}, normals_(options.normals) {}

  std::vector<SummaryFile> summary_paths() const override { return {{path_}}; }

  void begin() override {
    temporary_ = staged_.stage(path_);
    file_.emplace(temporary_, path_);
    // Named after the layer's temporary, not as one: ".NAME.normals.tmp-PID" is the temporary of
    // an output named NAME.normals.
    scratch_path_ = temporary_.string() + ".normals";
    if (normals_) scratch_.emplace(scratch_path_, path_);
    std::string out = usd_layer_header(info_, selection_, "");
    out += "def Xform \"Tree\" (\n    kind = \"component\"\n)\n{\n";
    out += "    def Mesh \"Mesh\" (\n        prepend apiSchemas = [\"MaterialBindingAPI\"]\n    )\n    {\n";
    out += usd_mesh_rest_attributes(model_, normals_);
    if (normals_) scratch_->write("        normal3f[] normals.timeSamples = {\n");
    out += "        point3f[] points.timeSamples = {\n";
    file_->write(out);
  }

  void write(const FrameData& frame) override {
    std::array<float, 6> extent = {std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
                                   std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(),
                                   -std::numeric_limits<float>::max(), -std::numeric_limits<float>::max()};
    for (size_t i = 0; i < frame.positions.size(); ++i) {
      extent[i % 3] = std::min(extent[i % 3], frame.positions[i]);
      extent[3 + i % 3] = std::max(extent[3 + i % 3], frame.positions[i]);
    }
    extents_.push_back({frame.frame, extent});
    text_.clear();
    append_usd_sample(text_, kSampleIndent, frame.frame, frame.positions.data(), model_.vertex_count(), 3);
    file_->write(text_);
    if (normals_) {
      text_.clear();
      append_usd_sample(text_, kSampleIndent, frame.frame, frame.normals.data(), model_.vertex_count(), 3);
      scratch_->write(text_);
    }
  }

  void finish() override {
    std::string out = "        }\n        float3[] extent.timeSamples = {\n";
    for (const auto& [frame, extent] : extents_) append_usd_sample(out, kSampleIndent, frame, extent.data(), 2, 3);
    file_->write(out + "        }\n");
    if (normals_) {
      scratch_->write("        }\n");
      scratch_->close();
      copy_scratch();
    }
    file_->write(usd_material_subsets(model_, "        ") + "    }\n" + usd_materials(info_.materials) + "}\n");
    file_->close();
  }

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
};

}  // namespace

std::unique_ptr<FrameSink> make_usd_sink(const OutputOptions& options, const fs::path& path, const TreeModel& model,
                                         const BakeInfo& info) {
  return std::make_unique<UsdSink>(options, path, model, info);
}

}  // namespace treeanim
