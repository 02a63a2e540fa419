#pragma once
// Skeleton: what the turtle draws, as flat arrays (docs/design.md). Produced by lsystem/,
// consumed by tree/. Scene units (the turtle's), Y up. Segments are stored parents first
// (segment_parent[s] < s), one segment per drawn F/G module, never merged.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace treeanim {

struct Skeleton {
  // --- segments (S) ---
  std::vector<Eigen::Vector3d> segment_start;  // (S) scene units, turtle position before the F
  std::vector<Eigen::Vector3d> segment_end;    // (S) scene units, after the F
  std::vector<Eigen::Vector3d> segment_up;     // (S) unit turtle U while drawing; seeds ring frames
  std::vector<double> segment_width;           // (S) diameter set by '!' (scene units); NaN if the grammar never set one
  std::vector<int32_t> segment_parent;         // (S) segment this one grows from; -1 for a root
  std::vector<uint8_t> segment_continues_parent;  // (S) 1: same axis as the parent (no '[' between, starts at its end)
  std::vector<int32_t> segment_order;          // (S) branching order: 0 trunk axis, +1 per lateral branch
  std::vector<uint32_t> segment_id;            // (S) stable id: index of the drawing module in the derived string
  std::vector<int32_t> segment_material;       // (S) material index from ' and ,

  // --- leaves (L): 'L' / '~' modules, '{ . }' polygons, spheres and circles ---
  std::vector<int32_t> leaf_segment;           // (L) attachment segment; -1 if drawn before any segment
  std::vector<Eigen::Vector3d> leaf_position;  // (L) scene units, the petiole base
  std::vector<Eigen::Vector3d> leaf_heading;   // (L) unit turtle H at the leaf
  std::vector<Eigen::Vector3d> leaf_left;      // (L) unit turtle L
  std::vector<Eigen::Vector3d> leaf_up;        // (L) unit turtle U (leaf normal)
  std::vector<double> leaf_scale;              // (L) first parameter of the leaf module, 1 without one
  std::vector<uint32_t> leaf_polygon_offsets;  // (L+1) CSR into polygon_points; an empty range = default leaf shape
  std::vector<Eigen::Vector3d> polygon_points; // (P) scene units, world positions: '{ . }' outlines and shape vertices
  std::vector<uint32_t> leaf_triangle_offsets; // (L+1) CSR into leaf_triangles; a non-empty range = the leaf is that mesh
  std::vector<uint32_t> leaf_triangles;        // (T*3) ids into the leaf's own polygon_points range; front faces U

  size_t segment_count() const { return segment_start.size(); }
  size_t leaf_count() const { return leaf_position.size(); }
};

}  // namespace treeanim
