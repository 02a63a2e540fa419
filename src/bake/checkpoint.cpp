// Checkpoint files (docs/checkpoint.md): root attributes name the format, version, bake and
// frame; /state holds every array of the SimState.
#include "bake/checkpoint.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <system_error>

#include "bake/scene_hash.h"
#include "common/errors.h"
#include "common/input_files.h"
#include "files/io_failure.h"
#include "files/staged_files.h"
#include "formats/hdf5_support.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

constexpr const char* kFormat = "treeanim-checkpoint";
// 2: the prediction keeps its goal offsets; 3: and its damping terms; 4: the state's digest.
constexpr int32_t kFormatVersion = 4;

// A variable-length UTF-8 string type, or -1.
hid_t make_string_type() {
  const hid_t type = H5Tcopy(H5T_C_S1);
  if (type < 0 || H5Tset_size(type, H5T_VARIABLE) < 0 || H5Tset_cset(type, H5T_CSET_UTF8) < 0) return -1;
  return type;
}

// HDF5 calls on one checkpoint file; every failure names the file and what failed.
class CheckpointFile {
 public:
  CheckpointFile(fs::path path, bool reading) : path_(std::move(path)), reading_(reading) {}

  [[noreturn]] void fail(const std::string& what) const {
    const std::string detail = hdf5_error_text();
    const std::string message = path_.string() + ": " + (reading_ ? "not a readable checkpoint: cannot " : "HDF5 could not ") +
                                what + (detail.empty() ? "" : " (" + detail + ")");
    if (reading_) throw InputError(message);
    throw OutputError(message);
  }
  hid_t check(hid_t id, const std::string& what) const {
    if (id < 0) fail(what);
    return id;
  }

