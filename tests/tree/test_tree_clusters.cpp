// Clusters: coverage, overlaps at joints, laterals and leaves, merging, CSR gather order.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "tree/build_tree_model.h"
#include "tree_test_util.h"

namespace treeanim {
namespace {

// Clusters that vertex v belongs to, read through the vertex CSR.
std::vector<uint32_t> clusters_of(const TreeModel& m, uint32_t v) {
  std::vector<uint32_t> out;
  for (uint32_t i = m.vertex_cluster_offsets[v]; i < m.vertex_cluster_offsets[v + 1]; ++i) {
    const uint32_t slot = m.vertex_memberships[i];
    const auto it = std::upper_bound(m.cluster_offsets.begin(), m.cluster_offsets.end(), slot);
    out.push_back(uint32_t(it - m.cluster_offsets.begin() - 1));
  }
  return out;
}

TEST(TreeClusters, EveryVertexIsInAClusterAndTheGatherIsOrdered) {
  const TreeModel m = build_tree_model(test::small_tree(), TreeOptions{});
  for (uint32_t v = 0; v < m.vertex_count(); ++v) {
    const auto cs = clusters_of(m, v);
    ASSERT_FALSE(cs.empty()) << v;
    EXPECT_TRUE(std::is_sorted(cs.begin(), cs.end()) && std::adjacent_find(cs.begin(), cs.end()) == cs.end());
    for (uint32_t i = m.vertex_cluster_offsets[v]; i < m.vertex_cluster_offsets[v + 1]; ++i) {
      EXPECT_EQ(m.cluster_members[m.vertex_memberships[i]], v);
      EXPECT_EQ(m.member_cluster[m.vertex_memberships[i]], cs[i - m.vertex_cluster_offsets[v]]) << v;
    }
  }
  for (size_t c = 0; c < m.cluster_count(); ++c)
    EXPECT_TRUE(std::is_sorted(m.cluster_members.begin() + m.cluster_offsets[c],
                               m.cluster_members.begin() + m.cluster_offsets[c + 1]));
}

TEST(TreeClusters, JointRingsAreInExactlyTheTwoSegmentClusters) {
  const TreeModel m = build_tree_model(test::chain(3), TreeOptions{});
  ASSERT_EQ(m.cluster_count(), 3u);
  // Rings 0..3, tip = 32. Ring 0 only in cluster 0; ring 1 in {0, 1}; ring 2 in {1, 2}.
  for (uint32_t k = 0; k < 8; ++k) {
    EXPECT_EQ(clusters_of(m, k), (std::vector<uint32_t>{0}));
    EXPECT_EQ(clusters_of(m, 8 + k), (std::vector<uint32_t>{0, 1}));
    EXPECT_EQ(clusters_of(m, 16 + k), (std::vector<uint32_t>{1, 2}));
    EXPECT_EQ(clusters_of(m, 24 + k), (std::vector<uint32_t>{2}));
  }
  EXPECT_EQ(clusters_of(m, 32), (std::vector<uint32_t>{2}));
  EXPECT_EQ(m.cluster_parent, (std::vector<int32_t>{-1, 0, 1}));
  EXPECT_EQ(m.segment_cluster, (std::vector<uint32_t>{0, 1, 2}));
}

TEST(TreeClusters, LateralBaseRingAndLeafPetiolesJoinTheParentCluster) {
  const Skeleton sk = test::small_tree();
  const TreeModel m = build_tree_model(sk, TreeOptions{});
  // 5 branch clusters (one per segment) then 3 leaf clusters.
  ASSERT_EQ(m.cluster_count(), 8u);
  EXPECT_EQ(m.cluster_kind, (std::vector<uint8_t>{0, 0, 0, 0, 0, 1, 1, 1}));
  EXPECT_EQ(m.cluster_parent, (std::vector<int32_t>{-1, 0, 1, 0, 3, 0, 1, 4}));
  // Lateral (segment 3) base ring: in the lateral's cluster and the trunk segment's cluster.
  int lateral_base = 0;
  for (uint32_t v = 0; v < m.vertex_count(); ++v)
    if (m.vertex_segment[v] == 3 && clusters_of(m, v) == std::vector<uint32_t>{0, 3}) ++lateral_base;
  EXPECT_EQ(lateral_base, 8);
  for (size_t l = 0; l < 3; ++l) {
    const uint32_t a = m.leaf_attachment_vertex[l];
    EXPECT_EQ(m.vertex_leaf[a], int32_t(l));
    EXPECT_EQ(clusters_of(m, a), (std::vector<uint32_t>{m.segment_cluster[sk.leaf_segment[l]], m.leaf_cluster[l]}));
    // The other leaf vertices are in the leaf cluster only.
    for (uint32_t v = 0; v < m.vertex_count(); ++v) {
      if (m.vertex_leaf[v] == int32_t(l) && v != a) {
        EXPECT_EQ(clusters_of(m, v), (std::vector<uint32_t>{m.leaf_cluster[l]}));
      }
    }
  }
}

TEST(TreeClusters, SegmentsPerClusterMergesConsecutiveSegmentsOfAnAxis) {
  TreeOptions o;
  o.cluster.segments_per_cluster = 2;
  const TreeModel m = build_tree_model(test::chain(5), o);
  EXPECT_EQ(m.segment_cluster, (std::vector<uint32_t>{0, 0, 1, 1, 2}));
  EXPECT_EQ(m.cluster_offsets, (std::vector<uint32_t>{0, 24, 48, 65}));  // 3 rings, 3 rings, 2 rings + tip
  EXPECT_EQ(m.cluster_parent, (std::vector<int32_t>{-1, 0, 1}));
  EXPECT_DOUBLE_EQ(m.cluster_length[0], 2.0);
  // A lateral never merges into its parent's axis.
  const TreeModel t = build_tree_model(test::small_tree(), o);
  EXPECT_EQ(t.segment_cluster, (std::vector<uint32_t>{0, 0, 1, 2, 2}));
}

TEST(TreeClusters, TargetVerticesClosesClustersBeforeTheyGrowPastIt) {
  TreeOptions o;
  o.cluster.segments_per_cluster = 100;
  o.cluster.target_vertices = 32;
  const TreeModel m = build_tree_model(test::chain(8), o);
  for (size_t c = 0; c < m.cluster_count(); ++c) EXPECT_LE(m.cluster_offsets[c + 1] - m.cluster_offsets[c], 32u);
  // 3 segments (4 rings = 32) per cluster; the tip cluster holds 2 segments, 3 rings and the tip.
  EXPECT_EQ(m.segment_cluster, (std::vector<uint32_t>{0, 0, 0, 1, 1, 1, 2, 2}));
}

TEST(TreeClusters, NoLeavesMeansNoLeafData) {
  const TreeModel m = build_tree_model(test::chain(4), TreeOptions{});
  EXPECT_EQ(m.leaf_count(), 0u);
  EXPECT_TRUE(m.leaf_attachment_vertex.empty());
  EXPECT_EQ(std::count(m.cluster_kind.begin(), m.cluster_kind.end(), uint8_t(kClusterLeaf)), 0);
  EXPECT_EQ(std::count(m.cluster_leaf.begin(), m.cluster_leaf.end(), -1), 4);
  EXPECT_EQ(std::count(m.vertex_leaf.begin(), m.vertex_leaf.end(), -1), int(m.vertex_count()));
}

}  // namespace
}  // namespace treeanim
