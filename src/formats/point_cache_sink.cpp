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
#include "formats/sink_factories.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

enum class CacheFormat { kPc2, kMdd };

// What a point cache writes.
struct PointCacheFiles {
  fs::path cache;  // "<name>.pc2" or "<name>.mdd"
  fs::path rest;   // "<name>.rest.obj"
  fs::path mtl;    // "<name>.rest.mtl", the materials the rest OBJ names
};

// The output's path => its files; the cache's extension is added unless the path has it.
PointCacheFiles point_cache_files(CacheFormat format, const fs::path& path) {
  const std::string extension = format == CacheFormat::kPc2 ? ".pc2" : ".mdd";
  const fs::path cache = path.extension() == extension ? path : fs::path(path.string() + extension);
  return {cache, fs::path(cache).replace_extension(".rest.obj"), fs::path(cache).replace_extension(".rest.mtl")};
}

void point_cache_targets(CacheFormat format, const fs::path& path, const TargetVisitor& visit) {
  const PointCacheFiles files = point_cache_files(format, path);
  for (const fs::path* file : {&files.cache, &files.rest, &files.mtl}) visit(*file, TargetKind::kFile);
}

class PointCacheSink final : public FrameSink {
 public:
  PointCacheSink(CacheFormat format, const OutputOptions& options, const fs::path& path, const TreeModel& model,
                 const BakeInfo& info)
      : format_(format), files_(point_cache_files(format, path)), model_(model), info_(info),
        selection_{info.frame_start, info.frame_count, options.frame_step} {}

  std::vector<SummaryFile> summary_paths() const override { return {{files_.cache}, {files_.rest}}; }

  void begin() override {
    write_mtl_file(staged_.stage(files_.mtl), files_.mtl, info_.generator + ", materials", info_.materials);
    write_obj_file(staged_.stage(files_.rest), files_.rest,
                   info_.generator + ", rest pose for " + files_.cache.filename().string(), rest_positions_f32(model_),
                   obj_shared_lines(model_, files_.mtl.filename().string()));
    file_.emplace(staged_.stage(files_.cache), files_.cache);
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
      throw OutputError(files_.cache.string() + ": the header announces " + std::to_string(selection_.written()) +
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
  CacheFormat format_;
  PointCacheFiles files_;
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
  // Its header's start frame is a float32, which holds every whole frame only up to 2^24.
  if (double(float(info.frame_start)) != double(info.frame_start))
    throw InputError(options.where() + ": PC2 keeps its start frame in float32, which cannot hold frame " +
                     std::to_string(info.frame_start) + " (past 16777216 it holds only some whole frames): bake "
                     "nearer frame 0 (time.start)");
  return std::make_unique<PointCacheSink>(CacheFormat::kPc2, options, path, model, info);
}

std::unique_ptr<FrameSink> make_mdd_sink(const OutputOptions& options, const fs::path& path,
                                         const TreeModel& model, const BakeInfo& info) {
  check_float32_key_times(options, info, "MDD frames", false);
  return std::make_unique<PointCacheSink>(CacheFormat::kMdd, options, path, model, info);
}

void pc2_targets(const OutputOptions&, const fs::path& path, const FrameSelection&, const TargetVisitor& visit) {
  point_cache_targets(CacheFormat::kPc2, path, visit);
}

void mdd_targets(const OutputOptions&, const fs::path& path, const FrameSelection&, const TargetVisitor& visit) {
  point_cache_targets(CacheFormat::kMdd, path, visit);
}

}  // namespace treeanim
