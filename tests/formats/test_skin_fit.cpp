// build_skin and fit_joints: joints from clusters (merged into limbs under max_joints), weights
// from memberships, and rigid motions recovered exactly from a rigidly moved tree.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "formats/skin_fit.h"
#include "formats_test_support.h"

namespace treeanim {
namespace {

TEST(SkinFit, OneJointPerClusterWithMembershipShares) {
  const TreeModel m = test::small_model();
  const Skin skin = build_skin(m, m.cluster_count());
  ASSERT_EQ(skin.joint_count(), 2u);
  EXPECT_EQ(skin.joint_parent, (std::vector<int32_t>{-1, 0}));
  // Vertex 3 is in both clusters: half each; vertex 4 in the leaf only.
  EXPECT_EQ(skin.vertex_joints[3][0], 0);
  EXPECT_EQ(skin.vertex_joints[3][1], 1);
  EXPECT_EQ(skin.vertex_weights[3][0], 0.5f);
  EXPECT_EQ(skin.vertex_weights[3][1], 0.5f);
  EXPECT_EQ(skin.vertex_joints[4][0], 1);
  EXPECT_EQ(skin.vertex_weights[4][0], 1.0f);
  EXPECT_EQ(skin.vertex_weights[4][1], 0.0f);
}

TEST(SkinFit, MaxJointsMergesTheSmallestIntoItsParent) {
  const TreeModel m = test::small_model();
  const Skin skin = build_skin(m, 1);
  ASSERT_EQ(skin.joint_count(), 1u);
  EXPECT_EQ(skin.joint_parent, (std::vector<int32_t>{-1}));
  EXPECT_EQ(skin.joint_offsets, (std::vector<uint32_t>{0, 6}));  // every vertex once
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    EXPECT_EQ(skin.vertex_joints[v][0], 0);
    EXPECT_EQ(skin.vertex_weights[v][0], 1.0f);
  }
}

TEST(SkinFit, RigidMotionIsRecoveredAndSkinsExactly) {
  const TreeModel m = test::small_model();
  const Skin skin = build_skin(m, m.cluster_count());
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 0.5).normalized()).toRotationMatrix();
  const Eigen::Vector3d translation(0.2, -0.1, 0.05);
  std::vector<float> moved;
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    const Eigen::Vector3d p = rotation * m.rest_positions.col(long(v)) + translation;
    for (int a = 0; a < 3; ++a) moved.push_back(float(p[a]));
  }
  std::vector<RigidMotion> motions;
  fit_joints(skin, m, moved.data(), motions);
  ASSERT_EQ(motions.size(), 2u);
  for (const RigidMotion& motion : motions) {
    EXPECT_LT((motion.rotation - rotation).norm(), 1e-6);
    EXPECT_LT((motion.translation - translation).norm(), 1e-6);
    EXPECT_NEAR(motion.rotation.determinant(), 1.0, 1e-12);
  }
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    const Eigen::Vector3d expected(moved[3 * v], moved[3 * v + 1], moved[3 * v + 2]);
    EXPECT_LT((skinned_position(skin, m, motions, v) - expected).norm(), 1e-6);
  }
}

TEST(SkinFit, AMirroredClusterStillGetsARotation) {
  const TreeModel m = test::small_model();
  const Skin skin = build_skin(m, m.cluster_count());
  std::vector<float> mirrored;
  for (size_t v = 0; v < m.vertex_count(); ++v)
    for (int a = 0; a < 3; ++a) mirrored.push_back(float((a == 2 ? -1.0 : 1.0) * m.rest_positions(a, long(v))));
  std::vector<RigidMotion> motions;
  fit_joints(skin, m, mirrored.data(), motions);
  for (const RigidMotion& motion : motions) EXPECT_NEAR(motion.rotation.determinant(), 1.0, 1e-12);
}

}  // namespace
}  // namespace treeanim
