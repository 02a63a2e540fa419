// Leaves: default quad, '{ . }' outlines, custom meshes through assimp, the turtle's meshes.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "common/errors.h"
#include "tree/build_tree_model.h"
#include "tree_test_util.h"

namespace treeanim {
namespace {

const std::filesystem::path kLeafObj = std::filesystem::path(TREEANIM_SOURCE_DIR) / "tests/data/leaf_hexagon.obj";

// Vertices of leaf l, in order.
std::vector<uint32_t> leaf_vertices(const TreeModel& m, int l) {
  std::vector<uint32_t> out;
  for (uint32_t v = 0; v < m.vertex_count(); ++v)
    if (m.vertex_leaf[v] == l) out.push_back(v);
  return out;
}

// Sum of the unnormalised normals of the triangles of leaf l.
Eigen::Vector3d leaf_normal(const TreeModel& m, int l) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    const uint32_t a = m.triangles[3 * t], b = m.triangles[3 * t + 1], c = m.triangles[3 * t + 2];
    if (m.vertex_leaf[a] != l) continue;
    n += (m.rest_positions.col(b) - m.rest_positions.col(a)).cross(m.rest_positions.col(c) - m.rest_positions.col(a));
  }
  return n;
}

TEST(TreeLeaves, DefaultQuadFollowsTheTurtleFrame) {
  TreeOptions o;
  o.leaf.size = 0.1;
  o.leaf.aspect = 0.5;
  o.leaf.petiole = 0.02;
  const Skeleton sk = test::small_tree();
  const TreeModel m = build_tree_model(sk, o);
  ASSERT_EQ(m.leaf_count(), 3u);
  for (int l = 0; l < 3; ++l) {
    const auto vs = leaf_vertices(m, l);
    ASSERT_EQ(vs.size(), 4u);
    const double s = sk.leaf_scale[l];
    const Eigen::Vector3d p = sk.leaf_position[l], h = sk.leaf_heading[l], left = sk.leaf_left[l];
    // base, right (-L), tip, left (+L)
    EXPECT_LT((m.rest_positions.col(vs[0]) - (p + 0.02 * s * h)).norm(), 1e-12);
    EXPECT_LT((m.rest_positions.col(vs[1]) - (p + 0.07 * s * h - 0.025 * s * left)).norm(), 1e-12);
    EXPECT_LT((m.rest_positions.col(vs[2]) - (p + 0.12 * s * h)).norm(), 1e-12);
    EXPECT_LT((m.rest_positions.col(vs[3]) - (p + 0.07 * s * h + 0.025 * s * left)).norm(), 1e-12);
    EXPECT_EQ(m.leaf_attachment_vertex[l], vs[0]);
    EXPECT_GT(leaf_normal(m, l).dot(sk.leaf_up[l]), 0);  // the front faces U
  }
}

TEST(TreeLeaves, PolygonOutlineIsFanTriangulatedFacingUp) {
  test::SkeletonBuilder b;
  const int s = b.segment({0, 0, 0}, {0, 1, 0}, -1, false);
  const Eigen::Vector3d h(1, 0, 0), left(0, 0, -1);  // U = H x L = (0, 1, 0)
  // Wound clockwise seen from U, so the mesher has to flip it.
  const std::vector<Eigen::Vector3d> outline = {{0.1, 1, 0}, {0.3, 1, -0.1}, {0.5, 1, 0}, {0.3, 1, 0.1}, {0.2, 1, 0.08}};
  b.leaf(s, {0, 1, 0}, h, left, 1.0, outline);
  const TreeModel m = build_tree_model(b.sk, TreeOptions{});
  const auto vs = leaf_vertices(m, 0);
  ASSERT_EQ(vs.size(), 5u);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(Eigen::Vector3d(m.rest_positions.col(vs[i])), outline[i]);
  size_t leaf_triangles = 0;
  for (size_t t = 0; t < m.triangle_count(); ++t) leaf_triangles += m.vertex_leaf[m.triangles[3 * t]] == 0;
  EXPECT_EQ(leaf_triangles, 3u);
  EXPECT_GT(leaf_normal(m, 0).dot(b.sk.leaf_up[0]), 0);
  EXPECT_EQ(m.leaf_attachment_vertex[0], vs[0]);  // nearest the leaf position (0, 1, 0)
}

