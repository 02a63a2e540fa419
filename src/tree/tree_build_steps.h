#pragma once
// Internal steps of build_tree_model() (one .cpp each), in the order they run:
// topology => radii => branch mesh => leaf mesh => clusters => masses.
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "lsystem/skeleton.h"
#include "tree/tree_model.h"
#include "tree/tree_options.h"

namespace treeanim {

// Axis structure of a Skeleton (segments are parents-first, so one forward pass builds it).
struct SegmentTopology {
  std::vector<int32_t> continuation;     // (S) the child continuing this segment's axis; -1 at a tip
  std::vector<uint8_t> starts_axis;      // (S) 1: a root or a lateral, which gets its own base ring
  std::vector<uint32_t> lateral_count;   // (S) laterals attached to this segment
  std::vector<uint32_t> leaf_count;      // (S) leaves attached to this segment
  std::vector<Eigen::Vector3d> direction;  // (S) unit axis direction (a zero-length segment inherits)
  std::vector<double> length;            // (S) m
};

// skeleton => axis structure, directions and lengths in metres.
SegmentTopology segment_topology(const Skeleton& skeleton, double scale);

// skeleton widths (or the pipe model where none is set) => model.segment_radius_base/top (m).
void segment_radii(const Skeleton& skeleton, const SegmentTopology& topology,
                   const TreeOptions& options, TreeModel& model);

// Where each segment's rings are in the vertex array.
struct BranchRings {
  std::vector<uint32_t> base_ring;  // (S) first vertex of the ring at the segment start
  std::vector<uint32_t> top_ring;   // (S) first vertex of the ring at the segment end
  std::vector<int32_t> tip_vertex;  // (S) centre vertex closing the tip; -1 where the axis goes on
};

// Vertices (branch, then leaves) and triangles that the mesh steps will write.
struct MeshCounts {
  size_t branch_vertices = 0;
  size_t branch_triangles = 0;
  size_t leaf_vertices = 0;
  size_t leaf_triangles = 0;
};

// topology + radii => branch vertices [0, branch_vertices) and triangles of the model
// (rest_positions, uvs, vertex_segment, vertex_leaf, triangles must be sized already; uvs and
// triangles left empty omit the surface, MeshSurface::kOmitted).
BranchRings build_branch_mesh(const Skeleton& skeleton, const SegmentTopology& topology,
                              const TreeOptions& options, TreeModel& model);
size_t branch_vertex_count(const SegmentTopology& topology, int ring_sides);
size_t branch_triangle_count(const SegmentTopology& topology, int ring_sides);

// One leaf shape in the leaf frame (metres): +y along the turtle's H, -x along L, +z along U
// (the turtle's initial frame), so that a mesh authored upright facing +z needs no rotation.
struct LeafTemplate {
  Eigen::Matrix3Xd positions;       // (3 x n) m
  Eigen::Matrix2Xf uvs;             // (2 x n)
  std::vector<uint32_t> triangles;  // (t*3) counter-clockwise seen from +z
  uint32_t attachment = 0;          // the vertex nearest the petiole base (origin)
  double area = 0;                  // m^2
  double length = 0;                // m, extent along y
  // A custom mesh's files as read: the mesh, and those it names (a glTF's buffers).
  std::vector<std::filesystem::path> files;
};

// leaf options => the default rhombus quad, base vertex at y = petiole.
LeafTemplate default_leaf_template(const LeafOptions& options);
// leaf options with a mesh path => that mesh (assimp), scaled so its largest extent is
// options.size and shifted by options.petiole along y. Throws InputError naming the file.
LeafTemplate load_leaf_template(const LeafOptions& options);

// Per-leaf results that the cluster and mass steps need.
struct LeafMeshes {
  std::vector<uint32_t> vertex_offsets;  // (L+1) leaf vertex ranges (absolute vertex ids)
  std::vector<uint32_t> attachment;      // (L) the petiole vertex
  std::vector<double> area;              // (L) m^2, one-sided blade area
  std::vector<double> length;            // (L) m
};

// leaves of the skeleton => vertices and triangles after the branch mesh (the model sized as for
// build_branch_mesh).
size_t leaf_vertex_count(const Skeleton& skeleton, const LeafTemplate& shape);
size_t leaf_triangle_count(const Skeleton& skeleton, const LeafTemplate& shape);
LeafMeshes build_leaf_meshes(const Skeleton& skeleton, const TreeOptions& options,
                             const LeafTemplate& shape, const MeshCounts& counts, TreeModel& model);

// topology + rings + leaves => every cluster array of the model (CSR both ways, parents,
// kinds, lengths, radii).
void build_clusters(const Skeleton& skeleton, const SegmentTopology& topology,
                    const TreeOptions& options, const BranchRings& rings,
                    const LeafMeshes& leaves, TreeModel& model);

// Eq. 9 volumes and leaf areas => vertex_mass, vertex_anchored and vertex_drag_area.
void assign_masses(const SegmentTopology& topology, const TreeOptions& options,
                   const BranchRings& rings, const LeafMeshes& leaves, TreeModel& model);

// Truncated cone volume (paper Eq. 9): radii and length in metres => m^3.
double truncated_cone_volume(double r_base, double r_top, double length);

}  // namespace treeanim
