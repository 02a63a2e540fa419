#pragma once
// Local shape matching of one cluster (Müller et al. 2005; docs/solver.md, "Local shape
// matching") as a pure kernel, and the corrections toward its goals.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "sim/solver_model.h"

namespace treeanim {

// Cluster c's rest data + predicted displacements u_p (V x 3) + warm start `rotation`;
// pinned_point: the displacement from rest of the match point o where that point is held (an
// attached leaf), nullptr where o is the centre and follows the members => `rotation` updated,
// R and the translation as t - t0, for goals R q + t. Writes nothing else; false when a
// value is not finite.
template <typename Real>
bool fit_cluster(const TreeModel& tree, const Attachment<Real>& attachment, const Rows3<Real>& predicted_offset,
                 size_t c, const Eigen::Vector3d* pinned_point, int max_iterations, double newton_stop,
                 Eigen::Quaterniond& rotation, Eigen::Matrix3d& R, Eigen::Vector3d& shift);

// Goals g = R q + t of cluster c, with t given as t - t0 => per-membership corrections
// alpha_c (g - p) = alpha_c ((R q - q) + (t - t0) - u_p) in `corrections` (0 for a released
// membership).
template <typename Real>
void write_corrections(const SolverModel<Real>& model, const Attachment<Real>& attachment,
                       const Rows3<Real>& predicted_offset, size_t c, const Eigen::Matrix3d& R,
                       const Eigen::Vector3d& shift, Rows3<Real>& corrections);

// Fits cluster c (see fit_cluster) and keeps the fit: rotation and shift in the state, R in
// the scratch; on success its corrections. False when the fit is not finite.
template <typename Real>
bool match_cluster(const SolverModel<Real>& model, const Attachment<Real>& attachment, SimState& state,
                   StepScratch<Real>& scratch, size_t c, const Eigen::Vector3d* pinned_point);

}  // namespace treeanim
