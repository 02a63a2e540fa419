// Point caches plus the rest OBJ they deform: one array of float32 xyz per written frame after a
// small header, read by Blender's and 3ds Max's Mesh Cache modifiers (PC2, MDD) and Houdini (MDD).
// - PC2 (POINTCACHE2, little-endian): char[12] "POINTCACHE2\0", int32 version 1, int32 points,
//   float32 start frame, float32 sample rate (frames between samples), int32 samples.
// - MDD (big-endian): int32 frames, int32 points, float32 time of each frame (s).
#include <optional>

#include "common/errors.h"
#include "files/output_file.h"
#include "files/staged_files.h"
#include "formats/frame_sink.h"
#include "formats/obj_format.h"
#include "formats/rest_positions_f32.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

enum class CacheFormat { kPc2, kMdd };

class PointCacheSink final : public FrameSink {
 public:
  PointCacheSink(CacheFormat format, const OutputOptions& options, const fs::path& path, const TreeModel& model,
                 const BakeInfo& info)
      : format_(format), path_(with_extension(path, format == CacheFormat::kPc2 ? ".pc2" : ".mdd")),
        rest_(fs::path(path_).replace_extension(".rest.obj")), mtl_(fs::path(path_).replace_extension(".rest.mtl")),
        model_(model), info_(info),
        selection_{info.frame_start, info.frame_count, options.frame_step} {}

  void for_each_target(const std::function<void(const fs::path&)>& visit) const override {
    visit(path_);
    visit(rest_);
    visit(mtl_);
  }
  std::vector<fs::path> summary_paths() const override { return {path_, rest_}; }

  void begin() override {
    write_mtl_file(staged_.stage(mtl_), mtl_, info_.generator + ", materials", info_.materials);
    write_obj_file(staged_.stage(rest_), rest_, info_.generator + ", rest pose for " + path_.filename().string(),
                   rest_positions_f32(model_), obj_shared_lines(model_, mtl_.filename().string()));
    file_.emplace(staged_.stage(path_), path_);
    const auto samples = uint32_t(selection_.written());
    const auto points = uint32_t(model_.vertex_count());
    if (format_ == CacheFormat::kPc2) {
      static const char signature[12] = "POINTCACHE2";
      file_->write(signature, sizeof signature);
      const float start = float(info_.frame_start), rate = float(selection_.step);
      file_->write_u32_le(1);
      file_->write_u32_le(points);
      file_->write_f32_le(&start, 1);
      file_->write_f32_le(&rate, 1);
      file_->write_u32_le(samples);
    } else {
      file_->write_u32_be(samples);
      file_->write_u32_be(points);
      times_.reserve(samples);
      const std::vector<float> unknown_yet(samples, 0.0f);  // the times, filled in by finish()
      file_->write_f32_be(unknown_yet.data(), unknown_yet.size());
    }
  }

  void write(const FrameData& frame) override {
    if (format_ == CacheFormat::kPc2) {
      file_->write_f32_le(frame.positions.data(), frame.positions.size());
    } else {
      file_->write_f32_be(frame.positions.data(), frame.positions.size());
      times_.push_back(float(frame.time));
    }
    ++samples_;
  }

  void finish() override {
    if (samples_ != selection_.written())
      throw OutputError(path_.string() + ": the header announces " + std::to_string(selection_.written()) +
                        " samples but the bake delivered " + std::to_string(samples_));
    if (format_ == CacheFormat::kMdd) {
      file_->seek(8);
      file_->write_f32_be(times_.data(), times_.size());
    }
    file_->close();
    file_.reset();
  }

  void abort() noexcept override {
    file_.reset();
    staged_.discard();
  }

 private:
  static fs::path with_extension(const fs::path& path, const std::string& extension) {
    return path.extension() == extension ? path : fs::path(path.string() + extension);
  }

  CacheFormat format_;
  fs::path path_;  // "<name>.pc2" or "<name>.mdd"
  fs::path rest_;  // "<name>.rest.obj"
  fs::path mtl_;   // "<name>.rest.mtl", the materials the rest OBJ names
  const TreeModel& model_;
  BakeInfo info_;
  FrameSelection selection_;
  std::optional<OutputFile> file_;
  std::vector<float> times_;  // MDD: (samples written) s
  long long samples_ = 0;
};

}  // namespace

std::unique_ptr<FrameSink> make_pc2_sink(const OutputOptions& options, const fs::path& path,
                                         const TreeModel& model, const BakeInfo& info) {
  return std::make_unique<PointCacheSink>(CacheFormat::kPc2, options, path, model, info);
}

std::unique_ptr<FrameSink> make_mdd_sink(const OutputOptions& options, const fs::path& path,
                                         const TreeModel& model, const BakeInfo& info) {
  return std::make_unique<PointCacheSink>(CacheFormat::kMdd, options, path, model, info);
}

}  // namespace treeanim
