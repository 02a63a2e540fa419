// The OpenVDB reader module (sim/volume_grids.h): the only code that links OpenVDB, loaded by
// sim/wind_volume.cpp when a scene has a wind volume.
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>

#include <poll.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <string_view>
#include <utility>

#include "sim/volume_grids.h"

namespace treeanim {

namespace {

std::once_flag openvdb_initialised;

// The grid's type as messages name it.
std::string grid_type(const openvdb::GridBase& grid) { return grid.valueType(); }

// Grids of the file => "'a' (vec3s), 'b' (float)" for a message naming what is there.
std::string grid_list(openvdb::io::File& file) {
  std::string list;
  const openvdb::GridPtrVecPtr grids = file.readAllGridMetadata();
  for (const openvdb::GridBase::Ptr& grid : *grids)
    list += (list.empty() ? "'" : ", '") + grid->getName() + "' (" + grid_type(*grid) + ")";
  return list.empty() ? "none" : list;
}

// Index-space point => inside the box of active voxels (voxel centres at whole coordinates);
// `clamp`: moved onto the box first.
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

// A frame's velocity: one vec3s grid, or three float grids (Houdini's split vel.x/.y/.z, each
// with its own transform, as a staggered grid has), each with its active voxels' box.
class OpenVdbGrids final : public VolumeGrids {
 public:
  std::string name;                                    // the velocity grid's name
  openvdb::Vec3SGrid::ConstPtr vector;                 // null for split grids
  std::array<openvdb::FloatGrid::ConstPtr, 3> split;   // null for a vec3s grid
  std::array<openvdb::CoordBBox, 3> box;               // index space: the active voxels' box, per grid

  std::string layout() const override {
    return vector ? "vec3s grid '" + name + "'" : "float grids '" + name + ".x', '" + name + ".y', '" + name + ".z'";
  }

  std::string grid_of(int axis) const override {
    return vector ? "vec3s grid '" + name + "'" : "float grid '" + name + "." + "xyz"[axis] + "'";
  }

  double voxel_size() const override {
    const openvdb::Vec3d voxel = vector ? vector->voxelSize() : split[0]->voxelSize();
    return std::max({voxel[0], voxel[1], voxel[2]});
  }

  std::vector<Eigen::Vector3d> corners() const override {
    std::vector<Eigen::Vector3d> points;
    for (int k = 0; k < (vector ? 1 : 3); ++k) {
      const openvdb::GridBase& grid = vector ? static_cast<const openvdb::GridBase&>(*vector) : *split[k];
      if (box[k].empty()) continue;
      const openvdb::Coord &lo = box[k].min(), &hi = box[k].max();
      for (int corner = 0; corner < 8; ++corner) {
        const openvdb::Vec3d ijk((corner & 1 ? hi : lo).x(), (corner & 2 ? hi : lo).y(), (corner & 4 ? hi : lo).z());
        const openvdb::Vec3d p = grid.transform().indexToWorld(ijk);
        points.emplace_back(p[0], p[1], p[2]);
      }
    }
    return points;
  }

  void sample(const Eigen::Matrix3Xd& points, bool clamp, Eigen::Matrix3Xd& velocity,
              std::vector<uint8_t>& inside) const override {
    const Eigen::Index n = points.cols();
    velocity.resize(3, n);
    inside.resize(size_t(n));
#pragma omp parallel if (n >= 4096)
    {
      Accessors access(*this);
#pragma omp for schedule(static)
      for (Eigen::Index i = 0; i < n; ++i) {
        Eigen::Vector3d v = Eigen::Vector3d::Zero();
        inside[size_t(i)] = sample_at(access, points.col(i), clamp, v);
        velocity.col(i) = v;
      }
    }
  }

  bool sample(const Eigen::Vector3d& point, bool clamp, Eigen::Vector3d& velocity) const override {
    Accessors access(*this);
    return sample_at(access, point, clamp, velocity);
  }

  Eigen::Vector3d background() const override {
    if (vector) {
      const openvdb::Vec3s b = vector->background();
      return {b[0], b[1], b[2]};
    }
    return {split[0]->background(), split[1]->background(), split[2]->background()};
  }

