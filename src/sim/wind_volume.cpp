#include "sim/wind_volume.h"

#include <dlfcn.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "common/errors.h"
#include "common/frame_field.h"
#include "common/input_files.h"
#include "common/message_text.h"
#include "sim/volume_grids.h"

namespace treeanim {

// A frame's velocity grids, as the OpenVDB module read them.
struct VolumeFrame {
  std::unique_ptr<const VolumeGrids> grids;
};

namespace {

// The OpenVDB module's entry point `name`, the module loaded from beside the running binary on
// first use (volume_grids.h). Throws InputError when it cannot be loaded: the scene asks for a
// reader this installation lacks.
void* volume_module_entry(const char* name) {
  static std::string failure;
  static void* const handle = []() -> void* {
    std::error_code error;
    const std::filesystem::path module =
        std::filesystem::read_symlink("/proc/self/exe", error).parent_path() / TREEANIM_VOLUME_MODULE;
    void* loaded = dlopen(module.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!loaded) {
      const char* why = dlerror();
      failure = "treeanim's OpenVDB reader could not be loaded (" + std::string(why ? why : "no reason given") +
                "): it is built beside the treeanim binary, and a binary copied elsewhere needs it beside it";
    }
    return loaded;
  }();
  if (!handle) throw InputError(failure);
  void* entry = dlsym(handle, name);
  if (!entry) throw InputError("treeanim's OpenVDB reader lacks its entry point " + std::string(name));
  return entry;
}

bool volume_trials = false;  // allow_volume_trials

ReadVolumeGrids* volume_reader() {
  static ReadVolumeGrids* const read = reinterpret_cast<ReadVolumeGrids*>(volume_module_entry(kReadVolumeGrids));
  return read;
}

// Frame file => its velocity grids read whole. Throws InputError naming the file and the grid.
VolumeFrame read_frame(const std::string& path, const std::string& name) {
  ReadVolumeGrids* read = volume_reader();
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error))
    throw InputError(path + ": the volume frame is missing (no such file, or not a regular file)");
  std::string what;
  VolumeFrame frame;
  frame.grids.reset(read(path, name, volume_trials ? "/proc/self/exe" : nullptr, what));
  if (!frame.grids) throw InputError(path + ": " + what);
  note_input_file(path);
  return frame;
}

// A file name with a frame field is one file per frame; without, one file for all time.
bool has_frame_number(const std::filesystem::path& pattern) {
  FrameField field;
  return read_frame_field(pattern.filename().string(), field) && field.begin != std::string::npos;
}

}  // namespace

void allow_volume_trials() { volume_trials = true; }

int serve_volume_trials() {
  try {
    return reinterpret_cast<ServeVolumeTrials*>(volume_module_entry(kServeVolumeTrials))();
  } catch (const InputError&) {  // no module: the reader that spawned this one reads unchecked
    return 1;
  }
}

std::string volume_frame_path(const std::filesystem::path& pattern, long long number) {
  const std::string name = pattern.filename().string();
  FrameField field;  // the scene reader let through only a name with at most one field
  if (!read_frame_field(name, field) || field.begin == std::string::npos) return pattern.string();
  return (pattern.parent_path() / with_frame_number(name, field, number)).string();
}

VolumeFrames volume_frames_at(const VolumeOptions& options, double t) {
  if (!has_frame_number(options.path)) return {options.first_frame, options.first_frame, 0};
  const double u = t * options.fps + double(options.first_frame);
  const double nearest = std::round(u);
  // A time that is a frame's to rounding is that frame's: the bake's frames then read one volume frame each.
  if (std::abs(u - nearest) <= 1e-9 * std::max(1.0, std::abs(u)))
    return {static_cast<long long>(nearest), static_cast<long long>(nearest), 0};
  const double first = std::floor(u);
  return {static_cast<long long>(first), static_cast<long long>(first) + 1, u - first};
}

