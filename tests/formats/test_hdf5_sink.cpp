// The HDF5 bake read back through the HDF5 C API: every dataset, shape, type and attribute of
// docs/design.md's layout, and the frames exactly as pushed.
#include <hdf5.h>

#include <cmath>

#include "common/errors.h"
#include "formats/vertex_normals.h"
#include "formats_test_support.h"

namespace treeanim {
namespace {

using test::small_frame;
using test::small_info;
using test::small_model;

struct Dataset {
  std::vector<hsize_t> dims;
  H5T_class_t type_class = H5T_NO_CLASS;
  size_t type_size = 0;
  H5T_sign_t sign = H5T_SGN_ERROR;
  std::vector<hsize_t> chunk;  // empty when contiguous
  std::vector<H5Z_filter_t> filters;
};

Dataset describe(hid_t file, const char* name) {
  Dataset d;
  const hid_t set = H5Dopen2(file, name, H5P_DEFAULT);
  EXPECT_GE(set, 0) << name;
  const hid_t space = H5Dget_space(set), type = H5Dget_type(set), plist = H5Dget_create_plist(set);
  d.dims.resize(size_t(H5Sget_simple_extent_ndims(space)));
  H5Sget_simple_extent_dims(space, d.dims.data(), nullptr);
  d.type_class = H5Tget_class(type);
  d.type_size = H5Tget_size(type);
  if (d.type_class == H5T_INTEGER) d.sign = H5Tget_sign(type);
  if (H5Pget_layout(plist) == H5D_CHUNKED) {
    d.chunk.resize(d.dims.size());
    H5Pget_chunk(plist, int(d.chunk.size()), d.chunk.data());
  }
  for (int i = 0; i < H5Pget_nfilters(plist); ++i) {
    unsigned flags = 0;
    size_t elements = 0;
    d.filters.push_back(H5Pget_filter2(plist, unsigned(i), &flags, &elements, nullptr, 0, nullptr, nullptr));
  }
  H5Pclose(plist);
  H5Tclose(type);
  H5Sclose(space);
  H5Dclose(set);
  return d;
}

template <typename T>
std::vector<T> read_all(hid_t file, const char* name, hid_t memory_type) {
  const hid_t set = H5Dopen2(file, name, H5P_DEFAULT);
  const hid_t space = H5Dget_space(set);
  std::vector<T> values(size_t(H5Sget_simple_extent_npoints(space)));
  if (!values.empty()) {
    EXPECT_GE(H5Dread(set, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), 0);
  }
  H5Sclose(space);
  H5Dclose(set);
  return values;
}

std::string read_string_attribute(hid_t file, const char* name) {
  const hid_t attribute = H5Aopen(file, name, H5P_DEFAULT);
  const hid_t type = H5Aget_type(attribute);
  EXPECT_TRUE(H5Tis_variable_str(type) > 0) << name;
  char* text = nullptr;
  H5Aread(attribute, type, &text);
  std::string value(text);
  H5free_memory(text);
  H5Tclose(type);
  H5Aclose(attribute);
  return value;
}

template <typename T>
T read_attribute(hid_t file, const char* name, hid_t memory_type) {
  T value{};
  const hid_t attribute = H5Aopen(file, name, H5P_DEFAULT);
  EXPECT_GE(H5Aread(attribute, memory_type, &value), 0) << name;
  H5Aclose(attribute);
  return value;
}

void expect_type(const Dataset& d, H5T_class_t type_class, size_t size, H5T_sign_t sign = H5T_SGN_ERROR) {
  EXPECT_EQ(d.type_class, type_class);
  EXPECT_EQ(d.type_size, size);
  if (type_class == H5T_INTEGER) {
    EXPECT_EQ(d.sign, sign);
  }
}

class Hdf5Sink : public test::TempFolder {};

TEST_F(Hdf5Sink, WritesTheContractLayout) {
  const TreeModel m = small_model();
  const BakeInfo info = small_info(5, 1);
  test::bake({test::output("hdf5", "sub/bake.h5")}, dir_, m, info);
  EXPECT_EQ(entries(), (std::vector<std::string>{"sub", "sub/bake.h5"}));

  const hid_t file = H5Fopen((dir_ / "sub/bake.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  EXPECT_EQ(read_string_attribute(file, "format"), "treeanim");
  EXPECT_EQ(read_attribute<int32_t>(file, "format_version", H5T_NATIVE_INT32), 1);
  EXPECT_EQ(read_string_attribute(file, "generator"), "treeanim test");
  EXPECT_EQ(read_attribute<double>(file, "fps", H5T_NATIVE_DOUBLE), 24.0);
  EXPECT_EQ(read_attribute<int64_t>(file, "frame_start", H5T_NATIVE_INT64), 1);
  EXPECT_EQ(read_attribute<int32_t>(file, "substeps", H5T_NATIVE_INT32), 3);
  EXPECT_EQ(read_string_attribute(file, "units"), "m");
  EXPECT_EQ(read_string_attribute(file, "up_axis"), "Y");
  EXPECT_EQ(read_attribute<uint64_t>(file, "seed", H5T_NATIVE_UINT64), 12345678901234ull);

  {
    const hid_t set = H5Dopen2(file, "/scene", H5P_DEFAULT);
    const hid_t type = H5Dget_type(set);
    EXPECT_TRUE(H5Tis_variable_str(type) > 0);
    char* text = nullptr;
    H5Dread(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, &text);
    EXPECT_EQ(std::string(text), info.scene_json);
    H5free_memory(text);
    H5Tclose(type);
    H5Dclose(set);
  }

  struct Expected {
    const char* name;
    std::vector<hsize_t> dims;
    H5T_class_t type_class;
    size_t size;
    H5T_sign_t sign;
  };
  const std::vector<Expected> layout = {
      {"/mesh/rest_positions", {6, 3}, H5T_FLOAT, 4, H5T_SGN_ERROR},
      {"/mesh/triangles", {3, 3}, H5T_INTEGER, 4, H5T_SGN_NONE},
      {"/mesh/triangle_material", {3}, H5T_INTEGER, 1, H5T_SGN_NONE},
      {"/model/mass", {6}, H5T_FLOAT, 8, H5T_SGN_ERROR},
      {"/model/anchored", {6}, H5T_INTEGER, 1, H5T_SGN_NONE},
      {"/model/cluster_offsets", {3}, H5T_INTEGER, 4, H5T_SGN_NONE},
      {"/model/cluster_members", {7}, H5T_INTEGER, 4, H5T_SGN_NONE},
      {"/model/cluster_kind", {2}, H5T_INTEGER, 1, H5T_SGN_NONE},
      {"/skeleton/segment_start", {1, 3}, H5T_FLOAT, 4, H5T_SGN_ERROR},
      {"/skeleton/segment_end", {1, 3}, H5T_FLOAT, 4, H5T_SGN_ERROR},
      {"/skeleton/segment_radius", {1, 2}, H5T_FLOAT, 4, H5T_SGN_ERROR},
      {"/skeleton/segment_parent", {1}, H5T_INTEGER, 4, H5T_SGN_2},
      {"/skeleton/segment_cluster", {1}, H5T_INTEGER, 4, H5T_SGN_NONE},
      {"/frames/time", {5}, H5T_FLOAT, 8, H5T_SGN_ERROR},
      {"/frames/positions", {5, 6, 3}, H5T_FLOAT, 4, H5T_SGN_ERROR},
      {"/frames/leaf_attached", {5, 1}, H5T_INTEGER, 1, H5T_SGN_NONE},
  };
  for (const Expected& e : layout) {
    SCOPED_TRACE(e.name);
    const Dataset d = describe(file, e.name);
    EXPECT_EQ(d.dims, e.dims);
    expect_type(d, e.type_class, e.size, e.sign);
  }
  EXPECT_EQ(H5Lexists(file, "/frames/velocities", H5P_DEFAULT), 0);  // not asked for
  const Dataset positions = describe(file, "/frames/positions");
  EXPECT_EQ(positions.chunk, (std::vector<hsize_t>{1, 6, 3}));
  EXPECT_TRUE(positions.filters.empty());

  EXPECT_EQ(read_all<float>(file, "/mesh/rest_positions", H5T_NATIVE_FLOAT), test::rest_f32(m));
  EXPECT_EQ(read_all<uint32_t>(file, "/mesh/triangles", H5T_NATIVE_UINT32), m.triangles);
  EXPECT_EQ(read_all<uint8_t>(file, "/mesh/triangle_material", H5T_NATIVE_UINT8), (std::vector<uint8_t>{0, 0, 1}));
  EXPECT_EQ(read_all<double>(file, "/model/mass", H5T_NATIVE_DOUBLE), m.vertex_mass);
  EXPECT_EQ(read_all<uint8_t>(file, "/model/anchored", H5T_NATIVE_UINT8), m.vertex_anchored);
  EXPECT_EQ(read_all<uint32_t>(file, "/model/cluster_offsets", H5T_NATIVE_UINT32), m.cluster_offsets);
  EXPECT_EQ(read_all<uint32_t>(file, "/model/cluster_members", H5T_NATIVE_UINT32), m.cluster_members);
  EXPECT_EQ(read_all<uint8_t>(file, "/model/cluster_kind", H5T_NATIVE_UINT8), m.cluster_kind);
  EXPECT_EQ(read_all<float>(file, "/skeleton/segment_start", H5T_NATIVE_FLOAT), (std::vector<float>{0.05f, 0, 0}));
  EXPECT_EQ(read_all<float>(file, "/skeleton/segment_end", H5T_NATIVE_FLOAT), (std::vector<float>{0.05f, 1, 0}));
  EXPECT_EQ(read_all<float>(file, "/skeleton/segment_radius", H5T_NATIVE_FLOAT), (std::vector<float>{0.05f, 0.04f}));
  EXPECT_EQ(read_all<int32_t>(file, "/skeleton/segment_parent", H5T_NATIVE_INT32), m.segment_parent);
  EXPECT_EQ(read_all<uint32_t>(file, "/skeleton/segment_cluster", H5T_NATIVE_UINT32), m.segment_cluster);

  const auto times = read_all<double>(file, "/frames/time", H5T_NATIVE_DOUBLE);
  const auto frames = read_all<float>(file, "/frames/positions", H5T_NATIVE_FLOAT);
  const auto attached = read_all<uint8_t>(file, "/frames/leaf_attached", H5T_NATIVE_UINT8);
  for (long long k = 0; k < 5; ++k) {
    const FrameData expected = small_frame(m, 1 + k);
    EXPECT_EQ(times[size_t(k)], expected.time);
    EXPECT_EQ(std::vector<float>(frames.begin() + k * 18, frames.begin() + (k + 1) * 18), expected.positions);
    EXPECT_EQ(attached[size_t(k)], expected.leaf_attached[0]);
  }
  H5Fclose(file);
}

TEST_F(Hdf5Sink, CompressionVelocitiesAndFrameStep) {
  const TreeModel m = small_model();
  OutputOptions o = test::output("hdf5", "bake.h5", 2);
  o.compression = 4;
  o.velocities = true;
  test::bake({o}, dir_, m, small_info(5, 10));

  const hid_t file = H5Fopen((dir_ / "bake.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  for (const char* name : {"/frames/positions", "/frames/velocities"}) {
    const Dataset d = describe(file, name);
    EXPECT_EQ(d.dims, (std::vector<hsize_t>{3, 6, 3})) << name;  // frames 10, 12, 14
    EXPECT_EQ(d.chunk, (std::vector<hsize_t>{1, 6, 3})) << name;
    EXPECT_EQ(d.filters, (std::vector<H5Z_filter_t>{H5Z_FILTER_SHUFFLE, H5Z_FILTER_DEFLATE})) << name;
  }
  EXPECT_EQ(read_attribute<int64_t>(file, "frame_start", H5T_NATIVE_INT64), 10);
  const auto times = read_all<double>(file, "/frames/time", H5T_NATIVE_DOUBLE);
  const auto positions = read_all<float>(file, "/frames/positions", H5T_NATIVE_FLOAT);
  const auto velocities = read_all<float>(file, "/frames/velocities", H5T_NATIVE_FLOAT);
  for (size_t k = 0; k < 3; ++k) {
    const FrameData expected = small_frame(m, 10 + 2 * long(k));
    EXPECT_EQ(times[k], expected.time);
    EXPECT_EQ(std::vector<float>(positions.begin() + long(k) * 18, positions.begin() + long(k + 1) * 18),
              expected.positions);
    EXPECT_EQ(std::vector<float>(velocities.begin() + long(k) * 18, velocities.begin() + long(k + 1) * 18),
              expected.velocities);
  }
  H5Fclose(file);
}

// "quantize": format_version 2, /frames/displacement_quantized instead of /frames/positions,
// int16 while every value fits and int32 from the first frame that does not (the frames before
// it moved over), and rest + step * q within half a step of every pushed position; "normals":
// /frames/normals exactly as OutputSet computed them.
TEST_F(Hdf5Sink, QuantizedDisplacementsAndNormals) {
  const TreeModel m = test::small_model();
  // The frames move up to 13 mm x frame x 3/7: at 1 mm every frame fits int16; at 1 um frame 6
  // (33,400 steps) does not.
  for (const double step : {1e-3, 1e-6}) {
    SCOPED_TRACE(step);
    OutputOptions o = test::output("hdf5", "bake.h5");
    o.quantize = step;
    o.normals = true;
    test::bake({o}, dir_, m, small_info(8, 0));

    const hid_t file = H5Fopen((dir_ / "bake.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(file, 0);
    EXPECT_EQ(read_attribute<int32_t>(file, "format_version", H5T_NATIVE_INT32), 2);
    EXPECT_EQ(H5Lexists(file, "/frames/positions", H5P_DEFAULT), 0);
    EXPECT_EQ(H5Lexists(file, "/frames/displacement_quantized_int32", H5P_DEFAULT), 0);
    const Dataset d = describe(file, "/frames/displacement_quantized");
    expect_type(d, H5T_INTEGER, step == 1e-3 ? 2 : 4, H5T_SGN_2);
    EXPECT_EQ(d.dims, (std::vector<hsize_t>{8, 6, 3}));
    EXPECT_EQ(d.chunk, (std::vector<hsize_t>{1, 6, 3}));
    EXPECT_EQ(d.filters, (std::vector<H5Z_filter_t>{H5Z_FILTER_SHUFFLE, H5Z_FILTER_DEFLATE}));
    const hid_t set = H5Dopen2(file, "/frames/displacement_quantized", H5P_DEFAULT);
    EXPECT_EQ(read_attribute<double>(set, "step", H5T_NATIVE_DOUBLE), step);
    H5Dclose(set);
    const auto rest = read_all<float>(file, "/mesh/rest_positions", H5T_NATIVE_FLOAT);
    const auto q = read_all<int32_t>(file, "/frames/displacement_quantized", H5T_NATIVE_INT32);
    const auto normals = read_all<float>(file, "/frames/normals", H5T_NATIVE_FLOAT);
    ASSERT_EQ(q.size(), 8u * 18u);
    ASSERT_EQ(normals.size(), 8u * 18u);
    std::vector<float> expected_normals;
    for (size_t k = 0; k < 8; ++k) {
      const FrameData frame = small_frame(m, long(k));
      for (size_t i = 0; i < 18; ++i)
        EXPECT_LE(std::fabs(double(rest[i]) + step * q[18 * k + i] - double(frame.positions[i])), 0.5 * step) << i;
      vertex_normals(m, frame.positions.data(), rest_normals(m), expected_normals);
      EXPECT_EQ(std::vector<float>(normals.begin() + long(18 * k), normals.begin() + long(18 * (k + 1))),
                expected_normals);
    }
    H5Fclose(file);
    std::filesystem::remove(dir_ / "bake.h5");
  }
}

// A displacement beyond int32 fails the bake (exit 4) and leaves nothing, never clipped.
TEST_F(Hdf5Sink, QuantizedOverflowFailsTheBake) {
  const TreeModel m = small_model();
  OutputOptions o = test::output("hdf5", "bake.h5");
  o.quantize = 1e-9;
  try {
    OutputSet set({o}, dir_, m, small_info(2, 0));
    set.begin();
    set.push(small_frame(m, 0));
    FrameData far = small_frame(m, 1);
    far.positions[6] += 10.0f;  // 10 m: 1e10 steps of 1 nm
    set.push(far);
    set.finish();
    FAIL() << "no error";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("frame 1 moves vertex 2 "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("holds in int32; raise quantize"), std::string::npos) << e.what();
  }
  EXPECT_EQ(entries(), std::vector<std::string>{});
}

}  // namespace
}  // namespace treeanim
