#include "sim/rotation.h"

#include <cmath>

namespace treeanim {

int extract_rotation(const Eigen::Matrix3d& A, Eigen::Quaterniond& q, int max_iterations) {
  // The angular step is the torque sum_i r_i x a_i of the columns, over |sum_i r_i . a_i|:
  // a Newton-like step on tr(R^T A). The 1e-9 guards a zero denominator; A is normalised by
  // the caller (order 1 for any cluster size), so the constant is scale-free. Convergence
  // tolerance 1e-9 rad is far below any visible angle and above round-off noise, so a settled
  // cluster stops after one iteration.
  constexpr double kEps = 1e-9;
  int iteration = 0;
  for (; iteration < max_iterations; ++iteration) {
    const Eigen::Matrix3d R = q.toRotationMatrix();
    const Eigen::Vector3d torque =
        R.col(0).cross(A.col(0)) + R.col(1).cross(A.col(1)) + R.col(2).cross(A.col(2));
    const double alignment =
        std::abs(R.col(0).dot(A.col(0)) + R.col(1).dot(A.col(1)) + R.col(2).dot(A.col(2)));
    const Eigen::Vector3d omega = torque * (1.0 / (alignment + kEps));
    const double angle = omega.norm();
    if (!(angle >= kEps)) break;  // also stops on NaN: the caller checks the result
    q = Eigen::Quaterniond(Eigen::AngleAxisd(angle, omega / angle)) * q;
    q.normalize();
  }
  return iteration;
}

}  // namespace treeanim
