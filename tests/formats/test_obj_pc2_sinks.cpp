// OBJ sequence and PC2 cache parsed back: vertex order, count, UVs and faces identical to
// the TreeModel in every file, positions exactly the pushed floats.
#include <cstring>

#include "common/errors.h"
#include "formats/sequence_pattern.h"
#include "formats/vertex_normals.h"
#include "formats_test_support.h"

namespace treeanim {
namespace {

using test::small_frame;
using test::small_info;
using test::small_model;

class ObjPc2 : public test::TempFolder {};

void expect_topology(const test::ObjMesh& mesh, const TreeModel& m, const std::string& mtllib) {
  EXPECT_EQ(mesh.mtllib, mtllib);
  EXPECT_EQ(mesh.face_materials, (std::vector<std::string>{"bark", "bark", "leaf"}));
  EXPECT_EQ(mesh.faces, m.triangles);
  EXPECT_EQ(mesh.face_uvs, m.triangles);
  EXPECT_EQ(mesh.uvs, std::vector<float>(m.uvs.data(), m.uvs.data() + m.uvs.size()));
}

TEST_F(ObjPc2, ObjSequenceKeepsVertexOrderAndTopology) {
  const TreeModel m = small_model();
  test::bake({test::output("obj", "obj/tree", 2)}, dir_, m, small_info(5, 1));
  EXPECT_EQ(entries(), (std::vector<std::string>{"obj", "obj/tree.0001.obj", "obj/tree.0003.obj",
                                                 "obj/tree.0005.obj", "obj/tree.rest.mtl", "obj/tree.rest.obj"}));
  const test::ObjMesh rest = test::parse_obj(dir_ / "obj/tree.rest.obj");
  EXPECT_EQ(rest.positions, test::rest_f32(m));
  expect_topology(rest, m, "tree.rest.mtl");
  // Kd is the linear base colour, as glTF's baseColorFactor; Pr the roughness.
  const std::string mtl = test::read_file(dir_ / "obj/tree.rest.mtl");
  EXPECT_EQ(mtl.substr(0, mtl.find('\n')), "# treeanim test, materials");
  EXPECT_NE(mtl.find("\nnewmtl bark\nKd 0.10653923"), std::string::npos) << mtl;
  EXPECT_NE(mtl.find("\nnewmtl leaf\nKd 0.07"), std::string::npos) << mtl;
  EXPECT_NE(mtl.find("\nPr 0.8\n"), std::string::npos) << mtl;
  EXPECT_NE(mtl.find("\nPr 0.6\n"), std::string::npos) << mtl;
  for (long long f : {1, 3, 5}) {
    char name[32];
    std::snprintf(name, sizeof name, "obj/tree.%04lld.obj", f);
    const test::ObjMesh mesh = test::parse_obj(dir_ / name);
    EXPECT_EQ(mesh.positions, small_frame(m, f).positions) << name;
    expect_topology(mesh, m, "tree.rest.mtl");
  }
}

TEST(SequencePattern, NamesFramesAndRest) {
  const SequencePattern plain = sequence_pattern("out/tree", ".obj", "/outputs/0");
  EXPECT_EQ(plain.frame(7), "out/tree.0007.obj");
  EXPECT_EQ(plain.frame(12345), "out/tree.12345.obj");
  EXPECT_EQ(plain.rest(), "out/tree.rest.obj");
  EXPECT_EQ(sequence_pattern("tree.obj", ".obj", "").frame(3), "tree.0003.obj");
  const SequencePattern field = sequence_pattern("a%b/leaf_%03d_x.obj", ".obj", "");
  EXPECT_EQ(field.frame(7), "a%b/leaf_007_x.obj");
  EXPECT_EQ(field.rest(), "a%b/leaf_rest_x.obj");
  EXPECT_EQ(sequence_pattern("t%d.glb", ".glb", "").frame(42), "t42.glb");
  const SequencePattern hashes = sequence_pattern("o/f.####.obj", ".obj", "");  // Houdini's $F4
  EXPECT_EQ(hashes.frame(7), "o/f.0007.obj");
  EXPECT_EQ(hashes.rest(), "o/f.rest.obj");
  try {
    sequence_pattern("t%04d_%d.obj", ".obj", "/outputs/3");
    FAIL() << "two fields accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "/outputs/3/path: expected at most one frame-number field, #### or \"%d\" / \"%0Nd\" (at most 18 "
              "digits), in the file name, got \"t%04d_%d.obj\"");
  }
  EXPECT_THROW(sequence_pattern("t%s.obj", ".obj", ""), InputError);
}

TEST_F(ObjPc2, Pc2CacheAndRestObj) {
  const TreeModel m = small_model();
  test::bake({test::output("pc2", "cache/tree.pc2", 2)}, dir_, m, small_info(6, 4));
  EXPECT_EQ(entries(), (std::vector<std::string>{"cache", "cache/tree.pc2", "cache/tree.rest.mtl", "cache/tree.rest.obj"}));
  const test::ObjMesh rest = test::parse_obj(dir_ / "cache/tree.rest.obj");
  EXPECT_EQ(rest.positions, test::rest_f32(m));
  expect_topology(rest, m, "tree.rest.mtl");

  const std::string bytes = test::read_file(dir_ / "cache/tree.pc2");
  ASSERT_EQ(bytes.size(), 32u + 3 * 6 * 3 * 4);  // frames 4, 6, 8
  EXPECT_EQ(std::memcmp(bytes.data(), "POINTCACHE2\0", 12), 0);
  auto u32 = [&](size_t offset) {
    const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + offset);
    return uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
  };
  auto f32 = [&](size_t offset) { return std::bit_cast<float>(u32(offset)); };
  EXPECT_EQ(u32(12), 1u);   // version
  EXPECT_EQ(u32(16), 6u);   // points
  EXPECT_EQ(f32(20), 4.0f);  // start frame
  EXPECT_EQ(f32(24), 2.0f);  // sample rate
  EXPECT_EQ(u32(28), 3u);   // samples
  for (size_t k = 0; k < 3; ++k) {
    const FrameData expected = small_frame(m, 4 + 2 * long(k));
    for (size_t i = 0; i < 18; ++i) EXPECT_EQ(f32(32 + 4 * (18 * k + i)), expected.positions[i]);
  }
}

