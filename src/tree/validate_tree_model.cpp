// Range checks of every index array of a TreeModel (cheap, always on).
#include <cmath>
#include <string>

#include "common/errors.h"
#include "tree/tree_model.h"

namespace treeanim {
namespace {

[[noreturn]] void fail(const std::string& what) { throw TreeModelError("tree model: " + what); }

void expect_size(const char* name, size_t size, size_t expected) {
  if (size != expected)
    fail(std::string(name) + " has " + std::to_string(size) + " entries, expected " + std::to_string(expected));
}

// Every entry of `values` in [lo, hi).
template <class T>
void expect_range(const char* name, const std::vector<T>& values, long long lo, long long hi) {
  for (size_t i = 0; i < values.size(); ++i)
    if (static_cast<long long>(values[i]) < lo || static_cast<long long>(values[i]) >= hi)
      fail(std::string(name) + "[" + std::to_string(i) + "] = " + std::to_string(values[i]) +
           " out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + ")");
}

// CSR offsets: starts at 0, never decreases, ends at `total`.
void expect_offsets(const char* name, const std::vector<uint32_t>& offsets, size_t rows, size_t total) {
  expect_size(name, offsets.size(), rows + 1);
  if (offsets[0] != 0) fail(std::string(name) + "[0] is not 0");
  for (size_t i = 0; i < rows; ++i)
    if (offsets[i + 1] < offsets[i]) fail(std::string(name) + " decreases at " + std::to_string(i + 1));
  if (offsets[rows] != total)
    fail(std::string(name) + " ends at " + std::to_string(offsets[rows]) + ", expected " + std::to_string(total));
}

void check_mesh(const TreeModel& m) {
  const size_t V = m.vertex_count();
  // Without its surface (MeshSurface::kOmitted) a model has no UVs and no triangles.
  if (m.uvs.cols() != 0 || !m.triangles.empty()) expect_size("uvs", size_t(m.uvs.cols()), V);
  if (m.triangles.size() % 3) fail("triangles size is not a multiple of 3");
  expect_range("triangles", m.triangles, 0, (long long)V);
  expect_size("triangle_material", m.triangle_material.size(), m.triangle_count());
  expect_range("triangle_material", m.triangle_material, 0, (long long)kMaterialCount);
  expect_size("vertex_segment", m.vertex_segment.size(), V);
  expect_size("vertex_leaf", m.vertex_leaf.size(), V);
  expect_range("vertex_segment", m.vertex_segment, -1, (long long)m.segment_count());
  expect_range("vertex_leaf", m.vertex_leaf, -1, (long long)m.leaf_count());
  if (!m.rest_positions.allFinite()) fail("rest_positions are not all finite");
  // The outputs keep positions and velocities in float32 (at most 3.4e38): a tree past this
  // would write inf, moving or not.
  constexpr double kFarthest = 1e24;  // m
  if (V > 0 && !(m.rest_positions.cwiseAbs().maxCoeff() <= kFarthest))
    fail("rest_positions reach past 1e24 m, beyond what the float32 outputs hold for its motion");
}

void check_masses(const TreeModel& m) {
  const size_t V = m.vertex_count();
  expect_size("vertex_mass", m.vertex_mass.size(), V);
  expect_size("vertex_anchored", m.vertex_anchored.size(), V);
  expect_size("vertex_drag_area", m.vertex_drag_area.size(), V);
  expect_range("vertex_anchored", m.vertex_anchored, 0, 2);
  for (size_t v = 0; v < V; ++v) {
    if (!(std::isfinite(m.vertex_mass[v]) && m.vertex_mass[v] > 0))
      fail("vertex_mass[" + std::to_string(v) + "] is not a positive finite number");
    if (!(std::isfinite(m.vertex_drag_area[v]) && m.vertex_drag_area[v] >= 0))
      fail("vertex_drag_area[" + std::to_string(v) + "] is not a finite number >= 0");
  }
}

void check_clusters(const TreeModel& m) {
  const size_t C = m.cluster_count(), M = m.membership_count(), V = m.vertex_count();
  expect_offsets("cluster_offsets", m.cluster_offsets, C, M);
  expect_range("cluster_members", m.cluster_members, 0, (long long)V);
  for (size_t c = 0; c < C; ++c)
    for (uint32_t i = m.cluster_offsets[c] + 1; i < m.cluster_offsets[c + 1]; ++i)
      if (m.cluster_members[i] <= m.cluster_members[i - 1])
        fail("cluster_members of cluster " + std::to_string(c) + " not strictly ascending at " + std::to_string(i));
  expect_range("cluster_kind", m.cluster_kind, 0, 2);
  expect_size("cluster_leaf", m.cluster_leaf.size(), C);
  expect_size("cluster_parent", m.cluster_parent.size(), C);
  expect_size("cluster_length", m.cluster_length.size(), C);
  expect_size("cluster_radius", m.cluster_radius.size(), C);
  expect_range("cluster_leaf", m.cluster_leaf, -1, (long long)m.leaf_count());
  for (size_t c = 0; c < C; ++c)
    if (m.cluster_parent[c] < -1 || m.cluster_parent[c] >= (long long)c)
      fail("cluster_parent[" + std::to_string(c) + "] = " + std::to_string(m.cluster_parent[c]) +
           " is not an earlier cluster");
}

// The vertex => cluster CSR must list every membership slot exactly once, at its own vertex,
// in ascending cluster order, and give every vertex at least one cluster; member_cluster must
// name the cluster that holds each slot.
void check_vertex_memberships(const TreeModel& m) {
  const size_t V = m.vertex_count(), M = m.membership_count();
  expect_offsets("vertex_cluster_offsets", m.vertex_cluster_offsets, V, M);
  expect_size("vertex_memberships", m.vertex_memberships.size(), M);
  expect_range("vertex_memberships", m.vertex_memberships, 0, (long long)M);
  std::vector<uint8_t> seen(M, 0);
  for (size_t v = 0; v < V; ++v) {
    if (m.vertex_cluster_offsets[v + 1] == m.vertex_cluster_offsets[v])
      fail("vertex " + std::to_string(v) + " belongs to no cluster");
    for (uint32_t i = m.vertex_cluster_offsets[v]; i < m.vertex_cluster_offsets[v + 1]; ++i) {
      const uint32_t slot = m.vertex_memberships[i];
      if (m.cluster_members[slot] != v || seen[slot]++)
        fail("vertex_memberships[" + std::to_string(i) + "] = " + std::to_string(slot) +
             " is not a distinct membership of vertex " + std::to_string(v));
      if (i > m.vertex_cluster_offsets[v] && slot <= m.vertex_memberships[i - 1])
        fail("vertex_memberships of vertex " + std::to_string(v) + " not in ascending cluster order");
    }
  }
  expect_size("member_cluster", m.member_cluster.size(), M);
  for (size_t c = 0; c < m.cluster_count(); ++c)
    for (uint32_t s = m.cluster_offsets[c]; s < m.cluster_offsets[c + 1]; ++s)
      if (m.member_cluster[s] != c)
        fail("member_cluster[" + std::to_string(s) + "] = " + std::to_string(m.member_cluster[s]) + " is not cluster " +
             std::to_string(c) + ", which holds the slot");
}

void check_leaves_and_segments(const TreeModel& m) {
  const size_t L = m.leaf_count(), S = m.segment_count();
  expect_size("leaf_attachment_vertex", m.leaf_attachment_vertex.size(), L);
  expect_range("leaf_cluster", m.leaf_cluster, 0, (long long)m.cluster_count());
  expect_range("leaf_attachment_vertex", m.leaf_attachment_vertex, 0, (long long)m.vertex_count());
  for (size_t l = 0; l < L; ++l)
    if (m.cluster_kind[m.leaf_cluster[l]] != kClusterLeaf || m.cluster_leaf[m.leaf_cluster[l]] != (long long)l)
      fail("leaf_cluster[" + std::to_string(l) + "] is not the leaf's cluster");
  expect_size("segment_end", m.segment_end.size(), S);
  expect_size("segment_radius_base", m.segment_radius_base.size(), S);
  expect_size("segment_radius_top", m.segment_radius_top.size(), S);
  expect_size("segment_parent", m.segment_parent.size(), S);
  expect_size("segment_cluster", m.segment_cluster.size(), S);
  for (size_t s = 0; s < S; ++s)
    if (m.segment_parent[s] < -1 || m.segment_parent[s] >= (long long)s)
      fail("segment_parent[" + std::to_string(s) + "] = " + std::to_string(m.segment_parent[s]) +
           " is not an earlier segment");
  expect_range("segment_cluster", m.segment_cluster, 0, (long long)m.cluster_count());
}

}  // namespace

void validate_tree_model(const TreeModel& model) {
  check_mesh(model);
  check_masses(model);
  check_clusters(model);
  check_vertex_memberships(model);
  check_leaves_and_segments(model);
}

}  // namespace treeanim
