#include "tree/build_tree_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "common/errors.h"
#include "tree/tree_build_steps.h"

namespace treeanim {
namespace {

// A vertex of a zero-length (or zero-area) cluster would otherwise get mass 0 and an infinite
// inverse mass; this keeps it finite without visibly changing any real tree's mass.
constexpr double kMinVertexMass = 1e-9;  // kg

// Spreads `amount` equally over the members of cluster c that pass `keep` into `out`.
template <class Keep>
void spread(const TreeModel& model, size_t c, double amount, Keep&& keep, std::vector<double>& out) {
  const auto first = model.cluster_members.begin() + model.cluster_offsets[c];
  const auto last = model.cluster_members.begin() + model.cluster_offsets[c + 1];
  const auto n = std::count_if(first, last, keep);
  if (n == 0) return;
  const double share = amount / double(n);
  for (auto it = first; it != last; ++it)
    if (keep(*it)) out[*it] += share;
}

// Anchors: the base ring of every root axis, and a leaf drawn before any segment (its
// petiole has no branch to hang from, so it is fixed where it was drawn).
void anchor(const BranchRings& rings, const LeafMeshes& leaves, uint32_t sides, TreeModel& model) {
  model.vertex_anchored.assign(model.vertex_count(), 0);
  for (size_t s = 0; s < model.segment_count(); ++s)
    if (model.segment_parent[s] < 0)
      std::fill_n(model.vertex_anchored.begin() + rings.base_ring[s], sides, uint8_t(1));
  for (size_t l = 0; l < leaves.attachment.size(); ++l)
    if (model.cluster_parent[model.leaf_cluster[l]] < 0) model.vertex_anchored[leaves.attachment[l]] = 1;
}

// The Skeleton's array sizes and parents-first order, which every later step indexes by.
void check_skeleton(const Skeleton& sk) {
  const size_t S = sk.segment_count(), L = sk.leaf_count();
  const bool segments_ok = sk.segment_end.size() == S && sk.segment_up.size() == S &&
                           sk.segment_width.size() == S && sk.segment_parent.size() == S &&
                           sk.segment_continues_parent.size() == S;
  const bool leaves_ok = sk.leaf_segment.size() == L && sk.leaf_heading.size() == L &&
                         sk.leaf_left.size() == L && sk.leaf_up.size() == L &&
                         sk.leaf_scale.size() == L && sk.leaf_polygon_offsets.size() >= L + (L > 0) &&
                         sk.leaf_triangle_offsets.size() >= L + (L > 0);
  if (!segments_ok || !leaves_ok) throw InputError("skeleton: array sizes disagree");
  if (S == 0 && L == 0) throw TreeModelError("the grammar draws nothing: no segment (F, G) and no leaf (L, ~, { . })");
  for (size_t s = 0; s < S; ++s)
    if (sk.segment_parent[s] < -1 || sk.segment_parent[s] >= int32_t(s))
      throw InputError("skeleton: segment_parent[" + std::to_string(s) + "] is not an earlier segment");
  for (size_t l = 0; l < L; ++l) {
    const uint32_t points = sk.leaf_polygon_offsets[l + 1] - sk.leaf_polygon_offsets[l];
    const uint32_t t0 = sk.leaf_triangle_offsets[l], t1 = sk.leaf_triangle_offsets[l + 1];
    const bool triangles_ok = t1 >= t0 && t1 <= sk.leaf_triangles.size() && (t1 - t0) % 3 == 0 &&
                              std::all_of(sk.leaf_triangles.begin() + t0, sk.leaf_triangles.begin() + t1,
                                          [&](uint32_t v) { return v < points; });
    if (sk.leaf_segment[l] < -1 || sk.leaf_segment[l] >= int32_t(S) ||
        sk.leaf_polygon_offsets[l + 1] < sk.leaf_polygon_offsets[l] ||
        sk.leaf_polygon_offsets[l + 1] > sk.polygon_points.size() || !triangles_ok)
      throw InputError("skeleton: leaf " + std::to_string(l) + " has a bad segment, polygon or triangle range");
  }
}

}  // namespace

void assign_masses(const SegmentTopology& topology, const TreeOptions& options,
                   const BranchRings& rings, const LeafMeshes& leaves, TreeModel& model) {
  const size_t V = model.vertex_count(), C = model.cluster_count();
  std::vector<double> volume(C, 0.0), area(C, 0.0);  // m^3 and projected m^2 per cluster
  for (size_t s = 0; s < model.segment_count(); ++s) {
    const double rb = model.segment_radius_base[s], rt = model.segment_radius_top[s];
    const double l = topology.length[s];
    volume[model.segment_cluster[s]] += truncated_cone_volume(rb, rt, l);
    area[model.segment_cluster[s]] += (rb + rt) * l;  // 2 * mean radius * length
  }
  model.vertex_mass.assign(V, 0.0);
  model.vertex_drag_area.assign(V, 0.0);
  // Wood goes to branch vertices only: a petiole vertex in a branch cluster carries its
  // leaf's mass, and takes it along when the leaf detaches.
  const auto is_branch = [&](uint32_t v) { return model.vertex_leaf[v] < 0; };
  const auto is_leaf = [&](uint32_t v) { return model.vertex_leaf[v] >= 0; };
  for (size_t c = 0; c < C; ++c) {
    if (model.cluster_kind[c] == kClusterBranch) {
      spread(model, c, options.wood_density * volume[c], is_branch, model.vertex_mass);
      spread(model, c, options.drag_share * area[c], is_branch, model.vertex_drag_area);
    } else {
      const size_t l = size_t(model.cluster_leaf[c]);
      spread(model, c, options.leaf.areal_density * leaves.area[l], is_leaf, model.vertex_mass);
      spread(model, c, options.drag_share * leaves.area[l], is_leaf, model.vertex_drag_area);
    }
  }
  // A drawn size past double's range (two steps of 1e300) overflows the volumes, not the points.
  if (!std::all_of(model.vertex_mass.begin(), model.vertex_mass.end(), [](double m) { return std::isfinite(m); }))
    throw TreeModelError("the tree is larger than a number holds: a segment's length or volume is not finite (a step such as F(1e300))");
  // Below the floor everywhere: segments of no length (F(0), a step of 1e-300) and no leaf, a
  // tree of floors alone whose motion would mean nothing.
  if (std::none_of(model.vertex_mass.begin(), model.vertex_mass.end(), [](double m) { return m >= kMinVertexMass; }))
    throw TreeModelError("the tree has no mass: its segments have no length and it has no leaf");
  for (double& m : model.vertex_mass) m = std::max(m, kMinVertexMass);
  anchor(rings, leaves, uint32_t(options.ring_sides), model);
}

TreeModel build_tree_model(const Skeleton& skeleton, const TreeOptions& options, MeshSurface surface) {
  check_skeleton(skeleton);
  TreeModel model;
  const SegmentTopology topology = segment_topology(skeleton, options.scale);
  segment_radii(skeleton, topology, options, model);

  // Leaf shape: loaded whenever a mesh is named, so a bad path is reported even on a bare tree.
  const LeafTemplate shape = options.leaf.mesh ? load_leaf_template(options.leaf) : default_leaf_template(options.leaf);
  MeshCounts counts;
  counts.branch_vertices = branch_vertex_count(topology, options.ring_sides);
  counts.branch_triangles = branch_triangle_count(topology, options.ring_sides);
  counts.leaf_vertices = leaf_vertex_count(skeleton, shape);
  counts.leaf_triangles = leaf_triangle_count(skeleton, shape);
  const size_t V = counts.branch_vertices + counts.leaf_vertices;
  if (V > std::numeric_limits<uint32_t>::max() / 2)  // ids and membership slots are uint32
    throw InputError("tree too large: " + std::to_string(V) + " vertices (at most 2^31)");
  model.rest_positions.resize(3, Eigen::Index(V));
  model.vertex_segment.resize(V);
  model.vertex_leaf.resize(V);
  if (surface == MeshSurface::kBuilt) {
    model.uvs.resize(2, Eigen::Index(V));
    model.triangles.resize(3 * (counts.branch_triangles + counts.leaf_triangles));
    model.triangle_material.assign(counts.branch_triangles, kMaterialBark);  // the branch mesh comes first
    model.triangle_material.resize(counts.branch_triangles + counts.leaf_triangles, kMaterialLeaf);
  }

  const BranchRings rings = build_branch_mesh(skeleton, topology, options, model);
  const LeafMeshes leaves = build_leaf_meshes(skeleton, options, shape, counts, model);

  model.segment_start.resize(skeleton.segment_count());
  model.segment_end.resize(skeleton.segment_count());
  for (size_t s = 0; s < skeleton.segment_count(); ++s) {
    model.segment_start[s] = skeleton.segment_start[s] * options.scale;
    model.segment_end[s] = skeleton.segment_end[s] * options.scale;
  }
  model.segment_parent = skeleton.segment_parent;

  build_clusters(skeleton, topology, options, rings, leaves, model);
  assign_masses(topology, options, rings, leaves, model);
  validate_tree_model(model);
  return model;
}

}  // namespace treeanim
