// PC2 point cache (POINTCACHE2, little-endian) plus the rest OBJ it deforms, for Blender's
// and 3ds Max's Mesh Cache modifier. Header: char[12] "POINTCACHE2\0", int32 version 1,
// int32 points, float32 start frame, float32 sample rate (frames between samples),
// int32 samples; then samples x points x 3 float32.
#include <optional>

#include "common/errors.h"
#include "io/frame_sink.h"
#include "io/obj_format.h"
#include "io/output_file.h"
#include "io/staged_files.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

class Pc2Sink final : public FrameSink {
 public:
  Pc2Sink(const OutputOptions& options, const fs::path& path, const TreeModel& model, const BakeInfo& info)
      : path_(path.extension() == ".pc2" ? path : fs::path(path.string() + ".pc2")),
        rest_(fs::path(path_).replace_extension(".rest.obj")), model_(model),
        info_(info), selection_{info.frame_start, info.frame_count, options.frame_step} {}

  void for_each_target(const std::function<void(const fs::path&)>& visit) const override {
    visit(path_);
    visit(rest_);
  }
  std::vector<fs::path> summary_paths() const override { return {path_, rest_}; }

  void begin() override {
    write_obj_file(staged_.stage(rest_), rest_, info_.generator + ", rest pose for " + path_.filename().string(),
                   rest_positions_f32(model_), obj_shared_lines(model_));
    file_.emplace(staged_.stage(path_), path_);
    static const char signature[12] = "POINTCACHE2";
    file_->write(signature, sizeof signature);
    const float start = float(info_.frame_start), rate = float(selection_.step);
    file_->write_u32_le(1);
    file_->write_u32_le(uint32_t(model_.vertex_count()));
    file_->write_f32_le(&start, 1);
    file_->write_f32_le(&rate, 1);
    file_->write_u32_le(uint32_t(selection_.written()));
  }

  void write(const FrameData& frame) override {
    file_->write_f32_le(frame.positions.data(), frame.positions.size());
    ++samples_;
  }

  void finish() override {
    if (samples_ != selection_.written())
      throw OutputError(path_.string() + ": the header announces " + std::to_string(selection_.written()) +
                        " samples but the bake delivered " + std::to_string(samples_));
    file_->close();
    file_.reset();
  }

  void abort() noexcept override {
    file_.reset();
    staged_.discard();
  }

 private:
  fs::path path_;  // "<name>.pc2"
  fs::path rest_;  // "<name>.rest.obj"
  const TreeModel& model_;
  BakeInfo info_;
  FrameSelection selection_;
  std::optional<OutputFile> file_;
  long long samples_ = 0;
};

}  // namespace

std::unique_ptr<FrameSink> make_pc2_sink(const OutputOptions& options, const fs::path& path,
                                         const TreeModel& model, const BakeInfo& info) {
  return std::make_unique<Pc2Sink>(options, path, model, info);
}

}  // namespace treeanim
