// Branch mesh: closed-form counts, outward winding, parallel transport, radii.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

#include "tree/build_tree_model.h"
#include "tree_test_util.h"

namespace treeanim {
namespace {

using test::SkeletonBuilder;

// Unit normal of triangle t (not normalised when degenerate).
Eigen::Vector3d triangle_normal(const TreeModel& m, size_t t) {
  const Eigen::Vector3d a = m.rest_positions.col(m.triangles[3 * t]);
  const Eigen::Vector3d b = m.rest_positions.col(m.triangles[3 * t + 1]);
  const Eigen::Vector3d c = m.rest_positions.col(m.triangles[3 * t + 2]);
  return (b - a).cross(c - a);
}

Eigen::Vector3d triangle_centroid(const TreeModel& m, size_t t) {
  return (m.rest_positions.col(m.triangles[3 * t]) + m.rest_positions.col(m.triangles[3 * t + 1]) +
          m.rest_positions.col(m.triangles[3 * t + 2])) / 3.0;
}

TEST(BranchMesh, ChainCountsMatchClosedForm) {
  for (int sides : {3, 5, 8}) {
    for (int n : {1, 2, 7}) {
      TreeOptions o;
      o.ring_sides = sides;
      const TreeModel m = build_tree_model(test::chain(n), o);
      // (n + 1) rings and one tip centre; two triangles per side per segment plus the cap fan.
      EXPECT_EQ(m.vertex_count(), size_t((n + 1) * sides + 1)) << sides << " sides, " << n;
      EXPECT_EQ(m.triangle_count(), size_t(2 * sides * n + sides)) << sides << " sides, " << n;
      EXPECT_EQ(m.cluster_count(), size_t(n));
    }
  }
}

TEST(BranchMesh, LateralGetsItsOwnBaseRingAtTheAttachment) {
  const Skeleton sk = test::small_tree();
  TreeOptions o;
  const TreeModel m = build_tree_model(sk, o);
  // Trunk: 4 rings + tip; lateral: 3 rings + tip; the leaves: 4 vertices each.
  EXPECT_EQ(m.vertex_count(), size_t(7 * 8 + 2 + 3 * 4));
  // The lateral (segment 3) base ring is centred on its start point (0, 1, 0).
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  int count = 0;
  for (size_t v = 0; v < m.vertex_count(); ++v)
    if (m.vertex_segment[v] == 3 && (m.rest_positions.col(v) - Eigen::Vector3d(0, 1, 0)).norm() < 0.1) {
      centre += m.rest_positions.col(v);
      ++count;
    }
  ASSERT_EQ(count, 8);
  EXPECT_LT((centre / 8 - Eigen::Vector3d(0, 1, 0)).norm(), 1e-12);
}

TEST(BranchMesh, WindingIsConsistentAndOutward) {
  SkeletonBuilder b;
  const int t0 = b.segment({0, 0, 0}, {0, 1, 0}, -1, false);
  const int t1 = b.extend(t0, {0.5, 1, 0.2});
  b.extend(t1, {-0.3, 0.8, 0.4});
  const int l0 = b.segment({0, 1, 0}, {0, 1.5, 0.8}, t0, false);
  b.extend(l0, {0.1, 0.2, 0.9});
  TreeOptions o;
  const TreeModel m = build_tree_model(b.sk, o);
  // Consistent orientation: no directed edge is used twice.
  std::map<std::pair<uint32_t, uint32_t>, int> edges;
  for (size_t t = 0; t < m.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) ++edges[{m.triangles[3 * t + k], m.triangles[3 * t + (k + 1) % 3]}];
  for (const auto& [edge, uses] : edges) EXPECT_EQ(uses, 1) << edge.first << "->" << edge.second;
  // Outward: a tube triangle faces away from its segment's axis line, a cap along the axis.
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    // The third corner of every branch triangle lies on its own segment's top ring or tip.
    const int s = m.vertex_segment[m.triangles[3 * t + 2]];
    const Eigen::Vector3d a = m.segment_start[s], d = (m.segment_end[s] - a).normalized();
    const Eigen::Vector3d c = triangle_centroid(m, t), n = triangle_normal(m, t);
    bool cap = false;
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = m.triangles[3 * t + k];
      cap |= m.vertex_segment[v] >= 0 && (m.rest_positions.col(v) - m.segment_end[m.vertex_segment[v]]).norm() < 1e-12;
    }
    if (cap) {
      EXPECT_GT(n.dot(d), 0) << "cap triangle " << t;
    } else {
      const Eigen::Vector3d radial = (c - a) - (c - a).dot(d) * d;
      EXPECT_GT(n.dot(radial), 0) << "tube triangle " << t;
    }
  }
}