// MDD, big-endian: int32 frames, int32 points, float32 time of each frame, then the frames.
TEST_F(ObjPc2, MddCacheAndRestObj) {
  const TreeModel m = small_model();
  test::bake({test::output("mdd", "cache/tree", 2)}, dir_, m, small_info(6, 4));
  EXPECT_EQ(entries(), (std::vector<std::string>{"cache", "cache/tree.mdd", "cache/tree.rest.mtl", "cache/tree.rest.obj"}));
  const test::ObjMesh rest = test::parse_obj(dir_ / "cache/tree.rest.obj");
  EXPECT_EQ(rest.positions, test::rest_f32(m));
  expect_topology(rest, m, "tree.rest.mtl");

  const std::string bytes = test::read_file(dir_ / "cache/tree.mdd");
  ASSERT_EQ(bytes.size(), 8u + 3 * 4 + 3 * 6 * 3 * 4);  // frames 4, 6, 8
  auto u32 = [&](size_t offset) {
    const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + offset);
    return uint32_t(b[0]) << 24 | uint32_t(b[1]) << 16 | uint32_t(b[2]) << 8 | uint32_t(b[3]);
  };
  auto f32 = [&](size_t offset) { return std::bit_cast<float>(u32(offset)); };
  EXPECT_EQ(u32(0), 3u);  // frames
  EXPECT_EQ(u32(4), 6u);  // points
  for (size_t k = 0; k < 3; ++k) {
    const FrameData expected = small_frame(m, 4 + 2 * long(k));
    EXPECT_EQ(f32(8 + 4 * k), float(expected.time));
    for (size_t i = 0; i < 18; ++i) EXPECT_EQ(f32(20 + 4 * (18 * k + i)), expected.positions[i]);
  }
}

// "normals": a "vn" line per vertex in the rest OBJ and every frame, faces "v/vt/vn".
TEST_F(ObjPc2, ObjSequenceWithNormals) {
  const TreeModel m = small_model();
  OutputOptions o = test::output("obj", "obj/tree");
  o.normals = true;
  test::bake({o}, dir_, m, small_info(2, 0));
  std::vector<float> expected;
  vertex_normals(m, small_frame(m, 1).positions.data(), rest_normals(m), expected);
  const std::string text = test::read_file(dir_ / "obj/tree.0001.obj");
  std::vector<float> read;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("vn ", 0) == 0) {
      std::istringstream fields(line.substr(3));
      for (float x; fields >> x;) read.push_back(x);
    }
  }
  EXPECT_EQ(read, expected);
  EXPECT_NE(text.find("\nf 2/2/2 3/3/3 1/1/1\n"), std::string::npos);
  EXPECT_NE(test::read_file(dir_ / "obj/tree.rest.obj").find("\nvn "), std::string::npos);
}

TEST_F(ObjPc2, Pc2PathGetsItsExtension) {
  const TreeModel m = small_model();
  test::bake({test::output("pc2", "tree")}, dir_, m, small_info(1, 0));
  EXPECT_EQ(entries(), (std::vector<std::string>{"tree.pc2", "tree.rest.mtl", "tree.rest.obj"}));
}

}  // namespace
}  // namespace treeanim
