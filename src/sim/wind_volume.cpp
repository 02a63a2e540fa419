#include "sim/wind_volume.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <sstream>

#include "common/errors.h"

namespace treeanim {

// A frame's velocity: one vec3s grid, or three float grids (Houdini's split vel.x/.y/.z, each
// with its own transform, as a staggered grid has), each with its active voxels' box.
struct VolumeFrame {
  openvdb::Vec3SGrid::ConstPtr vector;                 // null for split grids
  std::array<openvdb::FloatGrid::ConstPtr, 3> split;   // null for a vec3s grid
  std::array<openvdb::CoordBBox, 3> box;               // index space: the active voxels' box, per grid
};

namespace {

std::once_flag openvdb_initialised;

std::string number_text(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

// The grid's type as `info` and messages name it.
std::string grid_type(const openvdb::GridBase& grid) { return grid.valueType(); }

// Grids of the file => "'a' (vec3s), 'b' (float)" for a message naming what is there.
std::string grid_list(openvdb::io::File& file) {
  std::string list;
  const openvdb::GridPtrVecPtr grids = file.readAllGridMetadata();
  for (const openvdb::GridBase::Ptr& grid : *grids)
    list += (list.empty() ? "'" : ", '") + grid->getName() + "' (" + grid_type(*grid) + ")";
  return list.empty() ? "none" : list;
}

// Frame file => its velocity grids read whole (no delayed loading, so that a truncated file
// fails here, not in a step). Throws InputError naming the file and the grid.
VolumeFrame read_frame(const std::string& path, const std::string& name) {
  std::call_once(openvdb_initialised, [] { openvdb::initialize(); });
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error))
    throw InputError(path + ": the volume frame is missing (no such file, or not a regular file)");
  VolumeFrame frame;
  try {
    openvdb::io::File file(path);
    file.open(false);
    if (file.hasGrid(name)) {
      openvdb::GridBase::Ptr grid = file.readGrid(name);
      frame.vector = openvdb::GridBase::grid<openvdb::Vec3SGrid>(grid);
      if (!frame.vector)
        throw InputError(path + ": grid '" + name + "' holds " + grid_type(*grid) +
                         " values; a velocity is a vec3s grid, or the float grids '" + name + ".x', '" + name +
                         ".y', '" + name + ".z'");
      frame.box[0] = frame.vector->evalActiveVoxelBoundingBox();
    } else {
      const char* axes[3] = {".x", ".y", ".z"};
      for (int k = 0; k < 3; ++k) {
        const std::string component = name + axes[k];
        if (!file.hasGrid(component))
          throw InputError(path + ": no grid '" + name + "' (nor '" + name + ".x', '" + name + ".y', '" + name +
                           ".z'); its grids: " + grid_list(file));
        openvdb::GridBase::Ptr grid = file.readGrid(component);
        frame.split[k] = openvdb::GridBase::grid<openvdb::FloatGrid>(grid);
        if (!frame.split[k])
          throw InputError(path + ": grid '" + component + "' holds " + grid_type(*grid) +
                           " values; a velocity component is a float grid");
        frame.box[k] = frame.split[k]->evalActiveVoxelBoundingBox();
      }
    }
    file.close();
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {  // openvdb::Exception, and the streams' failures on a truncated file
    throw InputError(path + ": not a readable VDB file (" + e.what() + ")");
  }
  return frame;
}

// Index-space point => inside the box of active voxels (voxel centres at whole coordinates);
// `clamp`: moved onto the box first (the nearest voxel's value beyond the edge).
bool inside_box(const openvdb::CoordBBox& box, openvdb::Vec3d& ijk, bool clamp) {
  if (box.empty()) return false;
  bool inside = true;
  for (int k = 0; k < 3; ++k) {
    const double lo = box.min()[k], hi = box.max()[k];
    if (ijk[k] < lo || ijk[k] > hi) {
      inside = false;
      if (clamp) ijk[k] = std::clamp(ijk[k], lo, hi);
    }
  }
  return inside || clamp;
}

// Read accessors of one thread (an accessor caches its path through the tree; one per thread).
struct FrameAccessors {
  explicit FrameAccessors(const VolumeFrame& frame)
      : vector(frame.vector ? frame.vector->getConstAccessor() : empty_vector().getConstAccessor()),
        split{frame.split[0] ? frame.split[0]->getConstAccessor() : empty_float().getConstAccessor(),
              frame.split[1] ? frame.split[1]->getConstAccessor() : empty_float().getConstAccessor(),
              frame.split[2] ? frame.split[2]->getConstAccessor() : empty_float().getConstAccessor()} {}
  static const openvdb::Vec3SGrid& empty_vector() {
    static const openvdb::Vec3SGrid::Ptr grid = openvdb::Vec3SGrid::create();
    return *grid;
  }
  static const openvdb::FloatGrid& empty_float() {
    static const openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create();
    return *grid;
  }
  openvdb::Vec3SGrid::ConstAccessor vector;
  std::array<openvdb::FloatGrid::ConstAccessor, 3> split;
};

// Frame, a point in the volume's own space => its velocity there in volume units (trilinear
// over the voxel centres); false outside the active voxels (unless clamped to them).
bool sample_volume_space(const VolumeFrame& frame, FrameAccessors& access, const openvdb::Vec3d& p, bool clamp,
                         openvdb::Vec3d& v) {
  if (frame.vector) {
    openvdb::Vec3d ijk = frame.vector->worldToIndex(p);
    if (!inside_box(frame.box[0], ijk, clamp)) return false;
    v = openvdb::tools::BoxSampler::sample(access.vector, ijk);
    return true;
  }
  for (int k = 0; k < 3; ++k) {
    openvdb::Vec3d ijk = frame.split[k]->worldToIndex(p);
    if (!inside_box(frame.box[k], ijk, clamp)) return false;
    v[k] = openvdb::tools::BoxSampler::sample(access.split[k], ijk);
  }
  return true;
}

// A file name with #### or %d is one file per frame; without, one file for all time.
bool has_frame_number(const std::filesystem::path& pattern) {
  const std::string name = pattern.filename().string();
  return name.find('#') != std::string::npos || name.find('%') != std::string::npos;
}

}  // namespace

std::string volume_frame_path(const std::filesystem::path& pattern, long long number) {
  const std::string text = pattern.filename().string();
  // #### is printf's %04d (a negative frame -001, as Houdini's $F4 writes it).
  size_t begin = text.find('#'), end = 0;
  int width = 0;
  if (begin != std::string::npos) {
    end = text.find_first_not_of('#', begin);
    if (end == std::string::npos) end = text.size();
    width = int(end - begin);
  } else if ((begin = text.find('%')) != std::string::npos) {
    end = text.find('d', begin) + 1;
    width = std::atoi(text.substr(begin + 1, end - begin - 2).c_str());
  } else {
    return pattern.string();
  }
  char digits[64];  // the scene reader allows a width of 18 at most
  std::snprintf(digits, sizeof digits, "%0*lld", width, number);
  return (pattern.parent_path() / (text.substr(0, begin) + digits + text.substr(end))).string();
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
  FrameAccessors access(frame);
  const Eigen::Vector3d p = from_scene_ * (point - options_.translate);
  openvdb::Vec3d v;
  const bool clamp = options_.outside == VolumeOutside::kEdge;
  if (!sample_volume_space(frame, access, openvdb::Vec3d(p.x(), p.y(), p.z()), clamp, v)) return false;
  velocity = to_scene_ * Eigen::Vector3d(v[0], v[1], v[2]);
  return true;
}

void WindVolume::sample(const VolumeFrame& frame, const Eigen::Matrix3Xd& points, Eigen::Matrix3Xd& velocity,
                        std::vector<uint8_t>& inside) const {
  const Eigen::Index n = points.cols();
  velocity.resize(3, n);
  inside.resize(size_t(n));
  const bool clamp = options_.outside == VolumeOutside::kEdge;
#pragma omp parallel if (n >= 4096)
  {
    FrameAccessors access(frame);
#pragma omp for schedule(static)
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Vector3d p = from_scene_ * (points.col(i) - options_.translate);
      openvdb::Vec3d v;
      const bool in = sample_volume_space(frame, access, openvdb::Vec3d(p.x(), p.y(), p.z()), clamp, v);
      inside[size_t(i)] = in;
      velocity.col(i) = in ? Eigen::Vector3d(to_scene_ * Eigen::Vector3d(v[0], v[1], v[2])) : Eigen::Vector3d::Zero();
    }
  }
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
  bool bounded = false;
  for (long long number = summary.first_frame; number <= summary.last_frame; ++number) {
    const std::string path = volume_frame_path(options.path, number);
    if (!std::filesystem::exists(path))
      throw InputError(path + ": the volume frame is missing, and the bake's times " + number_text(t0) + " s to " +
                       number_text(t1) + " s need frames " + std::to_string(summary.first_frame) + " to " +
                       std::to_string(summary.last_frame) + " (frame F blows at (F - " +
                       std::to_string(options.first_frame) + ") / " + number_text(options.fps) + " s)");
    const VolumeFrame frame = read_frame(path, options.grid);
    for (int k = 0; k < 3; ++k) {
      const openvdb::GridBase* grid =
          frame.vector ? static_cast<const openvdb::GridBase*>(frame.vector.get()) : frame.split[k].get();
      if (k == 0 || frame.split[k]) {
        if (frame.box[k].empty()) continue;
        for (int corner = 0; corner < 8; ++corner) {
          const openvdb::Coord& lo = frame.box[k].min();
          const openvdb::Coord& hi = frame.box[k].max();
          const openvdb::Vec3d ijk((corner & 1 ? hi : lo).x(), (corner & 2 ? hi : lo).y(), (corner & 4 ? hi : lo).z());
          const openvdb::Vec3d p = grid->transform().indexToWorld(ijk);
          const Eigen::Vector3d x = volume.to_scene_point(Eigen::Vector3d(p[0], p[1], p[2]));
          summary.lower = bounded ? Eigen::Vector3d(summary.lower.cwiseMin(x)) : x;
          summary.upper = bounded ? Eigen::Vector3d(summary.upper.cwiseMax(x)) : x;
          bounded = true;
        }
      }
      if (frame.vector) break;
    }
    if (number == summary.first_frame) {
      const openvdb::Vec3d voxel = frame.vector ? frame.vector->voxelSize() : frame.split[0]->voxelSize();
      summary.voxel_size = voxel.length() > 0 ? std::max({voxel[0], voxel[1], voxel[2]}) * options.units : 0;
      summary.layout = frame.vector ? "vec3s grid '" + options.grid + "'"
                                    : "float grids '" + options.grid + ".x', '" + options.grid + ".y', '" +
                                          options.grid + ".z'";
    }
    // Every active value: finite and within the wind's range, in m/s.
    auto check = [&](const std::string& grid_name, const openvdb::Coord& ijk, double speed, bool finite) {
      const std::string where = path + ": grid '" + grid_name + "', voxel (" + std::to_string(ijk.x()) + ", " +
                                std::to_string(ijk.y()) + ", " + std::to_string(ijk.z()) + ")";
      if (!finite) throw InputError(where + ": the velocity is not finite");
      if (speed > max_speed)
        throw InputError(where + ": a speed of " + number_text(speed) + " m/s, beyond the wind's " +
                         number_text(max_speed) + " m/s (is `units` right?)");
      summary.largest_speed = std::max(summary.largest_speed, speed);
    };
    if (frame.vector) {
      for (auto it = frame.vector->cbeginValueOn(); it; ++it) {
        const openvdb::Vec3s v = *it;
        const bool finite = std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
        check(options.grid, it.getCoord(), finite ? v.length() * options.units : 0, finite);
      }
    } else {
      // A split grid's speed per voxel is its components' at that voxel, read from the other grids.
      std::array<openvdb::FloatGrid::ConstAccessor, 3> access{frame.split[0]->getConstAccessor(),
                                                             frame.split[1]->getConstAccessor(),
                                                             frame.split[2]->getConstAccessor()};
      const char* axes[3] = {".x", ".y", ".z"};
      for (int k = 0; k < 3; ++k)
        for (auto it = frame.split[k]->cbeginValueOn(); it; ++it) {
          double squared = 0;
          bool finite = true;
          for (int j = 0; j < 3; ++j) {
            const float c = j == k ? *it : access[j].getValue(it.getCoord());
            finite = finite && std::isfinite(c);
            squared += double(c) * c;
          }
          check(options.grid + axes[k], it.getCoord(), finite ? std::sqrt(squared) * options.units : 0, finite);
        }
    }
  }
  return summary;
}

}  // namespace treeanim
