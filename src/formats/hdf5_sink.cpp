// HDF5 bake (docs/outputs.md "HDF5 bake"): the model once, then /frames/* extended by one frame
// per write(), one frame per chunk, so a bake streams to disk and a reader can pull any frame with
// one chunk read. format_version 1 stores /frames/positions; 2 (option "quantize") stores
// /frames/displacement_quantized instead, integers q with positions = rest + step * q.
#include <hdf5.h>

#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "common/errors.h"
#include "common/message_text.h"
#include "files/staged_files.h"
#include "formats/frame_sink.h"
#include "formats/hdf5_support.h"
#include "formats/rest_positions_f32.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

class Hdf5Sink final : public FrameSink {
 public:
  Hdf5Sink(const OutputOptions& options, fs::path path, const TreeModel& model, const BakeInfo& info)
      : options_(options), path_(std::move(path)), model_(model), info_(info) {}

  std::vector<SummaryFile> summary_paths() const override { return {{path_}}; }

  void begin() override {
    const auto lock = hdf5_lock();
    rest_ = rest_positions_f32(model_);
    const fs::path temporary = staged_.stage(path_);
    file_ = Handle(check(H5Fcreate(temporary.c_str(), H5F_ACC_TRUNC, untimed_creation(H5P_FILE_CREATE).get(), H5P_DEFAULT),
                         "create the file"), H5Fclose);
    write_root_attributes();
    write_string_dataset(file_.get(), "scene", info_.scene_json);
    write_mesh();
    write_model();
    write_skeleton();
    create_frame_datasets();
  }

  void write(const FrameData& frame) override {
    const auto lock = hdf5_lock();
    const hsize_t n = model_.vertex_count();
    append(time_.get(), {}, H5T_NATIVE_DOUBLE, &frame.time);
    if (options_.quantize > 0) {
      if (!quantize(frame) && quantized_int16_) widen_quantized();
      append(positions_.get(), {n, 3}, H5T_NATIVE_INT32, quantized_.data());
    } else {
      append(positions_.get(), {n, 3}, H5T_NATIVE_FLOAT, frame.positions.data());
    }
    if (options_.normals) append(normals_.get(), {n, 3}, H5T_NATIVE_FLOAT, frame.normals.data());
    if (options_.velocities) append(velocities_.get(), {n, 3}, H5T_NATIVE_FLOAT, frame.velocities.data());
    if (leaf_attached_.get() >= 0)
      append(leaf_attached_.get(), {model_.leaf_count()}, H5T_NATIVE_UINT8, frame.leaf_attached.data());
    ++frames_written_;
  }

  void finish() override {
    const auto lock = hdf5_lock();
    bool ok = close_datasets();
    ok = file_.reset() && ok;
    if (!ok) fail("close the file");
  }

  void abort() noexcept override {
    {
      const auto lock = hdf5_lock();
      close_datasets();
      file_.reset();
      H5Eclear2(H5E_DEFAULT);
    }
    staged_.discard();
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    const std::string detail = hdf5_error_text();
    throw OutputError(path_.string() + ": HDF5 could not " + what +
                      (detail.empty() ? "" : " (" + detail + ")"));
  }
  hid_t check(hid_t id, const std::string& what) const {
    if (id < 0) fail(what);
    return id;
  }
  void check_status(herr_t status, const std::string& what) const {
    if (status < 0) fail(what);
  }

  // A variable-length UTF-8 string type (h5py reads it as str).
  Handle string_type() const {
    Handle type(check(H5Tcopy(H5T_C_S1), "make a string type"), H5Tclose);
    check_status(H5Tset_size(type.get(), H5T_VARIABLE), "make a string type");
    check_status(H5Tset_cset(type.get(), H5T_CSET_UTF8), "make a string type");
    return type;
  }

  // An attribute of the file's root, or of `object` when given.
  void write_attribute(const char* name, hid_t file_type, hid_t memory_type, const void* value,
                       hid_t object = -1) const {
    Handle space(check(H5Screate(H5S_SCALAR), "make a scalar space"), H5Sclose);
    Handle attribute(check(H5Acreate2(object < 0 ? file_.get() : object, name, file_type, space.get(), H5P_DEFAULT,
                                      H5P_DEFAULT),
                           std::string("create attribute ") + name), H5Aclose);
    check_status(H5Awrite(attribute.get(), memory_type, value), std::string("write attribute ") + name);
  }
  void write_string_attribute(const char* name, const std::string& value) const {
    const Handle type = string_type();
    const char* text = value.c_str();
    write_attribute(name, type.get(), type.get(), &text);
  }

