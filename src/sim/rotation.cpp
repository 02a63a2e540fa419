#include "sim/rotation.h"

#include <cmath>

namespace treeanim {

namespace {

// Rotation vector omega with |omega| = angle => its unit quaternion. A warm-started step is
// tiny, where the series (sin(a/2)/a to a^4, cos(a/2) to a^4, both below 1e-13 relative
// error for a < 1e-2) replaces the library's sine and cosine, the most costly part of a step.
Eigen::Quaterniond increment(const Eigen::Vector3d& omega, double angle) {
  if (angle >= 1e-2) return Eigen::Quaterniond(Eigen::AngleAxisd(angle, omega / angle));
  const double a2 = angle * angle;
  const double half_sinc = 0.5 - a2 * (1.0 / 48) + a2 * a2 * (1.0 / 3840);
  const double cosine = 1 - a2 * (1.0 / 8) + a2 * a2 * (1.0 / 384);
  return Eigen::Quaterniond(cosine, half_sinc * omega.x(), half_sinc * omega.y(), half_sinc * omega.z());
}

}  // namespace

int extract_rotation(const Eigen::Matrix3d& A, Eigen::Quaterniond& q, int max_iterations, double newton_stop) {
  // Müller et al. step: the torque sum_i r_i x a_i of the columns (the gradient of
  // tr(R^T A) over a rotation increment), divided by |tr(R^T A)| + 1e-9. That step is slow
  // about the long axis of an elongated cluster (a branch segment: 1% per iteration at a
  // 100:1 aspect), so where the second-order model is convex we take the Newton step with
  // its Hessian (tr(M) I - sym(M)), M = A R^T, instead; Müller's step stays the fallback far
  // from the optimum (e.g. an inverted cluster). A is normalised by the caller (order 1 for
  // any cluster size), so the constants are scale-free. A step is at most 1 rad (trust
  // region) so noise in a degenerate direction cannot spin a cluster.
  constexpr double kEps = 1e-9;
  constexpr double kMaxStep = 1.0;
  int iteration = 0;
  for (; iteration < max_iterations; ++iteration) {
    const Eigen::Matrix3d R = q.toRotationMatrix();
    const Eigen::Vector3d torque =
        R.col(0).cross(A.col(0)) + R.col(1).cross(A.col(1)) + R.col(2).cross(A.col(2));
    const double trace = R.col(0).dot(A.col(0)) + R.col(1).dot(A.col(1)) + R.col(2).dot(A.col(2));
    // Converged (cheap test first) only where the gradient is at round-off (1e-15 of the
    // trace): any larger step is taken, however small, since a warm-started cluster's pose
    // changes by O(h^2) a step (a leaf kicked at rate (wh)^2), which a coarser threshold
    // would freeze, an error growing as the step shrinks (docs/solver.md, "Rotation").
    const double scale = std::abs(trace) + kEps;
    if (!(torque.squaredNorm() > 1e-30 * scale * scale)) break;
    // H = tr(M)(1 + eps) I - sym(M), M = A R^T: symmetric, so six cofactors give its
    // determinant, Sylvester's leading minors and the Newton step adj(H) torque / det(H).
    const Eigen::Matrix3d M = A * R.transpose();
    const double diagonal = trace * (1 + kEps);
    const double h00 = diagonal - M(0, 0), h11 = diagonal - M(1, 1), h22 = diagonal - M(2, 2);
    const double h01 = -0.5 * (M(0, 1) + M(1, 0)), h02 = -0.5 * (M(0, 2) + M(2, 0)), h12 = -0.5 * (M(1, 2) + M(2, 1));
    const double c00 = h11 * h22 - h12 * h12, c01 = h02 * h12 - h01 * h22, c02 = h01 * h12 - h02 * h11;
    const double c11 = h00 * h22 - h02 * h02, c12 = h01 * h02 - h00 * h12, c22 = h00 * h11 - h01 * h01;
    const double det = h00 * c00 + h01 * c01 + h02 * c02;
    // Sylvester's criterion: H positive definite => the Newton step is an ascent step.
    const bool newton = trace > 0 && h00 > 0 && c22 > 0 && det > 0;
    Eigen::Vector3d omega;
    if (newton) {
      const double inv_det = 1 / det;
      omega = Eigen::Vector3d(c00 * torque.x() + c01 * torque.y() + c02 * torque.z(),
                              c01 * torque.x() + c11 * torque.y() + c12 * torque.z(),
                              c02 * torque.x() + c12 * torque.y() + c22 * torque.z()) *
              inv_det;
    } else {
      omega = torque * (1.0 / scale);
    }
    double angle = omega.norm();
    if (!std::isfinite(angle)) break;  // the caller checks the result
    if (angle > kMaxStep) {
      omega *= kMaxStep / angle;
      angle = kMaxStep;
    }
    q = increment(omega, angle) * q;
    q.normalize();
    // Newton converges quadratically: after a step below newton_stop the error left is of the
    // order of its square (1e-12 rad after 1e-6, what the test above would find), so that test
    // is not repeated; a gradient step below 1e-9 rad has nowhere left to go.
    if (angle < kEps || (newton && angle < newton_stop)) {
      ++iteration;
      break;
    }
  }
  return iteration;
}

}  // namespace treeanim
