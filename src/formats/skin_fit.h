#pragma once
// Linear blend skinning of a bake (docs/outputs.md "Skinned glTF"): one joint per cluster, or
// clusters merged into at most max_joints limbs, skin weights from the memberships as the solver
// averages them, and per frame each joint's rigid motion fitted to its vertices by least squares.
// HSM's goal for a cluster is a rigid transform, so a bake is very nearly such a skinning.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "tree/tree_model.h"

namespace treeanim {

// Influences a vertex keeps (glTF's JOINTS_0 / WEIGHTS_0 hold four).
constexpr int kSkinInfluences = 4;

struct Skin {
  std::vector<int32_t> joint_parent;          // (J) joint this one hangs from; -1 for a root
  std::vector<Eigen::Vector3d> joint_pivot;   // (J) m, mass-weighted rest centre: the joint's rest position
  std::vector<uint32_t> joint_offsets;        // (J+1) into joint_vertices
  std::vector<uint32_t> joint_vertices;       // vertex ids of each joint's clusters, ascending, each once
  std::vector<double> joint_vertex_mass;      // (as joint_vertices) kg, the fit's weights
  std::vector<std::array<uint16_t, kSkinInfluences>> vertex_joints;  // (V) joint ids, unused slots 0
  std::vector<std::array<float, kSkinInfluences>> vertex_weights;    // (V) summing to 1, unused slots 0
  size_t joint_count() const { return joint_parent.size(); }
};

// A joint's motion from the rest pose: x = R x0 + t.
struct RigidMotion {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
};

// Joints of `model`: a cluster each, or (max_joints < clusters) clusters merged into their parent,
// the one with the fewest vertices first (ties: the lower id), until max_joints remain. A
// vertex's weight on a joint is the share of its memberships in that joint's clusters (the
// solver averages a vertex's clusters alike); beyond four, the four largest are kept, rescaled.
Skin build_skin(const TreeModel& model, size_t max_joints);

// Per joint, the rigid motion that carries its rest vertices nearest to `positions` (V*3 float)
// in the mass-weighted least-squares sense (Kabsch, never a reflection) => motions (J).
void fit_joints(const Skin& skin, const TreeModel& model, const float* positions, std::vector<RigidMotion>& motions);

// The skinned position of vertex v under `motions`.
Eigen::Vector3d skinned_position(const Skin& skin, const TreeModel& model, const std::vector<RigidMotion>& motions,
                                 size_t v);

}  // namespace treeanim