  // --- writing ---
  void attribute(hid_t where, const char* name, hid_t file_type, hid_t memory_type, const void* value) const {
    Handle space(check(H5Screate(H5S_SCALAR), "make a scalar space"), H5Sclose);
    Handle attribute(check(H5Acreate2(where, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                           std::string("create attribute ") + name),
                     H5Aclose);
    check(H5Awrite(attribute.get(), memory_type, value), std::string("write attribute ") + name);
  }
  void string_attribute(hid_t where, const char* name, const std::string& value) const {
    Handle type(check(make_string_type(), "make a string type"), H5Tclose);
    const char* text = value.c_str();
    attribute(where, name, type.get(), type.get(), &text);
  }
  void array(hid_t group, const char* name, hid_t file_type, hid_t memory_type, std::vector<hsize_t> dims,
             const void* data) const {
    Handle space(check(H5Screate_simple(int(dims.size()), dims.data(), nullptr), std::string("make a space for ") + name),
                 H5Sclose);
    Handle dataset(check(H5Dcreate2(group, name, file_type, space.get(), H5P_DEFAULT,
                                    untimed_creation(H5P_DATASET_CREATE).get(), H5P_DEFAULT),
                         std::string("create /state/") + name),
                   H5Dclose);
    hsize_t total = 1;
    for (hsize_t d : dims) total *= d;
    if (total > 0)
      check(H5Dwrite(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), std::string("write /state/") + name);
    digest_ = fnv1a64(digest_, data, total * H5Tget_size(memory_type));
  }

  // --- reading ---
  std::string read_string_attribute(hid_t where, const char* name) const {
    Handle attribute(check(H5Aopen(where, name, H5P_DEFAULT), std::string("open attribute ") + name), H5Aclose);
    Handle type(check(make_string_type(), "make a string type"), H5Tclose);
    Handle stored(check(H5Aget_type(attribute.get()), std::string("read attribute ") + name), H5Tclose);
    if (H5Tget_class(stored.get()) != H5T_STRING || H5Tis_variable_str(stored.get()) <= 0)
      fail(std::string("read attribute ") + name + " as a string");
    char* text = nullptr;
    check(H5Aread(attribute.get(), type.get(), &text), std::string("read attribute ") + name);
    std::string value = text ? text : "";
    H5free_memory(text);
    return value;
  }
  template <typename T>
  T read_attribute(hid_t where, const char* name, hid_t memory_type) const {
    Handle attribute(check(H5Aopen(where, name, H5P_DEFAULT), std::string("open attribute ") + name), H5Aclose);
    T value{};
    check(H5Aread(attribute.get(), memory_type, &value), std::string("read attribute ") + name);
    return value;
  }
  // /state/<name> of exactly `dims` => `data`.
  void read_array(hid_t group, const char* name, hid_t memory_type, std::vector<hsize_t> dims, void* data) const {
    Handle dataset(check(H5Dopen2(group, name, H5P_DEFAULT), std::string("open /state/") + name), H5Dclose);
    Handle space(check(H5Dget_space(dataset.get()), std::string("read the shape of /state/") + name), H5Sclose);
    std::vector<hsize_t> stored(dims.size());
    if (H5Sget_simple_extent_ndims(space.get()) != int(dims.size()) ||
        H5Sget_simple_extent_dims(space.get(), stored.data(), nullptr) < 0 || stored != dims) {
      std::string expected;
      for (hsize_t d : dims) expected += (expected.empty() ? "" : " x ") + std::to_string(d);
      throw InputError(path_.string() + ": /state/" + name + " does not have the shape of this scene's tree (" +
                       expected + "): the checkpoint belongs to another tree");
    }
    hsize_t total = 1;
    for (hsize_t d : dims) total *= d;
    if (total > 0)
      check(H5Dread(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), std::string("read /state/") + name);
    digest_ = fnv1a64(digest_, data, total * H5Tget_size(memory_type));
  }

  // The digest of every array written or read so far and of the values folded in, in order
  // (the file's state_digest).
  uint64_t digest() const { return digest_; }
  void fold(const void* data, size_t bytes) const { digest_ = fnv1a64(digest_, data, bytes); }

 private:
  fs::path path_;
  bool reading_;
  mutable uint64_t digest_ = kFnv1aStart;
};

// fsync of a file or folder; false when it failed.
bool sync_path(const fs::path& path, bool folder) {
  const int fd = ::open(path.c_str(), folder ? O_RDONLY | O_DIRECTORY : O_RDONLY);
  if (fd < 0) return false;
  const bool ok = ::fsync(fd) == 0;
  ::close(fd);
  return ok;
}

template <typename Real>
void write_prediction(const CheckpointFile& file, hid_t group, const StepPrediction<Real>& p, hid_t file_type,
                      hid_t memory_type) {
  // Rows3 is (n x 3) column-major: the x column, then y, then z => dims [3, n].
  file.array(group, "prediction_offset", file_type, memory_type, {3, hsize_t(p.offset.rows())}, p.offset.data());
  file.array(group, "prediction_velocity", file_type, memory_type, {3, hsize_t(p.velocity.rows())}, p.velocity.data());
  file.array(group, "prediction_drag_force", file_type, memory_type, {3, hsize_t(p.drag_force.rows())},
             p.drag_force.data());
  file.array(group, "prediction_goal", file_type, memory_type, {3, hsize_t(p.goal.rows())}, p.goal.data());
  file.array(group, "prediction_damping_offset", file_type, memory_type, {3, hsize_t(p.damping_offset.rows())},
             p.damping_offset.data());
  file.array(group, "prediction_damping_compliance", file_type, memory_type, {hsize_t(p.damping_compliance.rows())},
             p.damping_compliance.data());
}

template <typename Real>
void read_prediction(const CheckpointFile& file, hid_t group, const StepPrediction<Real>& shape,
                     StepPrediction<Real>& p, hid_t memory_type) {
  p.offset.resize(shape.offset.rows(), 3);
  p.velocity.resize(shape.velocity.rows(), 3);
  p.drag_force.resize(shape.drag_force.rows(), 3);
  p.goal.resize(shape.goal.rows(), 3);
  p.damping_offset.resize(shape.damping_offset.rows(), 3);
  p.damping_compliance.resize(shape.damping_compliance.rows());
  file.read_array(group, "prediction_offset", memory_type, {3, hsize_t(p.offset.rows())}, p.offset.data());
  file.read_array(group, "prediction_velocity", memory_type, {3, hsize_t(p.velocity.rows())}, p.velocity.data());
  file.read_array(group, "prediction_drag_force", memory_type, {3, hsize_t(p.drag_force.rows())}, p.drag_force.data());
  file.read_array(group, "prediction_goal", memory_type, {3, hsize_t(p.goal.rows())}, p.goal.data());
  file.read_array(group, "prediction_damping_offset", memory_type, {3, hsize_t(p.damping_offset.rows())},
                  p.damping_offset.data());
  file.read_array(group, "prediction_damping_compliance", memory_type, {hsize_t(p.damping_compliance.rows())},
                  p.damping_compliance.data());
}

// A file's name => whether a bake takes it for one of its own in its checkpoints' folder: a
// checkpoint, a frame journal or the temporary of either.
bool bake_file_name(const std::string& name) {
  auto between = [&](const std::string& prefix, const std::string& suffix) {
    return name.size() > prefix.size() + suffix.size() && name.starts_with(prefix) && name.ends_with(suffix);
  };
  return between("checkpoint-", ".h5") || between("frames-from-", ".journal") ||
         ((name.starts_with(".checkpoint-") || name.starts_with(".frames-from-")) && name.find(".tmp-") != std::string::npos);
}

}  // namespace