// A mesh the turtle placed (a cpfg surface, sphere or circle): its points and triangles as they
// are, its area the triangles' sum, its attachment the point at the leaf position.
TEST(TreeLeaves, TurtleMeshKeepsItsTrianglesAndAttachesAtTheLeafPosition) {
  test::SkeletonBuilder b;
  const int s = b.segment({0, 0, 0}, {0, 1, 0}, -1, false);
  const Eigen::Vector3d h(0, 1, 0), left(-1, 0, 0);  // U = (0, 0, 1)
  // A unit square standing on the leaf position (its second point), two triangles facing U.
  const std::vector<Eigen::Vector3d> points = {{-0.5, 1, 0}, {0, 1, 0}, {0.5, 1, 0}, {0.5, 2, 0}, {-0.5, 2, 0}};
  b.leaf(s, {0, 1, 0}, h, left, 1.0, points, {0, 2, 3, 0, 3, 4});
  TreeOptions o;
  o.scale = 2.0;
  const TreeModel m = build_tree_model(b.sk, o);
  const auto vs = leaf_vertices(m, 0);
  ASSERT_EQ(vs.size(), 5u);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(Eigen::Vector3d(m.rest_positions.col(vs[i])), 2.0 * points[i]);
  size_t leaf_triangles = 0;
  for (size_t t = 0; t < m.triangle_count(); ++t) leaf_triangles += m.vertex_leaf[m.triangles[3 * t]] == 0;
  EXPECT_EQ(leaf_triangles, 2u);
  EXPECT_NEAR(leaf_normal(m, 0).z(), 2 * 4.0, 1e-12);  // area 4 m^2 after the scale, facing U
  EXPECT_EQ(m.leaf_attachment_vertex[0], vs[1]);
  EXPECT_NEAR(m.cluster_length[m.leaf_cluster[0]], 2.0, 1e-12);  // extent along H
  EXPECT_NEAR(m.vertex_drag_area[vs[0]] * 5, 4.0, 1e-12);       // the area spread over its 5 points
}

TEST(TreeLeaves, CustomObjMeshIsInstancedOnEveryLeaf) {
  TreeOptions o;
  o.leaf.mesh = kLeafObj;
  o.leaf.size = 0.1;  // the hexagon is 2 long: scale 0.05
  o.leaf.petiole = 0.0;
  const Skeleton sk = test::small_tree();
  const TreeModel m = build_tree_model(sk, o);
  // OBJ corners in the leaf frame: x towards -L, y along H, z along U.
  const std::vector<Eigen::Vector3d> corners = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 1.5, 0}, {0, 2, 0}, {-0.5, 1.5, 0}, {-0.5, 0.5, 0}};
  ASSERT_EQ(m.leaf_count(), 3u);
  for (int l = 0; l < 3; ++l) {
    const auto vs = leaf_vertices(m, l);
    ASSERT_EQ(vs.size(), 6u) << "assimp's per-face vertices must be joined";
    const double s = 0.05 * sk.leaf_scale[l];
    const Eigen::Vector3d p = sk.leaf_position[l];
    for (const Eigen::Vector3d& c : corners) {
      const Eigen::Vector3d expected = p + s * (-c.x() * sk.leaf_left[l] + c.y() * sk.leaf_heading[l] + c.z() * sk.leaf_up[l]);
      double nearest = 1e9;
      for (uint32_t v : vs) nearest = std::min(nearest, (m.rest_positions.col(v) - expected).norm());
      EXPECT_LT(nearest, 1e-7) << "leaf " << l;
    }
    EXPECT_LT((m.rest_positions.col(m.leaf_attachment_vertex[l]) - p).norm(), 1e-12);
    EXPECT_GT(leaf_normal(m, l).dot(sk.leaf_up[l]), 0);
    size_t leaf_triangles = 0;
    for (size_t t = 0; t < m.triangle_count(); ++t) leaf_triangles += m.vertex_leaf[m.triangles[3 * t]] == l;
    EXPECT_EQ(leaf_triangles, 4u);
  }
}

