#pragma once
// Hand-built Skeletons for the tree tests (independent of the L-system parser).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <vector>

#include "lsystem/skeleton.h"
#include "tree/tree_model.h"

namespace treeanim::test {

constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();

struct SkeletonBuilder {
  Skeleton sk;

  SkeletonBuilder() {
    sk.leaf_polygon_offsets = {0};
    sk.leaf_triangle_offsets = {0};
  }

  // One segment start => end; continues: same axis as the parent. => segment index.
  int segment(const Eigen::Vector3d& start, const Eigen::Vector3d& end, int parent, bool continues,
              double width = kUnset, const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ()) {
    sk.segment_start.push_back(start);
    sk.segment_end.push_back(end);
    sk.segment_up.push_back(up);
    sk.segment_width.push_back(width);
    sk.segment_parent.push_back(parent);
    sk.segment_continues_parent.push_back(continues ? 1 : 0);
    sk.segment_order.push_back(parent < 0 ? 0 : sk.segment_order[parent] + (continues ? 0 : 1));
    sk.segment_id.push_back(uint32_t(sk.segment_id.size()));
    sk.segment_material.push_back(0);
    return int(sk.segment_start.size()) - 1;
  }

  // Continues segment `parent` by `step` from its end.
  int extend(int parent, const Eigen::Vector3d& step, double width = kUnset) {
    const Eigen::Vector3d start = sk.segment_end[parent];
    return segment(start, start + step, parent, true, width);
  }

  // A leaf at `position` with turtle frame H, L (U = H x L); optional '{ . }' outline, or the
  // points of a mesh with its triangles (ids into those points).
  int leaf(int seg, const Eigen::Vector3d& position, const Eigen::Vector3d& heading,
           const Eigen::Vector3d& left, double scale = 1.0,
           const std::vector<Eigen::Vector3d>& outline = {}, const std::vector<uint32_t>& triangles = {}) {
    sk.leaf_segment.push_back(seg);
    sk.leaf_position.push_back(position);
    sk.leaf_heading.push_back(heading);
    sk.leaf_left.push_back(left);
    sk.leaf_up.push_back(heading.cross(left));
    sk.leaf_scale.push_back(scale);
    sk.polygon_points.insert(sk.polygon_points.end(), outline.begin(), outline.end());
    sk.leaf_polygon_offsets.push_back(uint32_t(sk.polygon_points.size()));
    sk.leaf_triangles.insert(sk.leaf_triangles.end(), triangles.begin(), triangles.end());
    sk.leaf_triangle_offsets.push_back(uint32_t(sk.leaf_triangles.size()));
    return int(sk.leaf_position.size()) - 1;
  }
};

// A straight vertical chain of n unit segments from the origin.
inline Skeleton chain(int n, double width = kUnset) {
  SkeletonBuilder b;
  int s = b.segment({0, 0, 0}, {0, 1, 0}, -1, false, width);
  for (int i = 1; i < n; ++i) s = b.extend(s, {0, 1, 0}, width);
  return b.sk;
}

// Trunk of 3 segments, a lateral of 2 segments at the end of the first, one leaf on each
// trunk segment and one on the lateral tip.
inline Skeleton small_tree() {
  SkeletonBuilder b;
  const int t0 = b.segment({0, 0, 0}, {0, 1, 0}, -1, false, 0.2);
  const int t1 = b.extend(t0, {0, 1, 0}, 0.15);
  b.extend(t1, {0.2, 1, 0}, 0.1);
  const int l0 = b.segment({0, 1, 0}, {0.7, 1.7, 0}, t0, false, 0.08);
  const int l1 = b.extend(l0, {0.6, 0.3, 0.1}, 0.05);
  const Eigen::Vector3d h(1, 0, 0), left(0, 0, 1);
  b.leaf(t0, {0, 0.5, 0}, h, left);
  b.leaf(t1, {0, 1.5, 0}, h, left, 2.0);
  b.leaf(l1, b.sk.segment_end[l1], Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(-1, 0, 0));
  return b.sk;
}

// Cluster c => the mass of its members that are not anchored (kg).
inline double free_cluster_mass(const TreeModel& model, size_t c) {
  double mass = 0;
  for (uint32_t s = model.cluster_offsets[c]; s < model.cluster_offsets[c + 1]; ++s)
    if (!model.vertex_anchored[model.cluster_members[s]]) mass += model.vertex_mass[model.cluster_members[s]];
  return mass;
}

}  // namespace treeanim::test