  void visit_active(const VoxelVisit& visit) const override {
    auto coordinates = [](const openvdb::Coord& c) { return std::array<int, 3>{c.x(), c.y(), c.z()}; };
    if (vector) {
      for (auto it = vector->cbeginValueOn(); it; ++it) {
        const openvdb::Vec3s v = *it;
        const bool finite = std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
        // In double: a float's |v|^2 overflows from 1.8e19 m/s and would report inf.
        visit(name, coordinates(it.getCoord()), finite ? Eigen::Vector3d(v[0], v[1], v[2]).norm() : 0, finite);
      }
      return;
    }
    std::array<openvdb::FloatGrid::ConstAccessor, 3> access{split[0]->getConstAccessor(), split[1]->getConstAccessor(),
                                                           split[2]->getConstAccessor()};
    const char* axes[3] = {".x", ".y", ".z"};
    for (int k = 0; k < 3; ++k) {
      const std::string grid = name + axes[k];
      for (auto it = split[k]->cbeginValueOn(); it; ++it) {
        double squared = 0;
        bool finite = true;
        for (int j = 0; j < 3; ++j) {
          const float c = j == k ? *it : access[j].getValue(it.getCoord());
          finite = finite && std::isfinite(c);
          squared += double(c) * c;
        }
        visit(grid, coordinates(it.getCoord()), finite ? std::sqrt(squared) : 0, finite);
      }
    }
  }

 private:
  // Read accessors of one thread (an accessor caches its path through the tree).
  struct Accessors {
    explicit Accessors(const OpenVdbGrids& grids)
        : vector(grids.vector ? grids.vector->getConstAccessor() : empty_vector().getConstAccessor()),
          split{grids.split[0] ? grids.split[0]->getConstAccessor() : empty_float().getConstAccessor(),
                grids.split[1] ? grids.split[1]->getConstAccessor() : empty_float().getConstAccessor(),
                grids.split[2] ? grids.split[2]->getConstAccessor() : empty_float().getConstAccessor()} {}
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

  // A point in the volume's space => its velocity in volume units; false outside the active
  // voxels (unless clamped to them).
  bool sample_at(Accessors& access, const Eigen::Vector3d& point, bool clamp, Eigen::Vector3d& velocity) const {
    const openvdb::Vec3d p(point.x(), point.y(), point.z());
    openvdb::Vec3d v;
    if (vector) {
      openvdb::Vec3d ijk = vector->worldToIndex(p);
      if (!inside_box(box[0], ijk, clamp)) return false;
      v = openvdb::tools::BoxSampler::sample(access.vector, ijk);
    } else {
      for (int k = 0; k < 3; ++k) {
        openvdb::Vec3d ijk = split[k]->worldToIndex(p);
        if (!inside_box(box[k], ijk, clamp)) return false;
        v[k] = openvdb::tools::BoxSampler::sample(access.split[k], ijk);
      }
    }
    velocity = Eigen::Vector3d(v[0], v[1], v[2]);
    return true;
  }
};

// A grid's inactive values set to its background: what the sampler reads between the active
// voxels is then what docs/scene.md says, never a value a cache left there unchecked.
template <typename Grid>
void clear_inactive(Grid& grid) {
  const typename Grid::ValueType background = grid.background();
  for (auto it = grid.tree().beginValueOff(); it; ++it) it.setValue(background);
}

// The file's grids (their metadata, read once), `name` => whether one has that name; throws when
// several have (OpenVDB's own lookup picks one and prints a warning on stdout).
bool has_one_grid(const openvdb::GridPtrVec& grids, const std::string& name) {
  size_t count = 0;
  for (const openvdb::GridBase::Ptr& grid : grids) count += grid->getName() == name;
  if (count > 1)
    throw std::invalid_argument(std::to_string(count) + " grids are named '" + name +
                                "': which one is the velocity is not clear");
  return count == 1;
}

// The file's layout walked as OpenVDB's File::open reads it (header, file metadata, then each
// grid's descriptor and its end), every length and position checked against the file's size.
// OpenVDB reads a length at the cut of a truncated file into an uninitialised integer and
// allocates that much: a file cut inside its metadata made it take 20 GB before it failed.
class LayoutWalk {
 public:
  explicit LayoutWalk(const std::string& path) : in_(path, std::ios::binary), size_(std::filesystem::file_size(path)) {}

