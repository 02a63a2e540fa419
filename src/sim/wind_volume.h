#pragma once
// A velocity volume sequence as the mean wind (docs/scene.md `wind.volume`, docs/solver.md "A
// wind volume"): OpenVDB frames read on demand, at most kVolumeFramesKept in memory, sampled
// trilinearly in space and linearly in time. Sampling is a pure function of (position, time),
// so results never depend on threads, shards or the order frames were read in.
#include <Eigen/Core>
#include <array>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "sim/sim_options.h"

namespace treeanim {

// Frames kept in memory: the two around the current time and the one before them, which the
// frame loop's last substeps may still read.
constexpr size_t kVolumeFramesKept = 3;

// One frame of the sequence in memory (defined in wind_volume.cpp: the grids the OpenVDB module read).
struct VolumeFrame;

// The frames around one time: velocity = (1 - weight) frame[0] + weight frame[1].
struct VolumeInstant {
  std::array<std::shared_ptr<const VolumeFrame>, 2> frame;  // frame[1] is null when weight is 0
  std::array<long long, 2> number{0, 0};                    // their frame numbers
  double weight = 0;                                        // of frame[1], in [0, 1)
};

// A scene time => the sequence's frames around it and the weight of the later one, exact at a
// frame's own time (a time within 1e-9 of a frame's is that frame's).
struct VolumeFrames {
  long long first = 0, second = 0;  // second == first when weight is 0
  double weight = 0;
};
VolumeFrames volume_frames_at(const VolumeOptions& options, double t);

// The file of frame `number`: the file name's frame field (common/frame_field.h) replaced;
// a name without one is the one file of every frame.
std::string volume_frame_path(const std::filesystem::path& pattern, long long number);

// What `info` prints and `validate` checks (check_wind_volume).
struct VolumeSummary {
  long long first_frame = 0, last_frame = 0;  // the frames the bake reads
  // m, the scene's box around every frame's active voxels; `active` false: no frame has one
  Eigen::Vector3d lower = Eigen::Vector3d::Zero(), upper = Eigen::Vector3d::Zero();
  bool active = false;
  double voxel_size = 0;                      // m, the first frame's largest voxel edge
  double largest_speed = 0;                   // m/s, over every voxel of every frame read
  std::string layout;                         // "vec3s grid 'vel'" or "float grids 'vel.x', 'vel.y', 'vel.z'"
};

// Every frame the scene times [t0, t1] need => read whole and checked: it exists, is a VDB,
// holds the grid (vec3s, or three float grids NAME.x/.y/.z), every active value finite and at
// most max_speed m/s. Throws InputError naming the file, the grid and the voxel or time.
VolumeSummary check_wind_volume(const VolumeOptions& options, double t0, double t1, double max_speed);

// `treeanim --volume-trial` (volume_grids.h) => its exit code: the module's trial reads.
int serve_volume_trials();
// The running binary answers --volume-trial (the treeanim command line): each volume file is
// then read once by a process of its own before this one reads it (volume_grids.h).
void allow_volume_trials();

class WindVolume {
 public:
  explicit WindVolume(const VolumeOptions& options);
  ~WindVolume();
  WindVolume(const WindVolume&) = delete;
  WindVolume& operator=(const WindVolume&) = delete;

  const VolumeOptions& options() const { return options_; }
  // A point in the volume's own space (its units, its up axis) => where it is in the scene (m).
  Eigen::Vector3d to_scene_point(const Eigen::Vector3d& p) const { return to_scene_ * p + options_.translate; }
  // t => the frames around t, read when not in memory (the oldest beyond kVolumeFramesKept
  // dropped). Thread-safe; throws InputError when a frame cannot be read.
  VolumeInstant at(double t) const;
  // Frame, scene points (3 x N, m) => their velocities (3 x N, m/s) and whether each is inside
  // the frame's active voxels (an `edge` volume is inside everywhere). Parallel over points.
  void sample(const VolumeFrame& frame, const Eigen::Matrix3Xd& points, Eigen::Matrix3Xd& velocity,
              std::vector<uint8_t>& inside) const;
  // Frame, scene point => velocity (m/s); false outside the frame's active voxels.
  bool sample(const VolumeFrame& frame, const Eigen::Vector3d& point, Eigen::Vector3d& velocity) const;
  // The two frames' samples at a point => the mean wind there; the keyed mean fills a frame's
  // outside when `outside` is "keys", still air when "calm".
  Eigen::Vector3d blend(bool inside0, const Eigen::Vector3d& v0, bool inside1, const Eigen::Vector3d& v1,
                        double weight, const Eigen::Vector3d& keys_mean) const;
  // Instant, scene point, the keyed mean => the mean wind there (both frames sampled).
  Eigen::Vector3d mean(const VolumeInstant& instant, const Eigen::Vector3d& point,
                       const Eigen::Vector3d& keys_mean) const;

 private:
  VolumeOptions options_;
  Eigen::Matrix3d to_scene_;     // volume vector => scene vector: rotation, up axis and units
  Eigen::Matrix3d from_scene_;   // its inverse
  mutable std::mutex mutex_;     // guards frames_
  // The frames in memory, each with its file's path, the most recently used last.
  mutable std::vector<std::pair<std::string, std::shared_ptr<const VolumeFrame>>> frames_;
};

}  // namespace treeanim