  void write_root_attributes() const {
    const int32_t version = options_.quantize > 0 ? 2 : 1, substeps = info_.substeps;
    const int64_t frame_start = info_.frame_start;
    const uint64_t seed = info_.seed;
    write_string_attribute("format", "treeanim");
    write_attribute("format_version", H5T_STD_I32LE, H5T_NATIVE_INT32, &version);
    write_string_attribute("generator", info_.generator);
    write_attribute("fps", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &info_.fps);
    write_attribute("frame_start", H5T_STD_I64LE, H5T_NATIVE_INT64, &frame_start);
    write_attribute("substeps", H5T_STD_I32LE, H5T_NATIVE_INT32, &substeps);
    write_string_attribute("units", "m");
    write_string_attribute("up_axis", "Y");
    write_attribute("seed", H5T_STD_U64LE, H5T_NATIVE_UINT64, &seed);
  }

  void write_string_dataset(hid_t group, const char* name, const std::string& value) const {
    const Handle type = string_type();
    Handle space(check(H5Screate(H5S_SCALAR), "make a scalar space"), H5Sclose);
    Handle dataset(check(H5Dcreate2(group, name, type.get(), space.get(), H5P_DEFAULT,
                                    untimed_creation(H5P_DATASET_CREATE).get(), H5P_DEFAULT),
                         std::string("create /") + name), H5Dclose);
    const char* text = value.c_str();
    check_status(H5Dwrite(dataset.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, &text),
                 std::string("write /") + name);
  }

  Handle create_group(const char* name) const {
    return Handle(check(H5Gcreate2(file_.get(), name, H5P_DEFAULT, untimed_creation(H5P_GROUP_CREATE).get(), H5P_DEFAULT),
                        std::string("create group ") + name), H5Gclose);
  }