// A model without its surface (a samples bake that writes nothing) has every other array of the
// model with it, to the bit: the leaves' lengths and attachments too, which the outlines and the
// turtle's meshes take from the points whose UVs they no longer write.
TEST(TreeLeaves, WithoutTheSurfaceEveryOtherArrayIsTheSame) {
  test::SkeletonBuilder b;
  const int s = b.segment({0, 0, 0}, {0, 1, 0}, -1, false);
  const int top = b.extend(s, {0.1, 1, 0});
  const Eigen::Vector3d h(1, 0, 0), left(0, 0, -1);
  b.leaf(s, {0, 1, 0}, h, left, 1.0, {{0.1, 1, 0}, {0.3, 1, -0.1}, {0.5, 1, 0}, {0.3, 1, 0.1}, {0.2, 1, 0.08}});
  b.leaf(top, {0.1, 2, 0}, {0, 1, 0}, {-1, 0, 0}, 1.0,
         {{-0.4, 2, 0}, {0.1, 2, 0}, {0.6, 2, 0}, {0.6, 2.7, 0}, {-0.4, 2.9, 0}}, {0, 2, 3, 0, 3, 4});
  b.leaf(top, {0.1, 2, 0}, h, left, 0.5);
  TreeOptions o;
  o.scale = 0.7;
  const TreeModel whole = build_tree_model(b.sk, o);
  const TreeModel bare = build_tree_model(b.sk, o, MeshSurface::kOmitted);
  ASSERT_EQ(whole.triangle_count(), 5u * uint32_t(o.ring_sides) + 3 + 2 + 2);  // two tubes and a cap; the leaves
  EXPECT_EQ(bare.uvs.cols(), 0);
  EXPECT_TRUE(bare.triangles.empty());
  EXPECT_TRUE(bare.triangle_material.empty());
  EXPECT_TRUE(bare.rest_positions.cwiseEqual(whole.rest_positions).all());
  EXPECT_EQ(bare.vertex_segment, whole.vertex_segment);
  EXPECT_EQ(bare.vertex_leaf, whole.vertex_leaf);
  EXPECT_EQ(bare.vertex_mass, whole.vertex_mass);
  EXPECT_EQ(bare.vertex_anchored, whole.vertex_anchored);
  EXPECT_EQ(bare.vertex_drag_area, whole.vertex_drag_area);
  EXPECT_EQ(bare.cluster_offsets, whole.cluster_offsets);
  EXPECT_EQ(bare.cluster_members, whole.cluster_members);
  EXPECT_EQ(bare.cluster_kind, whole.cluster_kind);
  EXPECT_EQ(bare.cluster_leaf, whole.cluster_leaf);
  EXPECT_EQ(bare.cluster_parent, whole.cluster_parent);
  EXPECT_EQ(bare.cluster_length, whole.cluster_length);
  EXPECT_EQ(bare.cluster_radius, whole.cluster_radius);
  EXPECT_EQ(bare.vertex_cluster_offsets, whole.vertex_cluster_offsets);
  EXPECT_EQ(bare.vertex_memberships, whole.vertex_memberships);
  EXPECT_EQ(bare.member_cluster, whole.member_cluster);
  EXPECT_EQ(bare.leaf_cluster, whole.leaf_cluster);
  EXPECT_EQ(bare.leaf_attachment_vertex, whole.leaf_attachment_vertex);
  EXPECT_EQ(bare.segment_start, whole.segment_start);
  EXPECT_EQ(bare.segment_end, whole.segment_end);
  EXPECT_EQ(bare.segment_radius_base, whole.segment_radius_base);
  EXPECT_EQ(bare.segment_radius_top, whole.segment_radius_top);
  EXPECT_EQ(bare.segment_parent, whole.segment_parent);
  EXPECT_EQ(bare.segment_cluster, whole.segment_cluster);
  // The lengths the outline and the mesh took from their points' v: 0.4 and 0.9 along H (x 0.7).
  EXPECT_NEAR(bare.cluster_length[bare.leaf_cluster[0]], 0.7 * 0.4, 1e-7);
  EXPECT_NEAR(bare.cluster_length[bare.leaf_cluster[1]], 0.7 * 0.9, 1e-7);
}

