// Vertex animation textures (docs/outputs.md "Vertex animation textures"), for game engines:
// STEM.positions.exr (offsets from the rest pose) and STEM.normals.exr (unit normals), RGB, one
// texel per vertex and frame; STEM.glb, the rest mesh with a second UV set addressing each
// vertex's texel; STEM.json, the layout. Vertex v of written frame f is at column v % width,
// row f * rows_per_frame + v / width, row 0 the first scanline (the top of the image): Houdini
// Labs' VAT 3.0 soft-body layout. The EXR scanlines are written frame by frame as they come.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <tiny_gltf.h>

#include <Iex.h>
#include <algorithm>
#include <array>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>

#include "common/errors.h"
#include "files/output_file.h"
#include "formats/frame_sink.h"
#include "formats/gltf_mesh.h"
#include "formats/rest_positions_f32.h"
#include "formats/sink_factories.h"
#include "formats/vat_layout.h"
#include "formats/vertex_normals.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

// One RGB texture written scanline by scanline into its temporary.
class ExrTexture {
 public:
  ExrTexture(const fs::path& temporary, const fs::path& target, const VatLayout& layout, bool half)
      : target_(target), half_(half), width_(layout.width) {
    Imf::Header header(int(layout.width), int(layout.height));
    header.compression() = Imf::ZIP_COMPRESSION;  // lossless: the bake's floats come back exactly
    for (const char* channel : {"R", "G", "B"})
      header.channels().insert(channel, Imf::Channel(half ? Imf::HALF : Imf::FLOAT));
    try {
      file_.emplace(temporary.c_str(), header);
    } catch (const std::exception& e) {
      throw OutputError(target_.string() + ": OpenEXR could not create " + temporary.string() + ": " + e.what());
    }
  }

  // Writes the next `rows` scanlines from `rgb` (rows x width x 3 floats).
  void write_rows(const std::vector<float>& rgb, size_t rows) {
    try {
      Imf::FrameBuffer buffer;
      const size_t pixel = 3 * (half_ ? sizeof(Imath::half) : sizeof(float));
      char* base = half_ ? reinterpret_cast<char*>(halves(rgb).data()) : reinterpret_cast<char*>(const_cast<float*>(rgb.data()));
      // OpenEXR addresses pixel (x, y) at base + x * xStride + y * yStride, y counted from the
      // data window's top: shift the base so that this batch's first row lands at next_row_.
      base -= ptrdiff_t(next_row_) * ptrdiff_t(pixel * width_);
      const char* names[3] = {"R", "G", "B"};
      for (int c = 0; c < 3; ++c)
        buffer.insert(names[c], Imf::Slice(half_ ? Imf::HALF : Imf::FLOAT,
                                           base + c * (half_ ? sizeof(Imath::half) : sizeof(float)), pixel,
                                           pixel * width_));
      file_->setFrameBuffer(buffer);
      file_->writePixels(int(rows));
      next_row_ += rows;
    } catch (const std::exception& e) {
      throw OutputError(target_.string() + ": OpenEXR could not write rows " + std::to_string(next_row_) + "-" +
                        std::to_string(next_row_ + rows - 1) + ": " + e.what());
    }
  }

  // Flushes and closes (the destructor writes the line offset table).
  void close() {
    try {
      file_.reset();
    } catch (const std::exception& e) {
      throw OutputError(target_.string() + ": OpenEXR could not finish the file: " + e.what());
    }
  }

 private:
  std::vector<Imath::half>& halves(const std::vector<float>& rgb) {
    half_buffer_.assign(rgb.begin(), rgb.end());
    return half_buffer_;
  }

  fs::path target_;
  bool half_;
  size_t width_;
  size_t next_row_ = 0;
  std::optional<Imf::OutputFile> file_;
  std::vector<Imath::half> half_buffer_;
};

// The rest mesh as a GLB: POSITION, NORMAL, TEXCOORD_0 (the model's UVs), TEXCOORD_1 (the texel
// of each vertex in frame 0, at its centre), the materials.
void write_rest_glb(const fs::path& temporary, const fs::path& target, const TreeModel& model,
                    const VatLayout& layout, const BakeInfo& info) {
  const size_t n = model.vertex_count();
  const std::vector<float> rest = rest_positions_f32(model);
  std::vector<float> uv1(2 * n);
  for (size_t v = 0; v < n; ++v) {
    const auto [column, row] = layout.texel(v, 0);
    uv1[2 * v] = float((double(column) + 0.5) / double(layout.width));
    uv1[2 * v + 1] = float((double(row) + 0.5) / double(layout.height));
  }
  tinygltf::Model gltf;
  GltfBuilder add(gltf);
  std::map<std::string, int> attributes;
  attributes["POSITION"] = add.floats(rest, TINYGLTF_TYPE_VEC3, 3, TINYGLTF_TARGET_ARRAY_BUFFER);
  set_bounds(gltf, attributes["POSITION"], rest, 3);
  attributes["NORMAL"] = add.floats(rest_normals(model), TINYGLTF_TYPE_VEC3, 3, TINYGLTF_TARGET_ARRAY_BUFFER);
  attributes["TEXCOORD_0"] = add.floats(gltf_uvs(model), TINYGLTF_TYPE_VEC2, 2, TINYGLTF_TARGET_ARRAY_BUFFER);
  attributes["TEXCOORD_1"] = add.floats(uv1, TINYGLTF_TYPE_VEC2, 2, TINYGLTF_TARGET_ARRAY_BUFFER);
  add_tree_scene(add, model, info, attributes);
  write_glb(gltf, temporary, target);
}