  // A fixed-size dataset written at once; `data` holds dims' product elements of memory_type.
  void write_array(hid_t group, const std::string& name, hid_t file_type, hid_t memory_type,
                   std::vector<hsize_t> dims, const void* data) const {
    Handle space(check(H5Screate_simple(int(dims.size()), dims.data(), nullptr), "make a space for " + name),
                 H5Sclose);
    Handle dataset(check(H5Dcreate2(group, name.c_str(), file_type, space.get(), H5P_DEFAULT,
                                    untimed_creation(H5P_DATASET_CREATE).get(),
                                    H5P_DEFAULT), "create " + name), H5Dclose);
    hsize_t total = 1;
    for (hsize_t d : dims) total *= d;
    if (total > 0)
      check_status(H5Dwrite(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "write " + name);
  }

  void write_mesh() const {
    const Handle group = create_group("/mesh");
    const hsize_t n = model_.vertex_count();
    write_array(group.get(), "rest_positions", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, {n, 3}, rest_.data());
    write_array(group.get(), "triangles", H5T_STD_U32LE, H5T_NATIVE_UINT32, {model_.triangle_count(), 3},
                model_.triangles.data());
    write_array(group.get(), "triangle_material", H5T_STD_U8LE, H5T_NATIVE_UINT8, {model_.triangle_count()},
                model_.triangle_material.data());
  }

  void write_model() const {
    const Handle group = create_group("/model");
    const hid_t g = group.get();
    write_array(g, "mass", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {model_.vertex_count()}, model_.vertex_mass.data());
    write_array(g, "anchored", H5T_STD_U8LE, H5T_NATIVE_UINT8, {model_.vertex_count()},
                model_.vertex_anchored.data());
    write_array(g, "cluster_offsets", H5T_STD_U32LE, H5T_NATIVE_UINT32, {model_.cluster_offsets.size()},
                model_.cluster_offsets.data());
    write_array(g, "cluster_members", H5T_STD_U32LE, H5T_NATIVE_UINT32, {model_.cluster_members.size()},
                model_.cluster_members.data());
    write_array(g, "cluster_kind", H5T_STD_U8LE, H5T_NATIVE_UINT8, {model_.cluster_kind.size()},
                model_.cluster_kind.data());
  }

  void write_skeleton() const {
    const Handle group = create_group("/skeleton");
    const hid_t g = group.get();
    const size_t s = model_.segment_count();
    std::vector<float> start(3 * s), end(3 * s), radius(2 * s);
    for (size_t i = 0; i < s; ++i) {
      for (int a = 0; a < 3; ++a) {
        start[3 * i + a] = float(model_.segment_start[i][a]);
        end[3 * i + a] = float(model_.segment_end[i][a]);
      }
      radius[2 * i] = float(model_.segment_radius_base[i]);
      radius[2 * i + 1] = float(model_.segment_radius_top[i]);
    }
    write_array(g, "segment_start", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, {s, 3}, start.data());
    write_array(g, "segment_end", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, {s, 3}, end.data());
    write_array(g, "segment_radius", H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, {s, 2}, radius.data());
    write_array(g, "segment_parent", H5T_STD_I32LE, H5T_NATIVE_INT32, {s}, model_.segment_parent.data());
    write_array(g, "segment_cluster", H5T_STD_U32LE, H5T_NATIVE_UINT32, {s}, model_.segment_cluster.data());
  }

  // An extendible dataset [0, frame_shape...] with one frame per chunk; shuffle + deflate at
  // `level` when it is > 0.
  Handle create_frame_dataset(hid_t group, const char* name, hid_t file_type, std::vector<hsize_t> frame_shape,
                              hsize_t frames_per_chunk, int level) const {
    std::vector<hsize_t> dims{0}, max_dims{H5S_UNLIMITED}, chunk{frames_per_chunk};
    for (hsize_t d : frame_shape) {
      dims.push_back(d);
      max_dims.push_back(d);
      chunk.push_back(d);
    }
    Handle space(check(H5Screate_simple(int(dims.size()), dims.data(), max_dims.data()), "make a frame space"),
                 H5Sclose);
    Handle properties = untimed_creation(H5P_DATASET_CREATE);
    check_status(H5Pset_chunk(properties.get(), int(chunk.size()), chunk.data()), std::string("chunk ") + name);
    if (level > 0) {
      check_status(H5Pset_shuffle(properties.get()), "enable shuffle");
      check_status(H5Pset_deflate(properties.get(), unsigned(level)), "enable deflate");
    }
    return Handle(check(H5Dcreate2(group, name, file_type, space.get(), H5P_DEFAULT, properties.get(),
                                   H5P_DEFAULT), std::string("create /frames/") + name), H5Dclose);
  }

  void create_frame_datasets() {
    const Handle group = create_group("/frames");
    const hid_t g = group.get();
    const hsize_t n = model_.vertex_count();
    const int level = options_.compression;
    // Times are tiny: 1024 per chunk keeps the chunk index small for long bakes.
    time_ = create_frame_dataset(g, "time", H5T_IEEE_F64LE, {}, 1024, 0);
    if (options_.quantize > 0) {
      positions_ = create_quantized_dataset(g, "displacement_quantized", H5T_STD_I16LE);
    } else {
      positions_ = create_frame_dataset(g, "positions", H5T_IEEE_F32LE, {n, 3}, 1, level);
    }
    if (options_.velocities)
      velocities_ = create_frame_dataset(g, "velocities", H5T_IEEE_F32LE, {n, 3}, 1, level);
    if (options_.normals) normals_ = create_frame_dataset(g, "normals", H5T_IEEE_F32LE, {n, 3}, 1, level);
    if (model_.leaf_count() > 0)
      leaf_attached_ = create_frame_dataset(g, "leaf_attached", H5T_STD_U8LE, {model_.leaf_count()}, 1, level);
  }

  // Grows `dataset` [k, frame_shape...] by one frame and writes `data` (one frame) there.
  void append(hid_t dataset, const std::vector<hsize_t>& frame_shape, hid_t memory_type, const void* data) const {
    write_frame(dataset, frames_written_, frame_shape, memory_type, data);
  }

  // Writes frame `index` of `dataset` [k, frame_shape...], growing it to index + 1 frames.
  void write_frame(hid_t dataset, hsize_t index, const std::vector<hsize_t>& frame_shape, hid_t memory_type,
                   const void* data) const {
    std::vector<hsize_t> dims{index + 1};
    dims.insert(dims.end(), frame_shape.begin(), frame_shape.end());
    check_status(H5Dset_extent(dataset, dims.data()), "extend a frame dataset");
    const auto [file_space, memory_space] = frame_spaces(dataset, index, frame_shape);
    check_status(H5Dwrite(dataset, memory_type, memory_space.get(), file_space.get(), H5P_DEFAULT, data),
                 "write frame " + std::to_string(index));
  }

  void read_frame(hid_t dataset, hsize_t index, const std::vector<hsize_t>& frame_shape, hid_t memory_type,
                  void* data) const {
    const auto [file_space, memory_space] = frame_spaces(dataset, index, frame_shape);
    check_status(H5Dread(dataset, memory_type, memory_space.get(), file_space.get(), H5P_DEFAULT, data),
                 "read frame " + std::to_string(index));
  }

  // The file space of `dataset` with frame `index` selected, and a memory space of one frame.
  std::pair<Handle, Handle> frame_spaces(hid_t dataset, hsize_t index, const std::vector<hsize_t>& frame_shape) const {
    std::vector<hsize_t> start(frame_shape.size() + 1, 0), count{1};
    start[0] = index;
    count.insert(count.end(), frame_shape.begin(), frame_shape.end());
    Handle file_space(check(H5Dget_space(dataset), "get a frame space"), H5Sclose);
    check_status(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr),
                 "select a frame");
    Handle memory_space(check(H5Screate_simple(int(count.size()), count.data(), nullptr), "make a frame space"),
                        H5Sclose);
    return {std::move(file_space), std::move(memory_space)};
  }