TEST(BranchMesh, HelixRingsFollowByParallelTransportWithoutFlips) {
  // 3 turns of a helix (radius 1, pitch 1), 40 segments per turn.
  SkeletonBuilder b;
  auto point = [](int i) {
    const double a = 2 * std::numbers::pi * i / 40.0;
    return Eigen::Vector3d(std::cos(a), i / 40.0, std::sin(a));
  };
  int s = b.segment(point(0), point(1), -1, false, 0.1);
  for (int i = 1; i < 120; ++i) s = b.segment(point(i), point(i + 1), s, true, 0.1);
  TreeOptions o;
  const TreeModel m = build_tree_model(b.sk, o);
  // Ring j's vertex 0 direction from its centre; ring j > 0 is the top ring of segment j - 1.
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  double max_angle = 0;
  for (int j = 0; j <= 120; ++j) {
    const Eigen::Vector3d centre = j == 0 ? point(0) : point(j);
    const Eigen::Vector3d dir = (m.rest_positions.col(8 * j) - centre).normalized();
    if (j > 0) max_angle = std::max(max_angle, std::acos(std::clamp(dir.dot(previous), -1.0, 1.0)));
    // Every vertex of the ring stays at least the radius away from the axis: no pinching.
    const double radius = j == 0 ? m.segment_radius_base[0] : m.segment_radius_top[j - 1];
    for (int k = 0; k < 8; ++k) EXPECT_GE((m.rest_positions.col(8 * j + k) - centre).norm(), radius - 1e-12);
    previous = dir;
  }
  // The tangent turns by about 360/40 / sqrt(1 + 1/(2 pi)^2) ~ 8.9 degrees per segment; a
  // Bishop frame rotates by no more than that, a flip or a spin about the axis by far more.
  EXPECT_LT(max_angle * 180 / std::numbers::pi, 9.5);
  EXPECT_GT(max_angle * 180 / std::numbers::pi, 1.0);
}

TEST(BranchMesh, AxisFramesAreSeededFromTheTurtleUp) {
  SkeletonBuilder b;
  const int t = b.segment({0, 0, 0}, {0, 1, 0}, -1, false, 0.2, {0, 0, 1});
  // A lateral along +x whose turtle U is tilted: the ring starts at U made perpendicular.
  b.segment({0, 1, 0}, {1, 1, 0}, t, false, 0.1, Eigen::Vector3d(0.6, 0.8, 0));
  const TreeModel m = build_tree_model(b.sk, TreeOptions{});
  EXPECT_LT((m.rest_positions.col(0) - Eigen::Vector3d(0, 0, 0.1)).norm(), 1e-12);
  // Trunk: base ring 0..7, top ring 8..15, tip 16; the lateral's base ring starts at 17.
  EXPECT_LT((m.rest_positions.col(17) - Eigen::Vector3d(0, 1.05, 0)).norm(), 1e-12);
  // Vertex 2 is a quarter turn counter-clockwise about the axis: T x N = (1,0,0) x (0,1,0).
  EXPECT_LT((m.rest_positions.col(19) - Eigen::Vector3d(0, 1, 0.05)).norm(), 1e-12);
}

