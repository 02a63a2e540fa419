// Masses (paper Eq. 9), anchors and drag areas.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <numeric>

#include "tree/build_tree_model.h"
#include "tree_test_util.h"

namespace treeanim {
namespace {

// Sum of vertex_mass over branch (or leaf) vertices.
double total_mass(const TreeModel& m, bool leaves) {
  double sum = 0;
  for (size_t v = 0; v < m.vertex_count(); ++v)
    if ((m.vertex_leaf[v] >= 0) == leaves) sum += m.vertex_mass[v];
  return sum;
}

// density * sum over segments of pi/3 (rt^2 + rt rb + rb^2) l, written out independently.
double expected_wood_mass(const TreeModel& m, double density) {
  double volume = 0;
  for (size_t s = 0; s < m.segment_count(); ++s) {
    const double rb = m.segment_radius_base[s], rt = m.segment_radius_top[s];
    const double l = (m.segment_end[s] - m.segment_start[s]).norm();
    volume += std::numbers::pi / 3 * (rt * rt + rt * rb + rb * rb) * l;
  }
  return density * volume;
}

TEST(TreeMasses, BranchMassIsDensityTimesTruncatedConeVolumes) {
  for (int per_cluster : {1, 2, 3}) {
    TreeOptions o;
    o.wood_density = 650;
    o.cluster.segments_per_cluster = per_cluster;
    const TreeModel m = build_tree_model(test::small_tree(), o);
    const double expected = expected_wood_mass(m, 650);
    EXPECT_NEAR(total_mass(m, false), expected, 1e-9 * expected) << per_cluster;
  }
}

TEST(TreeMasses, SharedVerticesSumTheirShares) {
  const TreeModel m = build_tree_model(test::chain(2, 0.2), TreeOptions{});
  // Cluster 0 (17 - 1 = 16 ring vertices), cluster 1 (16 + tip = 17); the joint ring has both.
  const double r0 = 0.1, r1 = 0.1 * 0.5;
  const double m0 = 700 * std::numbers::pi / 3 * 3 * r0 * r0;
  const double m1 = 700 * std::numbers::pi / 3 * (r1 * r1 + r1 * r0 + r0 * r0);
  EXPECT_NEAR(m.vertex_mass[0], m0 / 16, 1e-15);
  EXPECT_NEAR(m.vertex_mass[8], m0 / 16 + m1 / 17, 1e-15);
  EXPECT_NEAR(m.vertex_mass[16], m1 / 17, 1e-15);
  EXPECT_NEAR(test::free_cluster_mass(m, 0), 8 * m.vertex_mass[8], 1e-15);  // the anchored ring is excluded
}

TEST(TreeMasses, ThinnerBranchHasLighterVertices) {
  test::SkeletonBuilder b;
  const int t = b.segment({0, 0, 0}, {0, 1, 0}, -1, false, 0.3);
  const int thick = b.segment({0, 1, 0}, {1, 1, 0}, t, false, 0.2);
  const int thin = b.segment({0, 1, 0}, {-1, 1, 0}, t, false, 0.1);
  const TreeModel m = build_tree_model(b.sk, TreeOptions{});
  // The tip vertices are in the lateral's cluster only, so they carry one share each.
  const uint32_t thick_tip = m.cluster_members[m.cluster_offsets[m.segment_cluster[thick] + 1] - 1];
  const uint32_t thin_tip = m.cluster_members[m.cluster_offsets[m.segment_cluster[thin] + 1] - 1];
  ASSERT_EQ(m.vertex_segment[thick_tip], thick);
  ASSERT_EQ(m.vertex_segment[thin_tip], thin);
  EXPECT_LT(m.vertex_mass[thin_tip], m.vertex_mass[thick_tip]);
  EXPECT_LT(test::free_cluster_mass(m, m.segment_cluster[thin]), test::free_cluster_mass(m, m.segment_cluster[thick]));
}

TEST(TreeMasses, TrunkBaseRingIsAnchored) {
  const TreeModel m = build_tree_model(test::small_tree(), TreeOptions{});
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    const bool base = v < 8;
    EXPECT_EQ(m.vertex_anchored[v], base ? 1 : 0) << v;
  }
}

TEST(TreeMasses, LeafMassAndDragAreaComeFromTheBladeArea) {
  TreeOptions o;
  o.leaf.size = 0.1;
  o.leaf.aspect = 0.6;
  o.leaf.areal_density = 0.2;
  const Skeleton sk = test::small_tree();
  const TreeModel m = build_tree_model(sk, o);
  for (size_t l = 0; l < m.leaf_count(); ++l) {
    const double s = sk.leaf_scale[l];
    const double area = 0.5 * 0.1 * 0.06 * s * s;  // rhombus: half the product of its diagonals
    double mass = 0, drag = 0;
    for (size_t v = 0; v < m.vertex_count(); ++v)
      if (m.vertex_leaf[v] == int32_t(l)) {
        mass += m.vertex_mass[v];
        drag += m.vertex_drag_area[v];
      }
    EXPECT_NEAR(mass, 0.2 * area, 1e-15) << l;
    EXPECT_NEAR(drag, area, 1e-15) << l;
  }
  // Branch drag area: 2 * mean radius * length per segment, all of it on branch vertices.
  double expected = 0, drag = 0;
  for (size_t s = 0; s < m.segment_count(); ++s)
    expected += (m.segment_radius_base[s] + m.segment_radius_top[s]) * (m.segment_end[s] - m.segment_start[s]).norm();
  for (size_t v = 0; v < m.vertex_count(); ++v)
    if (m.vertex_leaf[v] < 0) drag += m.vertex_drag_area[v];
  EXPECT_NEAR(drag, expected, 1e-12);
}

// tree.drag_share scales every part's drag area, leaves' and branches', and no mass.
TEST(TreeMasses, TheDragShareScalesEveryPartsDragAndNoMass) {
  TreeOptions o;
  const Skeleton sk = test::small_tree();
  const TreeModel whole = build_tree_model(sk, o);
  o.drag_share = 0.25;
  const TreeModel shared = build_tree_model(sk, o);
  ASSERT_GT(whole.leaf_count(), 0u);
  for (size_t v = 0; v < whole.vertex_count(); ++v) {
    EXPECT_NEAR(shared.vertex_drag_area[v], 0.25 * whole.vertex_drag_area[v], 1e-15 + 1e-15 * whole.vertex_drag_area[v]);
    EXPECT_EQ(shared.vertex_mass[v], whole.vertex_mass[v]);
  }
}

}  // namespace
}  // namespace treeanim