  // Integers are only worth storing shuffled and deflated (level 4 unless one is given).
  Handle create_quantized_dataset(hid_t group, const char* name, hid_t file_type) const {
    Handle dataset = create_frame_dataset(group, name, file_type, {model_.vertex_count(), 3}, 1,
                                          options_.compression > 0 ? options_.compression : 4);
    write_attribute("step", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &options_.quantize, dataset.get());
    return dataset;
  }

  // frame => quantized_: (position - rest) / step rounded to the nearest integer; returns false
  // when a value does not fit in int16. A value beyond int32 fails the bake rather than being
  // clipped (a file never lies).
  bool quantize(const FrameData& frame) {
    quantized_.resize(rest_.size());
    bool fits_int16 = true;
    for (size_t i = 0; i < rest_.size(); ++i) {
      const double q = std::nearbyint((double(frame.positions[i]) - double(rest_[i])) / options_.quantize);
      if (!(std::fabs(q) <= 2147483647.0))
        throw OutputError(path_.string() + ": frame " + std::to_string(frame.frame) + " moves vertex " +
                          std::to_string(i / 3) + " " + number_text(double(frame.positions[i]) - rest_[i]) +
                          " m from rest, beyond what quantize = " + number_text(options_.quantize) +
                          " m holds in int32; raise quantize or leave it out");
      fits_int16 = fits_int16 && std::fabs(q) <= 32767.0;
      quantized_[i] = static_cast<int32_t>(q);
    }
    return fits_int16;
  }

  // The first frame past int16: the frames so far move to an int32 dataset of the same name.
  // Their int16 copy stays in the file as unused space (HDF5 does not give it back), once.
  void widen_quantized() {
    Handle group(check(H5Gopen2(file_.get(), "/frames", H5P_DEFAULT), "open /frames"), H5Gclose);
    Handle wide = create_quantized_dataset(group.get(), "displacement_quantized_int32", H5T_STD_I32LE);
    std::vector<int32_t> frame(rest_.size());
    const hsize_t n = model_.vertex_count();
    for (hsize_t k = 0; k < frames_written_; ++k) {
      read_frame(positions_.get(), k, {n, 3}, H5T_NATIVE_INT32, frame.data());
      write_frame(wide.get(), k, {n, 3}, H5T_NATIVE_INT32, frame.data());
    }
    if (!positions_.reset()) fail("close the int16 displacements");
    check_status(H5Ldelete(group.get(), "displacement_quantized", H5P_DEFAULT), "remove the int16 displacements");
    check_status(H5Lmove(group.get(), "displacement_quantized_int32", group.get(), "displacement_quantized", H5P_DEFAULT,
                         H5P_DEFAULT), "rename the int32 displacements");
    positions_ = std::move(wide);
    quantized_int16_ = false;
  }

  bool close_datasets() {
    bool ok = time_.reset();
    ok = positions_.reset() && ok;
    ok = velocities_.reset() && ok;
    ok = normals_.reset() && ok;
    return leaf_attached_.reset() && ok;
  }

  OutputOptions options_;
  fs::path path_;
  const TreeModel& model_;
  BakeInfo info_;
  bool quantized_int16_ = true;    // the quantized displacements are stored as int16 (else int32)
  std::vector<float> rest_;        // (V*3) m, float32 rest pose as stored in /mesh
  std::vector<int32_t> quantized_; // (V*3) scratch: one frame's quantized displacements
  // positions_ is /frames/positions, or /frames/displacement_quantized when quantized.
  Handle file_, time_, positions_, velocities_, normals_, leaf_attached_;
  hsize_t frames_written_ = 0;
};

}  // namespace

std::unique_ptr<FrameSink> make_hdf5_sink(const OutputOptions& options, const fs::path& path,
                                          const TreeModel& model, const BakeInfo& info) {
  return std::make_unique<Hdf5Sink>(options, path, model, info);
}

}  // namespace treeanim