  void walk() {
    int64_t magic = 0;
    uint32_t version = 0;
    // Not a VDB file, or one OpenVDB no longer reads: its own message says so. A file that
    // begins as VDB's magic number and stops within the header (OpenVDB then finds no grids).
    if (size_ < 12) {
      const int64_t expected = openvdb::OPENVDB_MAGIC;
      char start[12] = {};
      in_.read(start, std::streamsize(size_));
      if (size_ > 0 && std::memcmp(start, &expected, std::min<size_t>(size_, sizeof expected)) == 0)
        throw std::runtime_error(past_limit("the header"));
      return;
    }
    read(magic, "the header"), read(version, "the header");
    if (magic != openvdb::OPENVDB_MAGIC || version < openvdb::OPENVDB_FILE_VERSION_FLOAT_FRUSTUM_BBOX) return;
    skip(8, "the header");  // the library's major and minor version
    char offsets = 0;
    read(offsets, "the header");
    // Versions 220 and 221 have a file-wide compression flag.
    if (version < openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION) skip(1, "the header");
    skip(36, "the header's UUID");
    metadata("the file's metadata");
    if (!offsets) return;  // a stream's grids follow one another unindexed: OpenVDB reads them in order
    int32_t grids = 0;
    read(grids, "the grid count");
    for (int32_t g = 0; g < grids; ++g) {
      const std::string what = "grid " + std::to_string(g + 1);
      for (int k = 0; k < 3; ++k) text(what + "'s descriptor");  // unique name, type, instance parent
      int64_t grid = 0, block = 0, end = 0;
      read(grid, what + "'s descriptor"), read(block, what + "'s descriptor"), read(end, what + "'s descriptor");
      if (grid < int64_t(at_) || block < grid || end < block)
        throw std::runtime_error(what + "'s descriptor places it outside its own bounds");
      // The grid's own metadata, read before its transform and tree, lies before its data
      // block: a flipped length there made OpenVDB read on past the file's end and take 16 GB.
      skip(uint64_t(grid) - at_, what + ", which begins at byte " + std::to_string(grid));
      within(uint64_t(block), "the grid's data, which begins at byte " + std::to_string(block), [&] {
        if (version >= openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION) skip(4, what + "'s compression flags");
        const uint64_t tree_bytes = limit_ - at_;
        metadata(what + "'s metadata", &tree_bytes);
      });
      skip(uint64_t(end) - at_, what + ", which ends at byte " + std::to_string(end));
    }
  }

 private:
  std::ifstream in_;
  uint64_t size_, at_ = 0;
  uint64_t limit_ = size_;  // where what is walked must end: the file's end, a grid's data block, a value's end
  std::string limit_name_;  // that end before the file's, as messages name it

  // `what` runs past the limit => why the file cannot be read.
  std::string past_limit(const std::string& what) const {
    if (limit_ < size_) return what + " runs past " + limit_name_;
    return "the file is cut short: it ends at byte " + std::to_string(size_) + ", inside " + what;
  }
  // Walks what `walk` reads with its end at byte `end`, named `name`.
  template <typename Walk>
  void within(uint64_t end, const std::string& name, Walk walk) {
    const uint64_t outer = std::exchange(limit_, std::min(end, limit_));
    std::string outer_name = std::exchange(limit_name_, name);
    walk();
    limit_ = outer, limit_name_ = std::move(outer_name);
  }
  void skip(uint64_t bytes, const std::string& what) {
    if (bytes > limit_ - at_) throw std::runtime_error(past_limit(what));
    at_ += bytes;
    in_.seekg(std::streamoff(at_));
  }
  void read_bytes(char* to, uint64_t bytes, const std::string& what) {
    if (bytes > limit_ - at_) throw std::runtime_error(past_limit(what));
    in_.read(to, std::streamsize(bytes));
    at_ += bytes;
  }
  template <typename T>
  void read(T& value, const std::string& what) {
    read_bytes(reinterpret_cast<char*>(&value), sizeof value, what);
  }
  void text(const std::string& what) {  // a length, then that many bytes
    uint32_t length = 0;
    read(length, what);
    skip(length, what);
  }
  // A count, then name, type and value of each item. In a grid's own metadata (`tree_bytes`:
  // the bytes before its data block, which hold its tree), a delayed-load table is checked inside.
  void metadata(const std::string& what, const uint64_t* tree_bytes = nullptr) {
    uint32_t count = 0;
    read(count, what);
    for (uint32_t k = 0; k < count; ++k) {
      text(what);
      uint32_t length = 0;
      read(length, what);
      std::string type(tree_bytes && length == kDelayedLoad.size() ? length : 0, '\0');
      if (type.empty()) skip(length, what);
      else read_bytes(type.data(), length, what);
      if (type == kDelayedLoad)
        delayed_load(what, *tree_bytes);
      else
        text(what);
    }
  }