double estimated_checkpoint_bytes(size_t vertices, size_t clusters, size_t leaves) {
  constexpr double kVertexBytes = 8 * 3 * 8;  // 8 arrays of (V x 3) doubles
  constexpr double kClusterBytes = 8 * 8;     // rotation, shift and a damping term
  constexpr double kLayoutBytes = 64 * 1024;  // HDF5's superblock, groups and attributes
  return kVertexBytes * double(vertices) + kClusterBytes * double(clusters) + 2 * double(leaves) + kLayoutBytes;
}

fs::path checkpoint_path(const fs::path& dir, long long frame) {
  return dir / ("checkpoint-" + std::to_string(frame) + ".h5");
}

void check_checkpoint_folder(const fs::path& dir) {
  std::error_code error;
  for (fs::directory_iterator entry(dir, error), end; !error && entry != end; entry.increment(error)) {
    if (!bake_file_name(entry->path().filename().string())) continue;
    if (const std::string input = input_file_at(entry->path()); !input.empty())
      throw InputError(entry->path().string() + " is " + (input == entry->path().string() ? "" : input + ", ") +
                       "an input of this bake, in the checkpoints' folder under a name the bake replaces and "
                       "removes as its own; expected another name for it, or another --checkpoint-dir");
  }
}

void remove_spent_checkpoints(const fs::path& dir) noexcept {
  std::error_code error;
  if (!fs::is_directory(fs::symlink_status(dir, error))) return;
  std::vector<fs::path> removed;
  for (fs::directory_iterator entry(dir, error), end; !error && entry != end; entry.increment(error))
    if (bake_file_name(entry->path().filename().string()) && entry->is_regular_file(error))
      removed.push_back(entry->path());
  for (const fs::path& path : removed) fs::remove(path, error);
  ::rmdir(dir.c_str());  // fails, harmlessly, on a folder that holds anything else
}

std::vector<std::pair<long long, fs::path>> list_checkpoints(const fs::path& dir) {
  std::vector<std::pair<long long, fs::path>> found;
  std::error_code error;
  if (!fs::is_directory(dir, error)) return found;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir, error)) {
    const std::string name = entry.path().filename().string();
    const std::string prefix = "checkpoint-", suffix = ".h5";
    if (name.size() <= prefix.size() + suffix.size() || name.compare(0, prefix.size(), prefix) != 0 ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    const std::string number = name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
    size_t used = 0;
    long long frame = 0;
    try {
      frame = std::stoll(number, &used);
    } catch (const std::logic_error&) {
      continue;
    }
    if (used == number.size() && checkpoint_path(dir, frame).filename() == name) found.emplace_back(frame, entry.path());
  }
  std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  return found;
}