TEST(BranchMesh, UvsRunAroundAndAlongInMetres) {
  TreeOptions o;
  o.scale = 0.5;
  const TreeModel m = build_tree_model(test::chain(3), o);
  for (int ring = 0; ring < 4; ++ring)
    for (int k = 0; k < 8; ++k) {
      EXPECT_FLOAT_EQ(m.uvs(0, 8 * ring + k), k / 8.0f);
      EXPECT_FLOAT_EQ(m.uvs(1, 8 * ring + k), 0.5f * ring);
    }
}

TEST(BranchRadii, WidthsGiveDiametersTimesScale) {
  TreeOptions o;
  o.scale = 2.0;
  const TreeModel m = build_tree_model(test::small_tree(), o);
  EXPECT_DOUBLE_EQ(m.segment_radius_base[0], 0.2);
  EXPECT_DOUBLE_EQ(m.segment_radius_top[0], 0.15);  // base of the continuation
  EXPECT_DOUBLE_EQ(m.segment_radius_base[3], 0.08);
  EXPECT_DOUBLE_EQ(m.segment_radius_top[4], 0.05 * o.tip_taper);  // tip
  // The trunk's base ring lies at the base radius.
  EXPECT_NEAR(m.rest_positions.col(0).norm(), 0.2, 1e-12);
}

TEST(BranchRadii, WidthScaleMultipliesOnlyTheWidths) {
  TreeOptions o;
  o.scale = 2.0;
  o.width_scale = 0.5;
  const TreeModel m = build_tree_model(test::small_tree(), o);
  EXPECT_DOUBLE_EQ(m.segment_radius_base[0], 0.1);
  EXPECT_DOUBLE_EQ(m.segment_radius_base[3], 0.04);
  // Lengths keep `scale` alone.
  const TreeModel unscaled = build_tree_model(test::small_tree(), TreeOptions{});
  EXPECT_DOUBLE_EQ((m.segment_end[0] - m.segment_start[0]).norm(),
                   2.0 * (unscaled.segment_end[0] - unscaled.segment_start[0]).norm());
}

TEST(BranchRadii, PipeModelWithoutWidths) {
  // Trunk t0 => continuation t1 and two laterals; pipe exponent 2.5.
  SkeletonBuilder b;
  const int t0 = b.segment({0, 0, 0}, {0, 1, 0}, -1, false);
  const int t1 = b.extend(t0, {0, 1, 0});
  const int a = b.segment({0, 1, 0}, {1, 1, 0}, t0, false);
  b.extend(a, {1, 0, 0});
  b.segment({0, 1, 0}, {-1, 1, 0}, t0, false);
  TreeOptions o;
  o.pipe_exponent = 2.5;
  o.trunk_radius = 0.3;
  o.min_radius = 1e-4;
  const TreeModel m = build_tree_model(b.sk, o);
  const auto& r = m.segment_radius_base;
  EXPECT_DOUBLE_EQ(r[0], 0.3);
  const double k = o.pipe_exponent;
  EXPECT_NEAR(std::pow(r[t0], k), std::pow(r[t1], k) + std::pow(r[a], k) + std::pow(r[4], k), 1e-12);
  // Lateral a + its continuation run to the tip: the radius falls linearly towards
  // tip_taper * r[a] over the run (two unit segments).
  EXPECT_NEAR(r[3], r[a] * (1 - 0.5 * (1 - o.tip_taper)), 1e-12);
  EXPECT_NEAR(m.segment_radius_top[3], r[3] * o.tip_taper, 1e-12);
  EXPECT_DOUBLE_EQ(m.segment_radius_top[t0], r[t1]);
  // Clamping: a large minimum wins everywhere.
  o.min_radius = 0.25;
  const TreeModel clamped = build_tree_model(b.sk, o);
  for (size_t s = 0; s < clamped.segment_count(); ++s) {
    EXPECT_GE(clamped.segment_radius_base[s], 0.25);
    EXPECT_GE(clamped.segment_radius_top[s], 0.25);
  }
}

}  // namespace
}  // namespace treeanim