TEST(TreeLeaves, UnreadableMeshIsAnInputErrorNamingTheFile) {
  TreeOptions o;
  o.leaf.mesh = std::filesystem::path(TREEANIM_SOURCE_DIR) / "tests/data/no_such_leaf.obj";
  try {
    build_tree_model(test::small_tree(), o);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_leaf.obj: cannot read leaf mesh"), std::string::npos) << e.what();
  }
}

// Damaged meshes are refused with the file's name before the importer's triangulation reads
// them (a PLY cut short crashed it; a binary PLY's index past its points made it read
// anywhere; a NaN point reached the bake).
TEST(TreeLeaves, DamagedMeshIsAnInputErrorNamingTheFile) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("treeanim_damaged_leaf_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string ply_header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const std::pair<std::string, std::string> files[] = {
      {"short.ply", ply_header + "0 0 0\n"},
      {"index.ply", ply_header + "0 0 0\n0 1 0\n1 1 0\n3 0 1 2000000000\n"},
      {"twice.ply", ply_header + "0 0 0\n0 1 0\n1 1 0\n4 0 1 1 2\n"},
      {"nan.obj", "v 0 0 0\nv 0 1 0\nv nan 1 0\nf 1 2 3\n"},
      // A header cut short: assimp's reader sought round for ever.
      {"headless.ply", "ply\nformat ascii 1.0\n"},
      {"headless-element.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"},
  };
  for (const auto& [name, text] : files) {
    std::ofstream(dir / name) << text;
    TreeOptions o;
    o.leaf.mesh = dir / name;
    try {
      build_tree_model(test::small_tree(), o);
      ADD_FAILURE() << name << ": expected InputError";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(name + ": "), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("leaf mesh"), std::string::npos) << e.what();
    }
  }
  // What a valid file may hold besides its triangles still loads: a line, and a triangle with a
  // corner twice (no area), as they did before the checks.
  std::ofstream(dir / "lines.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 2\nl 1 2\n";
  TreeOptions o;
  o.leaf.mesh = dir / "lines.obj";
  EXPECT_GT(build_tree_model(test::small_tree(), o).leaf_count(), 0u);
  std::filesystem::remove_all(dir);
}

// A leaf mesh is joined at unit size, whatever its file's units: a triangle modelled 1e-5 or
// 1e-7 across keeps its three corners, as one 1 across does (assimp joined points closer than
// 1e-5 in the file's units, so the small ones lost a corner, or were refused as of no extent).
TEST(TreeLeaves, AMeshKeepsItsCornersAtAnySize) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("treeanim_small_leaf_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  size_t vertices = 0;
  for (const char* size : {"1", "1e-5", "1e-7"}) {
    std::ofstream(dir / "t.obj") << "v 0 0 0\nv " << size << " 0 0\nv 0 " << size << " 0\nf 1 2 3\n";
    TreeOptions o;
    o.leaf.mesh = dir / "t.obj";
    const TreeModel model = build_tree_model(test::small_tree(), o);
    if (vertices == 0) vertices = model.vertex_count();
    EXPECT_EQ(model.vertex_count(), vertices) << size;
    for (size_t t = 0; t < model.triangle_count(); ++t) {
      const uint32_t* corner = &model.triangles[3 * t];
      EXPECT_TRUE(corner[0] != corner[1] && corner[1] != corner[2] && corner[0] != corner[2]) << size;
    }
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace treeanim