void write_checkpoint(const fs::path& path, const SimState& state, long long frame, const CheckpointKey& key) {
  std::error_code error;
  fs::create_directories(path.parent_path(), error);
  if (error) throw OutputError(path.string() + ": cannot create the folder: " + error.message());
  const fs::path temporary = temporary_path(path);
  try {
    const auto lock = hdf5_lock();
    const CheckpointFile file(path, false);
    Handle handle(file.check(H5Fcreate(temporary.c_str(), H5F_ACC_TRUNC, untimed_creation(H5P_FILE_CREATE).get(),
                                       H5P_DEFAULT), "create the file"),
                  H5Fclose);
    const hid_t root = handle.get();
    const int64_t frame_index = frame;
    const uint8_t predicted = state.predicted ? 1 : 0;
    file.string_attribute(root, "format", kFormat);
    file.attribute(root, "format_version", H5T_STD_I32LE, H5T_NATIVE_INT32, &kFormatVersion);
    file.string_attribute(root, "generator", key.generator);
    file.string_attribute(root, "scene_hash", key.scene_hash);
    file.attribute(root, "frame", H5T_STD_I64LE, H5T_NATIVE_INT64, &frame_index);
    file.attribute(root, "time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &state.time);
    file.string_attribute(root, "precision", key.float_precision ? "float" : "double");
    file.attribute(root, "predicted", H5T_STD_U8LE, H5T_NATIVE_UINT8, &predicted);
    file.fold(&frame_index, sizeof frame_index), file.fold(&state.time, sizeof state.time);
    file.fold(&predicted, sizeof predicted);
    Handle group(file.check(H5Gcreate2(root, "/state", H5P_DEFAULT, untimed_creation(H5P_GROUP_CREATE).get(), H5P_DEFAULT),
                            "create /state"), H5Gclose);
    const hid_t g = group.get();
    const hsize_t V = state.positions.cols(), C = state.cluster_rotations.cols();
    file.array(g, "positions", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {V, 3}, state.positions.data());
    file.array(g, "velocities", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {V, 3}, state.velocities.data());
    file.array(g, "cluster_rotations", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {C, 4}, state.cluster_rotations.data());
    file.array(g, "cluster_shift", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {hsize_t(state.cluster_shift.cols()), 3},
               state.cluster_shift.data());
    file.array(g, "leaf_attached", H5T_STD_U8LE, H5T_NATIVE_UINT8, {state.leaf_attached.size()},
               state.leaf_attached.data());
    file.array(g, "island_asleep", H5T_STD_U8LE, H5T_NATIVE_UINT8, {state.island_asleep.size()},
               state.island_asleep.data());
    if (key.float_precision)
      write_prediction(file, g, state.prediction_float, H5T_IEEE_F32LE, H5T_NATIVE_FLOAT);
    else
      write_prediction(file, g, state.prediction_double, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE);
    group.reset();
    const uint64_t digest = file.digest();
    file.attribute(root, "state_digest", H5T_STD_U64LE, H5T_NATIVE_UINT64, &digest);
    if (!handle.reset()) file.fail("close the file");
  } catch (...) {
    fs::remove(temporary, error);
    throw;
  }
  // On disk before the name: a checkpoint with its final name is whole even after a crash.
  if (!sync_path(temporary, false)) {
    fs::remove(temporary, error);
    throw OutputError(io_failure(path, "cannot flush the checkpoint"));
  }
  fs::rename(temporary, path, error);
  if (error) {
    fs::remove(temporary, error);
    throw OutputError(path.string() + ": cannot rename the finished checkpoint into place: " + error.message());
  }
  sync_path(path.parent_path().empty() ? fs::path(".") : path.parent_path(), true);
}

std::pair<long long, SimState> read_checkpoint(const fs::path& path, const CheckpointKey& key, const SimState& shape) {
  const auto lock = hdf5_lock();
  const CheckpointFile file(path, true);
  // A FIFO or a device would block the open, or read for ever.
  if (std::error_code error; !fs::is_regular_file(path, error))
    throw InputError(path.string() + ": not a readable checkpoint: not a regular file");
  if (H5Fis_hdf5(path.c_str()) <= 0) {
    H5Eclear2(H5E_DEFAULT);
    throw InputError(path.string() + ": not a readable checkpoint: not an HDF5 file (damaged, or not written by treeanim)");
  }
  Handle handle(file.check(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), "open the file"), H5Fclose);
  const hid_t root = handle.get();
  const std::string format = file.read_string_attribute(root, "format");
  if (format != kFormat) throw InputError(path.string() + ": format '" + format + "' is not '" + kFormat + "'");
  const int32_t version = file.read_attribute<int32_t>(root, "format_version", H5T_NATIVE_INT32);
  if (version != kFormatVersion)
    throw InputError(path.string() + ": checkpoint format_version " + std::to_string(version) + ", this treeanim reads " +
                     std::to_string(kFormatVersion));
  const std::string generator = file.read_string_attribute(root, "generator");
  const std::string hash = file.read_string_attribute(root, "scene_hash");
  if (hash != key.scene_hash || generator != key.generator)
    throw InputError(path.string() + ": written for another scene or treeanim version (scene hash " + hash + ", " +
                     generator + "); this bake is " + key.scene_hash + ", " + key.generator +
                     ". Remove the checkpoints of the old bake or give --checkpoint-dir");
  const std::string precision = file.read_string_attribute(root, "precision");
  if (precision != (key.float_precision ? "float" : "double"))
    throw InputError(path.string() + ": a checkpoint in precision '" + precision + "' for a bake in the other one");
  SimState state = shape;
  const long long frame = file.read_attribute<int64_t>(root, "frame", H5T_NATIVE_INT64);
  state.time = file.read_attribute<double>(root, "time", H5T_NATIVE_DOUBLE);
  const uint8_t predicted = file.read_attribute<uint8_t>(root, "predicted", H5T_NATIVE_UINT8);
  state.predicted = predicted != 0;
  const int64_t frame_index = frame;
  file.fold(&frame_index, sizeof frame_index), file.fold(&state.time, sizeof state.time);
  file.fold(&predicted, sizeof predicted);
  Handle group(file.check(H5Gopen2(root, "/state", H5P_DEFAULT), "open /state"), H5Gclose);
  const hid_t g = group.get();
  const hsize_t V = shape.positions.cols(), C = shape.cluster_rotations.cols();
  file.read_array(g, "positions", H5T_NATIVE_DOUBLE, {V, 3}, state.positions.data());
  file.read_array(g, "velocities", H5T_NATIVE_DOUBLE, {V, 3}, state.velocities.data());
  file.read_array(g, "cluster_rotations", H5T_NATIVE_DOUBLE, {C, 4}, state.cluster_rotations.data());
  state.cluster_shift.resize(3, C);
  file.read_array(g, "cluster_shift", H5T_NATIVE_DOUBLE, {C, 3}, state.cluster_shift.data());
  file.read_array(g, "leaf_attached", H5T_NATIVE_UINT8, {state.leaf_attached.size()}, state.leaf_attached.data());
  file.read_array(g, "island_asleep", H5T_NATIVE_UINT8, {state.island_asleep.size()}, state.island_asleep.data());
  if (key.float_precision)
    read_prediction(file, g, shape.prediction_float, state.prediction_float, H5T_NATIVE_FLOAT);
  else
    read_prediction(file, g, shape.prediction_double, state.prediction_double, H5T_NATIVE_DOUBLE);
  const uint64_t digest = file.read_attribute<uint64_t>(root, "state_digest", H5T_NATIVE_UINT64);
  if (digest != file.digest())
    throw InputError(path.string() + ": not a readable checkpoint: its state does not match the digest it was "
                                     "written with (damaged on disk; delete it to resume from the one before)");
  if (!state.positions.allFinite() || !state.velocities.allFinite())
    throw InputError(path.string() + ": the state holds non-finite positions or velocities");
  return {frame, std::move(state)};
}

}  // namespace treeanim
