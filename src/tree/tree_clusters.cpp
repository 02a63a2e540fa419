// Shape-matching clusters (paper section 4): consecutive segments of an axis, one per leaf,
// overlapping at joint rings, lateral base rings and leaf petioles.
#include <algorithm>

#include "tree/tree_build_steps.h"

namespace treeanim {
namespace {

// Segments => branch clusters, parents before children (segments are stored that way and a
// cluster is numbered when its first segment is met). Fills segment_cluster and the branch
// part of the per-cluster arrays.
void group_segments(const Skeleton& skeleton, const SegmentTopology& topology,
                    const TreeOptions& options, TreeModel& model) {
  const size_t S = skeleton.segment_count();
  const uint32_t sides = uint32_t(options.ring_sides);
  const uint32_t max_segments = uint32_t(options.cluster.segments_per_cluster);
  const uint32_t target = uint32_t(options.cluster.target_vertices);
  std::vector<uint32_t> segments, members;  // (C) per branch cluster so far
  std::vector<double> weighted_radius;      // (C) sum of length * mean radius (m^2)
  std::vector<int32_t> first_segment;       // (C) the segment that started the cluster
  model.segment_cluster.resize(S);
  for (size_t s = 0; s < S; ++s) {
    const int32_t p = skeleton.segment_parent[s];
    // Members this segment brings: its top ring, the base rings of laterals on it, its leaf
    // petioles, its tip vertex.
    const uint32_t adds = sides * (1 + topology.lateral_count[s]) + topology.leaf_count[s] +
                          (topology.continuation[s] < 0);
    bool joins = false;
    if (!topology.starts_axis[s]) {
      const uint32_t c = model.segment_cluster[p];
      joins = segments[c] < max_segments && (target == 0 || members[c] + adds <= target);
    }
    uint32_t c;
    if (joins) {
      c = model.segment_cluster[p];
    } else {
      c = uint32_t(segments.size());
      segments.push_back(0);
      members.push_back(sides);  // the base ring
      weighted_radius.push_back(0);
      first_segment.push_back(int32_t(s));
      model.cluster_parent.push_back(p >= 0 ? int32_t(model.segment_cluster[p]) : -1);
      model.cluster_length.push_back(0);
    }
    model.segment_cluster[s] = c;
    ++segments[c];
    members[c] += adds;
    const double l = topology.length[s];
    model.cluster_length[c] += l;
    weighted_radius[c] += l * 0.5 * (model.segment_radius_base[s] + model.segment_radius_top[s]);
  }
  const size_t B = segments.size();
  model.cluster_radius.resize(B);
  for (size_t c = 0; c < B; ++c) {
    const int32_t s = first_segment[c];
    model.cluster_radius[c] = model.cluster_length[c] > 0
                                  ? weighted_radius[c] / model.cluster_length[c]
                                  : model.segment_radius_base[s];
  }
  model.cluster_kind.assign(B, kClusterBranch);
  model.cluster_leaf.assign(B, -1);
}

// One cluster per leaf after the branch clusters, hanging from its segment's cluster.
void add_leaf_clusters(const Skeleton& skeleton, const LeafMeshes& leaves, TreeModel& model) {
  const size_t L = skeleton.leaf_count();
  model.leaf_cluster.resize(L);
  model.leaf_attachment_vertex = leaves.attachment;
  for (size_t l = 0; l < L; ++l) {
    const int32_t s = skeleton.leaf_segment[l];
    model.leaf_cluster[l] = uint32_t(model.cluster_kind.size());
    model.cluster_kind.push_back(kClusterLeaf);
    model.cluster_leaf.push_back(int32_t(l));
    model.cluster_parent.push_back(s >= 0 ? int32_t(model.segment_cluster[s]) : -1);
    model.cluster_length.push_back(leaves.length[l]);
    model.cluster_radius.push_back(0);
  }
}

// Calls add(cluster, first_vertex, count) for every run of vertices a cluster holds. Run twice
// (count, then fill) so that no per-cluster container is allocated.
template <class Add>
void for_each_membership(const Skeleton& skeleton, const SegmentTopology& topology,
                         uint32_t sides, const BranchRings& rings, const LeafMeshes& leaves,
                         const TreeModel& model, Add&& add) {
  for (size_t s = 0; s < skeleton.segment_count(); ++s) {
    const uint32_t c = model.segment_cluster[s];
    const int32_t p = skeleton.segment_parent[s];
    // Base ring: its own cluster, plus the parent's cluster where a lateral attaches; a joint
    // ring joins the cluster of its upper segment only when the axis crosses into a new cluster
    // (the lower one already holds it as its top ring).
    if (topology.starts_axis[s] || model.segment_cluster[p] != c) add(c, rings.base_ring[s], sides);
    if (topology.starts_axis[s] && p >= 0) add(model.segment_cluster[p], rings.base_ring[s], sides);
    add(c, rings.top_ring[s], sides);
    if (rings.tip_vertex[s] >= 0) add(c, uint32_t(rings.tip_vertex[s]), 1u);
  }
  for (size_t l = 0; l < skeleton.leaf_count(); ++l) {
    add(model.leaf_cluster[l], leaves.vertex_offsets[l], leaves.vertex_offsets[l + 1] - leaves.vertex_offsets[l]);
    // The petiole vertex is the leaf's overlap with its branch: detaching the leaf releases
    // this one membership and the leaf keeps all of its own vertices.
    const int32_t seg = skeleton.leaf_segment[l];
    if (seg >= 0) add(model.segment_cluster[seg], leaves.attachment[l], 1u);
  }
}

}  // namespace

// The slots come out in ascending cluster id because they are visited in order.
void index_memberships(TreeModel& model) {
  const size_t V = model.vertex_count();
  model.vertex_cluster_offsets.assign(V + 1, 0);
  for (uint32_t v : model.cluster_members) ++model.vertex_cluster_offsets[v + 1];
  for (size_t v = 0; v < V; ++v) model.vertex_cluster_offsets[v + 1] += model.vertex_cluster_offsets[v];
  std::vector<uint32_t> cursor(model.vertex_cluster_offsets.begin(), model.vertex_cluster_offsets.end() - 1);
  model.vertex_memberships.resize(model.cluster_members.size());
  for (uint32_t slot = 0; slot < model.cluster_members.size(); ++slot)
    model.vertex_memberships[cursor[model.cluster_members[slot]]++] = slot;
  model.member_cluster.resize(model.cluster_members.size());
  for (size_t c = 0; c + 1 < model.cluster_offsets.size(); ++c)
    std::fill(model.member_cluster.begin() + model.cluster_offsets[c], model.member_cluster.begin() + model.cluster_offsets[c + 1],
              static_cast<uint32_t>(c));
}

void build_clusters(const Skeleton& skeleton, const SegmentTopology& topology,
                    const TreeOptions& options, const BranchRings& rings,
                    const LeafMeshes& leaves, TreeModel& model) {
  group_segments(skeleton, topology, options, model);
  add_leaf_clusters(skeleton, leaves, model);
  const size_t C = model.cluster_count();
  const uint32_t sides = uint32_t(options.ring_sides);
  model.cluster_offsets.assign(C + 1, 0);
  for_each_membership(skeleton, topology, sides, rings, leaves, model,
                      [&](uint32_t c, uint32_t, uint32_t n) { model.cluster_offsets[c + 1] += n; });
  for (size_t c = 0; c < C; ++c) model.cluster_offsets[c + 1] += model.cluster_offsets[c];
  std::vector<uint32_t> cursor(model.cluster_offsets.begin(), model.cluster_offsets.end() - 1);
  model.cluster_members.resize(model.cluster_offsets[C]);
  for_each_membership(skeleton, topology, sides, rings, leaves, model,
                      [&](uint32_t c, uint32_t first, uint32_t n) {
                        for (uint32_t i = 0; i < n; ++i) model.cluster_members[cursor[c]++] = first + i;
                      });
  for (size_t c = 0; c < C; ++c)
    std::sort(model.cluster_members.begin() + model.cluster_offsets[c],
              model.cluster_members.begin() + model.cluster_offsets[c + 1]);
  index_memberships(model);
}

}  // namespace treeanim
