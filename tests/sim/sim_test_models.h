#pragma once
// Hand-built TreeModels for the solver tests: rings of vertices around straight branch
// segments, one cluster per segment (its two rings, shared with the neighbours), optional
// quad leaves sharing their petiole vertex with a branch cluster. Masses from the cone
// volumes (wood 700 kg/m^3), drag areas from the projected areas (2 r L, leaf area).
#include <Eigen/Core>
#include <vector>

#include "tree/tree_model.h"

namespace treeanim::testing {

class ModelBuilder {
 public:
  // A ring of `sides` vertices around `centre` normal to `axis` => its first vertex id.
  uint32_t add_ring(const Eigen::Vector3d& centre, const Eigen::Vector3d& axis, double radius, int sides,
                    bool anchored = false);
  // The branch cluster between two rings (each `sides` long) => cluster id.
  uint32_t add_segment(uint32_t ring_a, uint32_t ring_b, int sides, int32_t parent, double radius,
                       double length);
  // A square leaf of side `size` hanging from vertex `petiole` of `branch` (its first vertex
  // is the petiole point, shared with the branch cluster) => leaf index.
  uint32_t add_leaf(uint32_t branch, uint32_t petiole, const Eigen::Vector3d& normal, double size);
  // Straight branch of `segments` clusters from `base` along `axis` => cluster ids.
  std::vector<uint32_t> add_branch(const Eigen::Vector3d& base, const Eigen::Vector3d& axis, double length,
                                   int segments, double r_base, double r_top, int32_t parent,
                                   bool anchored_base, int sides = 6);
  // Masses, drag areas, CSRs => the finished model.
  TreeModel finish();

  std::vector<Eigen::Vector3d> positions;
  std::vector<uint8_t> anchored;
  std::vector<int32_t> vertex_leaf;
  std::vector<std::vector<uint32_t>> members;
  std::vector<uint8_t> kind;
  std::vector<int32_t> parent;
  std::vector<double> length, radius, area, mass;  // per cluster
  std::vector<uint32_t> leaf_cluster, leaf_attachment;
};

// A small tree: trunk (r 0.1 m, 3 m, 6 clusters) with laterals of radius 0.04, 0.02 and
// 0.008 m, optionally `leaves_per_branch` leaves on each lateral's tip cluster.
TreeModel small_tree(int leaves_per_branch = 0, Eigen::Vector3d origin = Eigen::Vector3d::Zero());

}  // namespace treeanim::testing
