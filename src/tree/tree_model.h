#pragma once
// TreeModel: the immutable, compiled tree (docs/design.md; MuJoCo's mjModel). Built once by
// build_tree_model(), read-only afterwards; the solver and the sinks only read it.
// SI units (m, kg), Y up. Index arrays are range-checked once by validate_tree_model().
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "common/errors.h"

namespace treeanim {

enum ClusterKind : uint8_t { kClusterBranch = 0, kClusterLeaf = 1 };
// The surface a triangle belongs to; mesh outputs give each its own material (tree/surface_materials.h).
enum TriangleMaterial : uint8_t { kMaterialBark = 0, kMaterialLeaf = 1 };
inline constexpr size_t kMaterialCount = 2;
inline constexpr const char* kMaterialNames[kMaterialCount] = {"bark", "leaf"};  // by TriangleMaterial

// Whether a model carries its surface (UVs, triangles and their materials): what writes or
// shows the mesh reads it; the solver and the samples read none of it.
enum class MeshSurface : uint8_t { kBuilt, kOmitted };

struct TreeModel {
  // --- mesh (V vertices, T triangles; uvs, triangles, triangle_material empty without the surface) ---
  Eigen::Matrix3Xd rest_positions;                // (3 x V) m
  Eigen::Matrix2Xf uvs;                           // (2 x V) u around the branch, v along it (m)
  std::vector<uint32_t> triangles;                // (T*3) vertex ids, counter-clockwise seen from outside
  std::vector<int32_t> vertex_segment;            // (V) segment the vertex was built for; -1 for leaf vertices
  std::vector<int32_t> vertex_leaf;               // (V) leaf the vertex belongs to; -1 for branch vertices
  std::vector<uint8_t> triangle_material;         // (T) TriangleMaterial

  // --- masses and forces ---
  std::vector<double> vertex_mass;                // (V) kg (shared vertices sum their shares)
  std::vector<uint8_t> vertex_anchored;           // (V) 1 = fixed to the ground
  std::vector<double> vertex_drag_area;           // (V) m^2, the vertex's share of projected branch/leaf area

  // --- clusters (C clusters, M memberships), CSR ---
  std::vector<uint32_t> cluster_offsets;          // (C+1) into cluster_members
  std::vector<uint32_t> cluster_members;          // (M) vertex ids, ascending within a cluster
  std::vector<uint8_t> cluster_kind;              // (C) ClusterKind
  std::vector<int32_t> cluster_leaf;              // (C) leaf index of a leaf cluster; -1 for branches
  std::vector<int32_t> cluster_parent;            // (C) cluster this one hangs from; -1 for the root
  std::vector<double> cluster_length;             // (C) m, axis length (leaf: leaf length)
  std::vector<double> cluster_radius;             // (C) m, mean branch radius (leaf: 0)

  // --- vertex => clusters, CSR, for a fixed-order gather of goals (index_memberships) ---
  std::vector<uint32_t> vertex_cluster_offsets;   // (V+1) into vertex_memberships
  std::vector<uint32_t> vertex_memberships;       // (M) membership slots (indices into cluster_members), ascending cluster id
  std::vector<uint32_t> member_cluster;           // (M) the cluster of each membership slot

  // --- leaves (L) ---
  std::vector<uint32_t> leaf_cluster;             // (L) the leaf's cluster
  std::vector<uint32_t> leaf_attachment_vertex;   // (L) the vertex shared with the branch cluster

  // --- skeleton, in metres (recorded in /skeleton of the HDF5 bake) ---
  std::vector<Eigen::Vector3d> segment_start;     // (S) m
  std::vector<Eigen::Vector3d> segment_end;       // (S) m
  std::vector<double> segment_radius_base;        // (S) m
  std::vector<double> segment_radius_top;         // (S) m
  std::vector<int32_t> segment_parent;            // (S) -1 for the root
  std::vector<uint32_t> segment_cluster;          // (S) the cluster built from this segment

  size_t vertex_count() const { return size_t(rest_positions.cols()); }
  size_t triangle_count() const { return triangles.size() / 3; }
  size_t cluster_count() const { return cluster_kind.size(); }
  size_t membership_count() const { return cluster_members.size(); }
  size_t leaf_count() const { return leaf_cluster.size(); }
  size_t segment_count() const { return segment_start.size(); }
};

// cluster_offsets and cluster_members => the vertex => clusters index (vertex_cluster_offsets,
// vertex_memberships, whose slots come out in ascending cluster id) and member_cluster.
void index_memberships(TreeModel& model);

// What the drawn tree cannot be (nothing drawn, a point or mass not finite): an InputError the
// caller names the grammar in (prepare_tree), since the grammar drew it.
struct TreeModelError : InputError {
  using InputError::InputError;
};

// Range-checks every index array and size (cheap, always on). Throws TreeModelError.
void validate_tree_model(const TreeModel& model);

}  // namespace treeanim
