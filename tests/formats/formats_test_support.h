#pragma once
// Hand-made TreeModel and frames for the formats/ tests, so they need neither the grower nor the
// solver: a branch quad (vertices 0-3, two triangles) and one leaf triangle hanging from
// vertex 3 (vertices 3-5), one segment, two clusters.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "formats/outputs.h"
#include "output/output_formats.h"
#include "tree/tree_model.h"

namespace treeanim::test {

inline TreeModel small_model() {
  TreeModel m;
  m.rest_positions.resize(3, 6);
  m.rest_positions << 0.0, 0.1, 0.1, 0.0, 0.05, 0.2,  //
      0.0, 0.0, 1.0, 1.0, 1.25, 1.2,                  //
      0.0, 0.0, 0.0, 0.0, 0.1, -0.3;
  m.uvs.resize(2, 6);
  m.uvs << 0.0f, 1.0f, 1.0f, 0.0f, 0.5f, 1.0f,  //
      0.0f, 0.0f, 1.0f, 1.0f, 0.25f, 0.75f;
  m.triangles = {1, 2, 0, 0, 2, 3, 4, 5, 3};  // first use not in index order: exporters must keep it
  m.triangle_material = {kMaterialBark, kMaterialBark, kMaterialLeaf};
  m.vertex_segment = {0, 0, 0, 0, -1, -1};
  m.vertex_leaf = {-1, -1, -1, 0, 0, 0};
  m.vertex_mass = {0.5, 0.5, 0.25, 0.3, 0.01, 0.01};
  m.vertex_anchored = {1, 1, 0, 0, 0, 0};
  m.vertex_drag_area = {0, 0, 0.01, 0.01, 0.002, 0.002};
  m.cluster_offsets = {0, 4, 7};
  m.cluster_members = {0, 1, 2, 3, 3, 4, 5};
  m.cluster_kind = {kClusterBranch, kClusterLeaf};
  m.cluster_leaf = {-1, 0};
  m.cluster_parent = {-1, 0};
  m.cluster_length = {1.0, 0.3};
  m.cluster_radius = {0.05, 0.0};
  m.vertex_cluster_offsets = {0, 1, 2, 3, 5, 6, 7};
  m.vertex_memberships = {0, 1, 2, 3, 4, 5, 6};
  m.member_cluster = {0, 0, 0, 0, 1, 1, 1};
  m.leaf_cluster = {1};
  m.leaf_attachment_vertex = {3};
  m.segment_start = {Eigen::Vector3d(0.05, 0, 0)};
  m.segment_end = {Eigen::Vector3d(0.05, 1, 0)};
  m.segment_radius_base = {0.05};
  m.segment_radius_top = {0.04};
  m.segment_parent = {-1};
  m.segment_cluster = {0};
  return m;
}

inline BakeInfo small_info(long long frames = 5, long long start = 1) {
  BakeInfo info;
  info.scene_json = R"({"time": {"fps": 24}})";
  info.generator = "treeanim test";
  info.fps = 24;
  info.frame_start = start;
  info.frame_count = frames;
  info.substeps = 3;
  info.seed = 12345678901234ull;
  return info;
}

// Frame `frame`: the rest pose swayed by an amount that differs per frame and vertex, with
// values that are not short decimals (so text round-trips are really tested).
inline FrameData small_frame(const TreeModel& m, long long frame, bool velocities = true) {
  FrameData data;
  data.frame = frame;
  data.time = double(frame) / 24.0;
  for (long v = 0; v < m.rest_positions.cols(); ++v)
    for (int a = 0; a < 3; ++a) {
      const double sway = (m.vertex_anchored[size_t(v)] ? 0.0 : 1.0) * 0.013 * double(frame) * (a + 1) / 7.0;
      data.positions.push_back(float(m.rest_positions(a, v) + sway));
      if (velocities) data.velocities.push_back(float(0.1 * v + a - 0.01 * double(frame)));
    }
  data.leaf_attached = {uint8_t(frame < 3 ? 1 : 0)};
  return data;
}

// A fresh empty folder per test, removed afterwards.
class TempFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           ("treeanim-io-" + std::to_string(::getpid()) + "-" + info->test_suite_name() + "-" + info->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  // Names of every entry in the folder (recursively), sorted.
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::recursive_directory_iterator(dir_))
      names.push_back(std::filesystem::relative(e.path(), dir_).string());
    std::sort(names.begin(), names.end());
    return names;
  }
  std::filesystem::path dir_;
};

// Leaves a Unix socket file at `path` => 0, or -1 with errno set. Bound at a short name and moved,
// since a socket's address holds at most 107 bytes.
inline int bind_unix_socket(const std::filesystem::path& path) {
  const std::string bound_at = "/tmp/treeanim-socket-" + std::to_string(::getpid());
  ::unlink(bound_at.c_str());
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  if (fd < 0) return -1;
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::snprintf(address.sun_path, sizeof address.sun_path, "%s", bound_at.c_str());
  const int bound = ::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address);
  ::close(fd);
  return bound == 0 ? ::rename(bound_at.c_str(), path.c_str()) : bound;
}

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A parsed OBJ: "v", "vt" and "f v/vt" lines.
struct ObjMesh {
  std::vector<float> positions;   // (V*3)
  std::vector<float> uvs;         // (V*2)
  std::vector<uint32_t> faces;    // (T*3) 0-based
  std::vector<uint32_t> face_uvs; // (T*3) 0-based
  std::vector<std::string> face_materials;  // (T) the "usemtl" name in force
  std::string mtllib;                       // the "mtllib" file
};

inline ObjMesh parse_obj(const std::filesystem::path& path) {
  ObjMesh mesh;
  std::istringstream in(read_file(path));
  std::string line, material;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string tag;
    fields >> tag;
    if (tag == "mtllib") {
      fields >> mesh.mtllib;
    } else if (tag == "usemtl") {
      fields >> material;
    } else if (tag == "v") {
      for (int a = 0; a < 3; ++a) {
        std::string x;
        fields >> x;
        mesh.positions.push_back(std::stof(x));
      }
    } else if (tag == "vt") {
      for (int a = 0; a < 2; ++a) {
        std::string x;
        fields >> x;
        mesh.uvs.push_back(std::stof(x));
      }
    } else if (tag == "f") {
      mesh.face_materials.push_back(material);
      for (int c = 0; c < 3; ++c) {
        std::string corner;
        fields >> corner;
        const size_t slash = corner.find('/');
        mesh.faces.push_back(uint32_t(std::stoul(corner.substr(0, slash)) - 1));
        mesh.face_uvs.push_back(uint32_t(std::stoul(corner.substr(slash + 1)) - 1));
      }
    }
  }
  return mesh;
}

inline std::vector<float> rest_f32(const TreeModel& m) {
  return std::vector<float>(m.rest_positions.data(), m.rest_positions.data() + m.rest_positions.size());
}

inline OutputOptions output(const std::string& format, const std::string& path, int frame_step = 1) {
  OutputOptions o;
  o.format = find_output_format(format);
  o.path = path;
  o.frame_step = frame_step;
  o.pointer = "/outputs/0";
  return o;
}

// Runs a whole bake of `info.frame_count` small frames through an OutputSet.
inline void bake(const std::vector<OutputOptions>& outputs, const std::filesystem::path& dir, const TreeModel& m,
                 const BakeInfo& info) {
  OutputSet set(outputs, dir, m, info);
  set.begin();
  for (long long f = info.frame_start; f < info.frame_start + info.frame_count; ++f)
    set.push(small_frame(m, f, set.wants_velocities()));
  set.finish();
}

}  // namespace treeanim::test