class VatSink final : public FrameSink {
 public:
  VatSink(const OutputOptions& options, const fs::path& stem, const TreeModel& model, const BakeInfo& info)
      : stem_(stem.string()), model_(model), info_(info),
        selection_{info.frame_start, info.frame_count, options.frame_step}, half_(options.vat_half),
        layout_(vat_layout(model.vertex_count(), size_t(selection_.written()), options.texture_width)) {
    if (layout_.rows_per_frame > kVatMaxSize)  // no frame fits, whatever the frame_step
      throw InputError(options.where() + "/texture_width: " + std::to_string(layout_.width) + " texels a row put a frame's " +
                       std::to_string(model.vertex_count()) + " vertices on " + std::to_string(layout_.rows_per_frame) +
                       " rows, over " + std::to_string(kVatMaxSize) + "; expected at least " +
                       std::to_string((model.vertex_count() + kVatMaxSize - 1) / kVatMaxSize) + " (or 0: as wide as the vertices)");
    if (layout_.height > kVatMaxSize)
      throw InputError(options.where() + ": the vertex animation textures would be " + std::to_string(layout_.width) +
                       " x " + std::to_string(layout_.height) + " texels (" + std::to_string(layout_.rows_per_frame) +
                       " rows a frame x " + std::to_string(selection_.written()) + " frames), over " +
                       std::to_string(kVatMaxSize) + " x " + std::to_string(kVatMaxSize) + "; at most " +
                       std::to_string(kVatMaxSize / layout_.rows_per_frame * size_t(options.frame_step)) +
                       " frames of this bake fit at frame_step " + std::to_string(options.frame_step) +
                       " (raise frame_step or shorten the bake)");
  }

  std::vector<SummaryFile> summary_paths() const override {
    return {{stem_ + ".positions.exr"}, {stem_ + ".normals.exr"}, {stem_ + ".glb"}, {stem_ + ".json"}};
  }

  void begin() override {
    rest_ = rest_positions_f32(model_);
    const fs::path positions = stem_ + ".positions.exr", normals = stem_ + ".normals.exr";
    positions_.emplace(staged_.stage(positions), positions, layout_, half_);
    normals_.emplace(staged_.stage(normals), normals, layout_, half_);
    const fs::path glb = stem_ + ".glb";
    write_rest_glb(staged_.stage(glb), glb, model_, layout_, info_);
    rows_.assign(3 * layout_.width * layout_.rows_per_frame, 0.0f);
  }

  void write(const FrameData& frame) override {
    for (size_t i = 0; i < rest_.size(); ++i) {
      rows_[i] = frame.positions[i] - rest_[i];
      const size_t axis = i % 3;
      low_[axis] = std::min(low_[axis], double(rows_[i]));
      high_[axis] = std::max(high_[axis], double(rows_[i]));
    }
    positions_->write_rows(rows_, layout_.rows_per_frame);
    std::copy(frame.normals.begin(), frame.normals.end(), rows_.begin());
    normals_->write_rows(rows_, layout_.rows_per_frame);
    ++frames_;
  }

  void finish() override {
    if (frames_ != size_t(selection_.written()))
      throw OutputError(stem_ + ".positions.exr: laid out for " + std::to_string(selection_.written()) +
                        " frames but the bake delivered " + std::to_string(frames_));
    positions_->close();
    normals_->close();
    const fs::path json_path = stem_ + ".json";
    const nlohmann::ordered_json layout = {
        {"generator", info_.generator},
        {"vertex_count", model_.vertex_count()},
        {"frame_count", frames_},
        {"fps", info_.fps / double(selection_.step)},
        {"frame_start", info_.frame_start},
        {"frame_step", selection_.step},
        {"texture_width", layout_.width},
        {"texture_height", layout_.height},
        {"rows_per_frame", layout_.rows_per_frame},
        {"bounds_min", frames_ ? std::vector<double>(low_.begin(), low_.end()) : std::vector<double>(3, 0.0)},
        {"bounds_max", frames_ ? std::vector<double>(high_.begin(), high_.end()) : std::vector<double>(3, 0.0)},
        {"loop", info_.loop},
        {"precision", half_ ? "half" : "float"},
        {"positions", fs::path(stem_ + ".positions.exr").filename().string()},
        {"normals", fs::path(stem_ + ".normals.exr").filename().string()},
        {"mesh", fs::path(stem_ + ".glb").filename().string()},
        {"units", "m"},
        {"up_axis", "Y"},
    };
    OutputFile file(staged_.stage(json_path), json_path);
    file.write(layout.dump(2) + "\n");
    file.close();
  }

  void abort() noexcept override {
    positions_.reset();  // OpenEXR's destructors do not throw; the files go with the temporaries
    normals_.reset();
    staged_.discard();
  }

 private:
  std::string stem_;
  const TreeModel& model_;
  BakeInfo info_;
  FrameSelection selection_;
  bool half_;
  VatLayout layout_;
  std::vector<float> rest_;           // (N*3) m, float rest pose the offsets are taken from
  std::vector<float> rows_;           // (rows_per_frame * width * 3) one frame's texels; padding stays 0
  std::optional<ExrTexture> positions_, normals_;
  std::array<double, 3> low_{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
                             std::numeric_limits<double>::max()};
  std::array<double, 3> high_{-std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
                              -std::numeric_limits<double>::max()};
  size_t frames_ = 0;
};

}  // namespace

void vat_targets(const OutputOptions&, const fs::path& stem, const FrameSelection&, const TargetVisitor& visit) {
  for (const char* suffix : {".positions.exr", ".normals.exr", ".glb", ".json"}) visit(stem.string() + suffix, TargetKind::kFile);
}

std::unique_ptr<FrameSink> make_vat_sink(const OutputOptions& options, const fs::path& path, const TreeModel& model,
                                         const BakeInfo& info) {
  return std::make_unique<VatSink>(options, path, model, info);
}

}  // namespace treeanim
