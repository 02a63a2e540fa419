#pragma once
// The mesh of hsm.particles "samples" (docs/solver.md, "Particles"): each cluster's rigid frame
// fitted to its samples, and every mesh vertex placed from the frames of its clusters, blended
// as the clusters blend a shared vertex (the mean), once per written frame.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "sim/sim_state.h"
#include "sim/vertex_run.h"
#include "tree/tree_model.h"

namespace treeanim {

// Each cluster's frame: x = R (x0 - t0) + t0 + shift for its rest points x0.
struct ClusterFrames {
  Eigen::Matrix4Xd rotation;  // (4 x C) unit quaternions (x, y, z, w)
  Eigen::Matrix3Xd shift;     // (3 x C) m, t - t0
  Eigen::Matrix3Xd velocity;  // (3 x C) m/s, of the centre (with velocities)
  Eigen::Matrix3Xd spin;      // (3 x C) rad/s, angular velocity (with velocities)
};

class SampleSkin {
 public:
  // mesh: the tree's model; samples: sample_tree_model(mesh) (both must outlive the skin).
  SampleSkin(const TreeModel& mesh, const TreeModel& samples);

  // The samples' state => each cluster's frame (`frames`), fitted to the samples it holds
  // (a branch's without the leaves' shared vertices), warm-started from the state's rotations;
  // a cluster whose samples are all at rest has exactly the identity.
  void fit_frames(const SimState& samples_state, bool velocities, ClusterFrames& frames) const;

  // The samples' state => the mesh's: positions (and velocities when asked) of every mesh
  // vertex from its clusters' frames, the mean over the memberships the leaves' flags leave
  // active; time and leaf flags copied. `frames` is scratch (its fit is left there).
  void pose(const SimState& samples_state, bool velocities, ClusterFrames& frames, SimState& mesh_state) const;
  // The same places and velocities (null: none), each double rounded to float as it is placed,
  // in (3 x V) arrays: the frame an output writes, without the mesh's state in doubles.
  void pose(const SimState& samples_state, ClusterFrames& frames, float* positions, float* velocities) const;

  // The mesh's vertices.
  size_t vertex_count() const { return mesh_.vertex_count(); }

  // The rest centre of each cluster's fit, t0 (3 x C) m.
  const Eigen::Matrix3Xd& rest_centres() const { return rest_centre_; }

 private:
  // pose's work, into arrays of doubles or floats.
  template <typename Out>
  void place(const SimState& samples_state, ClusterFrames& frames, Out* positions, Out* velocities) const;

  const TreeModel& mesh_;
  const TreeModel& samples_;
  // The fit's samples of cluster c: fit_samples_[fit_offsets_[c], fit_offsets_[c + 1]), their
  // weights m / sum m and rest offsets x0 - t0.
  std::vector<uint32_t> fit_offsets_, fit_samples_;
  std::vector<double> fit_weight_;
  Eigen::Matrix3Xd fit_offset_;       // (3 x F) m
  Eigen::Matrix3Xd rest_centre_;      // (3 x C) m
  std::vector<double> match_scale_;   // (C) 1/m^2, 1 / sum w |q|^2 (0 for a point)
  Eigen::Matrix<double, 9, Eigen::Dynamic> rest_moment_;  // (9 x C) sum w q q^T of each fit, column-major
  Eigen::Matrix3Xd offset_sum_;       // (3 x C) m, sum w q of each fit (0 but for round-off)
  std::vector<int32_t> petiole_leaf_; // (V) the leaf whose shared vertex this mesh vertex is; -1
  // The mesh's vertices placed a run at a time, their clusters' frames read once (a ring, a
  // leaf's blade); the others (anchored, a leaf's shared vertex, in no cluster or in more than
  // kMaxRunClusters) one at a time, ascending.
  std::vector<VertexRun> runs_;
  std::vector<uint32_t> single_vertices_;
};

}  // namespace treeanim