  // OpenVDB's table of which leaf nodes a grid may load later (io::DelayedLoadMetadata): a
  // count of leaves, their masks and their compressed sizes, each raw or as a Blosc buffer.
  // OpenVDB sizes its arrays by that count and by the sizes the Blosc headers give, and reads
  // on whatever they say: a flipped bit in them took it to 6.7 GB.
  static constexpr std::string_view kDelayedLoad = "__delayedload";
  void delayed_load(const std::string& what, uint64_t tree_bytes) {
    uint32_t length = 0;
    read(length, what);
    if (length == 0) return;
    const std::string table = what + "'s delayed-load table";
    const uint64_t end = at_ + length;
    if (end > limit_) throw std::runtime_error(past_limit(table));
    within(end, "the table's " + std::to_string(length) + " bytes", [&] { delayed_load_table(table, tree_bytes); });
    skip(end - at_, table);
  }
  void delayed_load_table(const std::string& table, uint64_t tree_bytes) {
    uint32_t count = 0, bytes = 0;
    read(count, table), read(bytes, table);
    // Each leaf node's value mask takes 64 bytes of the tree (its origin follows from its place).
    if (count > tree_bytes / 64)
      throw std::runtime_error(table + " counts " + std::to_string(count) + " leaf nodes, more than the grid's " +
                               std::to_string(tree_bytes) + " bytes of tree can hold");
    auto array = [&](uint32_t compressed, uint64_t element, const std::string& part) {
      if (compressed == 0) return skip(count * element, part);
      // Blosc's header: its uncompressed size at byte 4, its compressed size at byte 12.
      uint32_t header[4] = {};
      if (compressed < sizeof header) throw std::runtime_error(part + " is shorter than a Blosc header");
      read(header, part);
      // OpenVDB pads an array of 48 to 127 bytes by 128 before it compresses it.
      if (header[1] < count * element || header[1] > count * element + 128 || header[3] > compressed)
        throw std::runtime_error(part + " does not hold the " + std::to_string(count) + " values its count says");
      skip(compressed - sizeof header, part);
    };
    array(bytes, sizeof(int8_t), table + " (its masks)");
    read(bytes, table);
    if (bytes != std::numeric_limits<uint32_t>::max()) array(bytes, sizeof(int64_t), table + " (its sizes)");
  }
};

// Frame file, grid name => its grids read whole (OpenVDB initialised); throws
// std::runtime_error with what is wrong.
std::unique_ptr<OpenVdbGrids> read_grids(const std::string& path, const std::string& name) {
  auto frame = std::make_unique<OpenVdbGrids>();
  frame->name = name;
  LayoutWalk(path).walk();
  openvdb::io::File file(path);
  file.open(false);
  const openvdb::GridPtrVecPtr grids = file.readAllGridMetadata();
  if (has_one_grid(*grids, name)) {
    openvdb::GridBase::Ptr grid = file.readGrid(name);
    const openvdb::Vec3SGrid::Ptr vector = openvdb::GridBase::grid<openvdb::Vec3SGrid>(grid);
    if (!vector)
      throw std::invalid_argument("grid '" + name + "' holds " + grid_type(*grid) +
                                  " values; a velocity is a vec3s grid, or the float grids '" + name + ".x', '" +
                                  name + ".y', '" + name + ".z'");
    clear_inactive(*vector);
    frame->vector = vector;
    frame->box[0] = frame->vector->evalActiveVoxelBoundingBox();
  } else {
    const char* axes[3] = {".x", ".y", ".z"};
    for (int k = 0; k < 3; ++k) {
      const std::string component = name + axes[k];
      if (!has_one_grid(*grids, component))
        throw std::invalid_argument("no grid '" + name + "' (nor '" + name + ".x', '" + name + ".y', '" + name +
                                    ".z'); its grids: " + grid_list(file));
      openvdb::GridBase::Ptr grid = file.readGrid(component);
      const openvdb::FloatGrid::Ptr split = openvdb::GridBase::grid<openvdb::FloatGrid>(grid);
      if (!split)
        throw std::invalid_argument("grid '" + component + "' holds " + grid_type(*grid) +
                                    " values; a velocity component is a float grid");
      clear_inactive(*split);
      frame->split[k] = split;
      frame->box[k] = frame->split[k]->evalActiveVoxelBoundingBox();
    }
  }
  file.close();
  return frame;
}

// Frame file, grid name => its grids, or null with what is wrong with the file or the grid.
std::unique_ptr<OpenVdbGrids> try_read(const std::string& path, const std::string& name, std::string& error) {
  try {
    return read_grids(path, name);
  } catch (const std::invalid_argument& e) {
    error = e.what();
  } catch (const std::exception& e) {  // openvdb::Exception, and the streams' failures on a truncated file
    error = std::string("not a readable VDB file (") + e.what() + ")";
  }
  return nullptr;
}

// The memory a trial read may take beyond what the process holds: a grid expands its
// compressed file many times over.
constexpr uint64_t kTrialBytes = uint64_t(2) << 30, kTrialFileTimes = 64;

// A message or a request over the trial's socket: a length, then that many bytes. => false when
// the other end is gone. MSG_NOSIGNAL: a trial process that died is an answer, not a SIGPIPE.
bool send_text(int socket, const std::string& text) {
  const uint32_t length = uint32_t(text.size());
  std::string bytes(reinterpret_cast<const char*>(&length), sizeof length);
  bytes += text;
  for (size_t done = 0; done < bytes.size();) {
    const ssize_t n = send(socket, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += size_t(n);
  }
  return true;
}

// Reads `size` bytes into `to` by `deadline` (none: wait) => false at the end of the stream, an
// error or the deadline (`late` set).
bool receive(int socket, char* to, size_t size, const std::chrono::steady_clock::time_point* deadline, bool& late) {
  for (size_t done = 0; done < size;) {
    if (deadline) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(*deadline - std::chrono::steady_clock::now());
      pollfd ready = {socket, POLLIN, 0};
      const int polled = poll(&ready, 1, int(std::max<int64_t>(left.count(), 0)));
      if (polled < 0 && errno == EINTR) continue;
      if (polled == 0) late = true;
      if (polled <= 0) return false;
    }
    const ssize_t n = read(socket, to + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += size_t(n);
  }
  return true;
}
bool receive_text(int socket, std::string& text, const std::chrono::steady_clock::time_point* deadline, bool& late) {
  uint32_t length = 0;
  if (!receive(socket, reinterpret_cast<char*>(&length), sizeof length, deadline, late)) return false;
  text.resize(length);
  return receive(socket, text.data(), length, deadline, late);
}

// OpenVDB's reader trusts the lengths inside a grid's tree and data: a raw chunk longer than
// its node is read over the heap past the node's buffer (a flipped bit in a leaf's length did
// that, and malloc aborted), and counts size what it allocates. So each file is first read by
// a process of its own, `treeanim --volume-trial` (spawned anew, not forked: a fork of this
// process, threads and all, could wait for ever on a lock another thread held), which reads
// file after file until one fails or this process ends; a file is read here only when that
// read came through.
class TrialReader {
 public:
  ~TrialReader() { stop(false); }
  // => nothing, or what is wrong with the file.
  std::string read_file(const char* program, const std::string& path, const std::string& name) {
    const uint64_t file_bytes = std::filesystem::file_size(path);
    if (child_ < 0 && !start(program)) return "";  // no trial process: the read in this one is the only one
    // A trial that neither ends nor answers within a minute and a second per MB is stopped.
    const int seconds = int(std::min<uint64_t>(60 + (file_bytes >> 20), 3600));
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
    std::string error;
    bool late = false;
    if (send_text(socket_, path) && send_text(socket_, name) && receive_text(socket_, error, &deadline, late))
      return error;
    const int status = stop(late);
    if (late)
      return "not a readable VDB file (OpenVDB's reader was still reading it after " + std::to_string(seconds) + " s)";
    if (WIFSIGNALED(status))
      return "not a readable VDB file (OpenVDB's reader failed on it with signal " + std::to_string(WTERMSIG(status)) +
             " (" + strsignal(WTERMSIG(status)) + "): the file is damaged)";
    return "not a readable VDB file (reading it failed without a message: it may have needed more than the " +
           std::to_string((kTrialBytes + kTrialFileTimes * file_bytes) >> 30) + " GiB a trial read may take)";
  }

 private:
  pid_t child_ = -1;
  int socket_ = -1;

  bool start(const char* program) {
    int ends[2];
    if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, ends) != 0) return false;
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, ends[1], STDIN_FILENO);
    posix_spawn_file_actions_adddup2(&actions, ends[1], STDOUT_FILENO);
    std::string binary = program, argument = kVolumeTrialArgument;
    char* arguments[] = {binary.data(), argument.data(), nullptr};
    const int spawned = posix_spawn(&child_, program, &actions, nullptr, arguments, environ);
    posix_spawn_file_actions_destroy(&actions);
    close(ends[1]);
    if (spawned != 0) {
      close(ends[0]);
      child_ = -1;
      return false;
    }
    socket_ = ends[0];
    return true;
  }
  // The trial process ended (`kill`: killed first) => its wait status.
  int stop(bool kill_it) {
    if (child_ < 0) return 0;
    if (kill_it) kill(child_, SIGKILL);
    close(socket_);  // a trial process waiting for the next file ends
    int status = 0;
    while (waitpid(child_, &status, 0) < 0 && errno == EINTR) {
    }
    child_ = -1, socket_ = -1;
    return status;
  }
};

// Files that came through a trial read, with their size and time then: each is tried once.
std::mutex tried_mutex;
std::map<std::string, std::pair<uintmax_t, std::filesystem::file_time_type>> tried;
TrialReader trial_reader;

}  // namespace

}  // namespace treeanim