WindVolume::WindVolume(const VolumeOptions& options) : options_(options) {
  Eigen::Matrix3d up = Eigen::Matrix3d::Identity();
  // (x, y, z) => (x, z, -y), as Blender's glTF exporter turns a scene.
  if (options.z_up) up << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(options.rotate * std::numbers::pi / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  to_scene_ = options.units * turn * up;
  from_scene_ = to_scene_.inverse();
}

WindVolume::~WindVolume() = default;

VolumeInstant WindVolume::at(double t) const {
  const VolumeFrames wanted = volume_frames_at(options_, t);
  VolumeInstant instant;
  instant.number = {wanted.first, wanted.second};
  instant.weight = wanted.weight;
  std::lock_guard lock(mutex_);
  for (int j = 0; j < (wanted.weight > 0 ? 2 : 1); ++j) {
    const std::string path = volume_frame_path(options_.path, instant.number[j]);
    auto held = std::find_if(frames_.begin(), frames_.end(), [&](const auto& f) { return f.first == path; });
    if (held != frames_.end()) {
      std::rotate(held, held + 1, frames_.end());  // most recently used last
    } else {
      if (frames_.size() == kVolumeFramesKept) frames_.erase(frames_.begin());
      frames_.emplace_back(path, std::make_shared<const VolumeFrame>(read_frame(path, options_.grid)));
    }
    instant.frame[j] = frames_.back().second;
  }
  return instant;
}

bool WindVolume::sample(const VolumeFrame& frame, const Eigen::Vector3d& point, Eigen::Vector3d& velocity) const {
  Eigen::Vector3d v;
  if (!frame.grids->sample(from_scene_ * (point - options_.translate), options_.outside == VolumeOutside::kEdge, v))
    return false;
  velocity = to_scene_ * v;
  return true;
}

void WindVolume::sample(const VolumeFrame& frame, const Eigen::Matrix3Xd& points, Eigen::Matrix3Xd& velocity,
                        std::vector<uint8_t>& inside) const {
  // Column by column, as a single point is turned (a matrix product may sum in another order).
  Eigen::Matrix3Xd own(3, points.cols());
  for (Eigen::Index i = 0; i < points.cols(); ++i) own.col(i) = from_scene_ * (points.col(i) - options_.translate);
  frame.grids->sample(own, options_.outside == VolumeOutside::kEdge, velocity, inside);
  for (Eigen::Index i = 0; i < points.cols(); ++i)
    if (inside[size_t(i)]) velocity.col(i) = to_scene_ * Eigen::Vector3d(velocity.col(i));
}

Eigen::Vector3d WindVolume::blend(bool inside0, const Eigen::Vector3d& v0, bool inside1, const Eigen::Vector3d& v1,
                                  double weight, const Eigen::Vector3d& keys_mean) const {
  const Eigen::Vector3d outside = options_.outside == VolumeOutside::kKeys ? keys_mean : Eigen::Vector3d::Zero();
  const Eigen::Vector3d a = inside0 ? v0 : outside;
  if (weight == 0) return a;
  return (1 - weight) * a + weight * (inside1 ? v1 : outside);
}

Eigen::Vector3d WindVolume::mean(const VolumeInstant& instant, const Eigen::Vector3d& point,
                                 const Eigen::Vector3d& keys_mean) const {
  Eigen::Vector3d v0 = Eigen::Vector3d::Zero(), v1 = Eigen::Vector3d::Zero();
  const bool inside0 = sample(*instant.frame[0], point, v0);
  const bool inside1 = instant.frame[1] && sample(*instant.frame[1], point, v1);
  return blend(inside0, v0, inside1, v1, instant.weight, keys_mean);
}

VolumeSummary check_wind_volume(const VolumeOptions& options, double t0, double t1, double max_speed) {
  const VolumeFrames first = volume_frames_at(options, t0), last = volume_frames_at(options, t1);
  VolumeSummary summary;
  summary.first_frame = first.first;
  summary.last_frame = last.second;
  const WindVolume volume(options);
  bool& bounded = summary.active;
  for (long long number = summary.first_frame; number <= summary.last_frame; ++number) {
    const std::string path = volume_frame_path(options.path, number);
    std::error_code error;
    const std::filesystem::file_status status = std::filesystem::status(path, error);
    if (!std::filesystem::status_known(status))  // a loop of links, a name too long
      throw InputError(path + ": cannot read the volume frame: " + why_no_file(status, error));
    if (!std::filesystem::exists(status))
      throw InputError(path + ": the volume frame is missing, and the bake's times " + number_text(t0) + " s to " +
                       number_text(t1) + " s need frames " + std::to_string(summary.first_frame) + " to " +
                       std::to_string(summary.last_frame) + " (frame F blows at (F - " +
                       std::to_string(options.first_frame) + ") / " + number_text(options.fps) + " s)");
    const VolumeFrame frame = read_frame(path, options.grid);
    for (const Eigen::Vector3d& corner : frame.grids->corners()) {
      const Eigen::Vector3d x = volume.to_scene_point(corner);
      summary.lower = bounded ? Eigen::Vector3d(summary.lower.cwiseMin(x)) : x;
      summary.upper = bounded ? Eigen::Vector3d(summary.upper.cwiseMax(x)) : x;
      bounded = true;
    }
    if (number == summary.first_frame) {
      summary.voxel_size = frame.grids->voxel_size() * options.units;
      summary.layout = frame.grids->layout();
    }
    // Every active value, and the background the inactive ones read: finite and within the
    // wind's range, in m/s. `where` names the value, built only for a failure (a string per
    // voxel took seconds a frame on a dense cache).
    auto check = [&](auto where, double speed, bool finite) {
      if (!finite) throw InputError(where() + ": the velocity is not finite");
      speed *= options.units;
      if (speed > max_speed)
        throw InputError(where() + ": a speed of " + number_text(speed) + " m/s, beyond the wind's " +
                         number_text(max_speed) + " m/s (is `units` right?)");
      summary.largest_speed = std::max(summary.largest_speed, speed);
    };
    // A non-finite background names the grid that holds it (one of a split grid's three).
    const Eigen::Vector3d background = frame.grids->background();
    int axis = 0;
    while (axis < 2 && std::isfinite(background[axis])) ++axis;
    check([&] {
      return path + ": the background of " + (background.allFinite() ? frame.grids->layout() : frame.grids->grid_of(axis)) +
             " (the inactive voxels' value)";
    }, background.allFinite() ? background.norm() : 0, background.allFinite());
    frame.grids->visit_active([&](const std::string& grid, const std::array<int, 3>& ijk, double speed, bool finite) {
      check([&] {
        return path + ": grid '" + grid + "', voxel (" + std::to_string(ijk[0]) + ", " + std::to_string(ijk[1]) + ", " +
               std::to_string(ijk[2]) + ")";
      }, speed, finite);
    });
  }
  return summary;
}

}  // namespace treeanim
