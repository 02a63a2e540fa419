#pragma once
// One frame's velocity grids, as the OpenVDB reader (src/vdb/) holds them. That reader is a module
// that treeanim loads, and OpenVDB with it, only when a scene blows a wind volume: linked into the
// binary, OpenVDB's 57 MB library cost every run some 29 MB of memory and most of its start-up
// (docs/design.md, "OpenVDB on demand").
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace treeanim {

class VolumeGrids {
 public:
  virtual ~VolumeGrids() = default;
  // "vec3s grid 'vel'" or "float grids 'vel.x', 'vel.y', 'vel.z'"
  virtual std::string layout() const = 0;
  // The grid that holds the velocity's axis (0 x, 1 y, 2 z): "vec3s grid 'vel'" or "float grid 'vel.y'".
  virtual std::string grid_of(int axis) const = 0;
  // The first grid's largest voxel edge, in the volume's units.
  virtual double voxel_size() const = 0;
  // The eight corners of each grid's box of active voxel centres, in the volume's space (none
  // for a grid without active voxels).
  virtual std::vector<Eigen::Vector3d> corners() const = 0;
  // Points in the volume's space (3 x N) => the velocity at each (volume units, trilinear over
  // the voxel centres) and whether it is inside the active voxels; `clamp` moves a point onto
  // their box first (the nearest voxel's value beyond the edge). Parallel over 4,096 points or more.
  virtual void sample(const Eigen::Matrix3Xd& points, bool clamp, Eigen::Matrix3Xd& velocity,
                      std::vector<uint8_t>& inside) const = 0;
  // The same for one point; false outside.
  virtual bool sample(const Eigen::Vector3d& point, bool clamp, Eigen::Vector3d& velocity) const = 0;
  // The value of every inactive voxel (volume units): the grids' background, per axis.
  virtual Eigen::Vector3d background() const = 0;
  // Every active voxel => visit(its grid's name, its index coordinates, its speed in volume units,
  // whether its velocity is finite). A split grid's speed is its components' at that voxel.
  using VoxelVisit = std::function<void(const std::string& grid, const std::array<int, 3>& ijk, double speed,
                                        bool finite)>;
  virtual void visit_active(const VoxelVisit& visit) const = 0;
};

// The module's entry point, found by this name: a frame file and its grid's name => its
// grids read whole (no delayed loading: a truncated file fails here, not in a step), or null
// with `error` set to what is wrong (a message that follows the file's path).
// With `trial_program` (the treeanim binary; null: no trial), the entry point first reads a file
// it has not read before in a process of its own, `trial_program --volume-trial` (OpenVDB's
// reader can overflow its heap on a damaged file), whose command line calls the module's trial
// entry: file after file from stdin, each read and let go with the process's address space
// capped, and what is wrong, or nothing, answered on stdout => exit 0 at the end of stdin.
using ReadVolumeGrids = VolumeGrids*(const std::string& path, const std::string& grid, const char* trial_program,
                                     std::string& error);
constexpr const char* kReadVolumeGrids = "treeanim_read_volume_grids";
using ServeVolumeTrials = int();
constexpr const char* kServeVolumeTrials = "treeanim_trial_serve_volumes";
constexpr const char* kVolumeTrialArgument = "--volume-trial";

}  // namespace treeanim