// The entry points (sim/volume_grids.h): no exception leaves the module.
extern "C" __attribute__((visibility("default"))) treeanim::VolumeGrids* treeanim_read_volume_grids(
    const std::string& path, const std::string& grid, const char* trial_program, std::string& error) {
  using namespace treeanim;
  try {
    std::call_once(openvdb_initialised, [] { openvdb::initialize(); });
    const auto stamp = std::make_pair(std::filesystem::file_size(path), std::filesystem::last_write_time(path));
    std::lock_guard lock(tried_mutex);
    if (auto it = tried.find(path); trial_program && (it == tried.end() || it->second != stamp)) {
      error = trial_reader.read_file(trial_program, path, grid);
      if (!error.empty()) return nullptr;
      tried[path] = stamp;
    }
  } catch (const std::exception& e) {  // the file's size or time could not be read
    error = std::string("not a readable VDB file (") + e.what() + ")";
    return nullptr;
  }
  return try_read(path, grid, error).release();
}

extern "C" __attribute__((visibility("default"))) int treeanim_trial_serve_volumes() {
  using namespace treeanim;
  openvdb::initialize();
  // File after file from the socket on stdin, each answered on stdout: nothing, or what is wrong.
  for (std::string path, grid;;) {
    bool late = false;
    if (!receive_text(STDIN_FILENO, path, nullptr, late) || !receive_text(STDIN_FILENO, grid, nullptr, late)) return 0;
    std::string error;
    try {
      // The cap is on address space, above what the process holds now (terabytes with
      // AddressSanitizer's shadow): the soft limit, raised or lowered for each file.
      unsigned long long pages = 0;
      if (FILE* statm = std::fopen("/proc/self/statm", "r")) {
        if (std::fscanf(statm, "%llu", &pages) != 1) pages = 0;
        std::fclose(statm);
      }
      rlimit limit = {};
      if (pages > 0 && getrlimit(RLIMIT_AS, &limit) == 0) {
        limit.rlim_cur = std::min<rlim_t>(limit.rlim_max, pages * uint64_t(sysconf(_SC_PAGESIZE)) + kTrialBytes +
                                                              kTrialFileTimes * std::filesystem::file_size(path));
        setrlimit(RLIMIT_AS, &limit);
      }
      try_read(path, grid, error);
    } catch (const std::exception& e) {  // the file's size, or the message's own allocation under the cap
      error = std::string("not a readable VDB file (") + e.what() + ")";
    }
    if (!send_text(STDOUT_FILENO, error)) return 0;
  }
}
