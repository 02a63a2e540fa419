#pragma once
// Rotational part of a 3x3 deformation gradient, Müller et al. 2016, "A robust method to
// extract the rotational part of deformations" (MIG '16).
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "sim/lanes.h"

namespace treeanim {

// Where the Newton iterations stop (docs/solver.md, "Rotation"): after a step below 1e-6 rad,
// with some 1e-12 rad left, the rotation of round-off that the paper's set-up (hsm.particles
// "vertices") keeps; after one below 5e-2 rad: about the optimum the objective is even, so a
// step from a turn a away leaves some a^3 / 2, at most 6.3e-5 rad (test
// Rotation.AWarmStartASubstepAwayTakesOneStepWithTheSamplesTolerance), far below a step's own
// error. "samples", where a cluster's fixed costs are the step's, takes one step a substep
// where the vertices take two: a leaf in gusts turns more than 1e-2 rad a substep.
constexpr double kNewtonStopRoundOff = 1e-6;
constexpr double kNewtonStopSamples = 5e-2;

// A (any 3x3, e.g. a cluster's normalised A_pq) + warm start q => q updated in place to the
// rotation R maximising tr(R^T A) locally, reached by at most `max_iterations` steps; a Newton
// step shorter than `newton_stop` rad ends them, its square of the order of what is left.
// Each step turns q by the series of its half angle's sine and cosine below 1e-2 rad and by
// the library's above; with `series_turns` ("samples") by their longer series up to the
// step's 1 rad cap (turn_series.h).
//
// Why this method and not a polar decomposition (SVD, or the paper's S^-1 from A^T A):
// it works on the rotation directly, so R is a proper rotation (det +1) by construction, also
// for inverted clusters (where the polar factor is a reflection); it needs no inverse, so a
// planar leaf (rank 2) or a collinear two-ring cluster (rank 1) yields no NaN; where A leaves
// the rotation undetermined (the spin about a collinear cluster's axis) it keeps the warm start,
// so nothing jitters. Returns the iterations used.
int extract_rotation(const Eigen::Matrix3d& A, Eigen::Quaterniond& q, int max_iterations,
                     double newton_stop = kNewtonStopRoundOff, bool series_turns = false);

// Four unit quaternions (x, y, z, w), a lane each => their rotation matrices, column-major, as
// the library's toRotationMatrix computes each.
inline void rotation_matrix(const Double4 (&q)[4], Double4 (&R)[9]) {
  const Double4 &x = q[0], &y = q[1], &z = q[2], &w = q[3];
  const Double4 tx = 2 * x, ty = 2 * y, tz = 2 * z;
  const Double4 twx = tx * w, twy = ty * w, twz = tz * w, txx = tx * x, txy = ty * x, txz = tz * x;
  const Double4 tyy = ty * y, tyz = tz * y, tzz = tz * z;
  R[0] = 1 - (tyy + tzz), R[1] = txy + twz, R[2] = txz - twy;
  R[3] = txy - twz, R[4] = 1 - (txx + tzz), R[5] = tyz + twx;
  R[6] = txz + twy, R[7] = tyz - twx, R[8] = 1 - (txx + tyy);
}

// The same for four matrices and warm starts at once, lane l of A (column-major) and q (x, y,
// z, w) one cluster's: each q comes out as extract_rotation would give it, to the bit.
void extract_rotations(const Double4 (&A)[9], Double4 (&q)[4], int max_iterations,
                       double newton_stop = kNewtonStopRoundOff, bool series_turns = false);

}  // namespace treeanim
