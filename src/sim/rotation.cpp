#include "sim/rotation.h"

#include <cmath>

#include "sim/kernel_isa.h"
#include "sim/turn_series.h"

namespace treeanim {

namespace {

// Rotation vector omega with |omega| = angle => its unit quaternion. A warm-started step is
// tiny, where the series (sin(a/2)/a to a^4, cos(a/2) to a^4, both below 1e-13 relative
// error for a < 1e-2) replaces the library's sine and cosine, the most costly part of a step;
// with `series_turns` the longer series do for every step (extract_rotation).
Eigen::Quaterniond increment(const Eigen::Vector3d& omega, double angle, bool series_turns) {
  const double a2 = angle * angle;
  double half_sinc, cosine;
  if (series_turns) {
    half_turn_factors(a2, half_sinc, cosine);
  } else {
    if (angle >= 1e-2) return Eigen::Quaterniond(Eigen::AngleAxisd(angle, omega / angle));
    half_sinc = 0.5 - a2 * (1.0 / 48) + a2 * a2 * (1.0 / 3840);
    cosine = 1 - a2 * (1.0 / 8) + a2 * a2 * (1.0 / 384);
  }
  return Eigen::Quaterniond(cosine, half_sinc * omega.x(), half_sinc * omega.y(), half_sinc * omega.z());
}

}  // namespace

int extract_rotation(const Eigen::Matrix3d& A, Eigen::Quaterniond& q, int max_iterations, double newton_stop,
                     bool series_turns) {
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
    q = increment(omega, angle, series_turns) * q;
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

void extract_rotations(const Double4 (&A)[9], Double4 (&q)[4], int max_iterations, double newton_stop,
                       bool series_turns) {
  // extract_rotation's arithmetic, written out as the library computes it (the quaternion's
  // matrix, product and norm), in every lane at once; a lane that extract_rotation would have
  // left stays as it is.
  with_kernel_isa([&] {
    constexpr double kEps = 1e-9;
    constexpr double kMaxStep = 1.0;
    const Double4 zero = {};
    Mask4 active = zero == zero;
    for (int iteration = 0; iteration < max_iterations; ++iteration) {
      if ((active[0] | active[1] | active[2] | active[3]) == 0) break;
      Double4 R[9];
      rotation_matrix(q, R);
      Double4 torque[3] = {zero, zero, zero}, trace = zero;
      for (int i = 0; i < 3; ++i) {
        const Double4 *r = R + 3 * i, *a = A + 3 * i;
        const Double4 cross[3] = {r[1] * a[2] - r[2] * a[1], r[2] * a[0] - r[0] * a[2], r[0] * a[1] - r[1] * a[0]};
        const Double4 dot = (r[0] * a[0] + r[1] * a[1]) + r[2] * a[2];
        for (int k = 0; k < 3; ++k) torque[k] = i == 0 ? cross[k] : torque[k] + cross[k];
        trace = i == 0 ? dot : trace + dot;
      }
      const Double4 scale = (trace < zero ? -trace : trace) + kEps;
      active &= (torque[0] * torque[0] + torque[1] * torque[1]) + torque[2] * torque[2] > 1e-30 * scale * scale;
      Double4 M[9];  // A R^T, column-major
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) matrix_row_sum(i, A[i] * R[j], A[i + 3] * R[j + 3], A[i + 6] * R[j + 6], M[i + 3 * j]);
      const Double4 diagonal = trace * (1 + kEps);
      const Double4 h00 = diagonal - M[0], h11 = diagonal - M[4], h22 = diagonal - M[8];
      const Double4 h01 = -0.5 * (M[3] + M[1]), h02 = -0.5 * (M[6] + M[2]), h12 = -0.5 * (M[7] + M[5]);
      const Double4 c00 = h11 * h22 - h12 * h12, c01 = h02 * h12 - h01 * h22, c02 = h01 * h12 - h02 * h11;
      const Double4 c11 = h00 * h22 - h02 * h02, c12 = h01 * h02 - h00 * h12, c22 = h00 * h11 - h01 * h01;
      const Double4 det = (h00 * c00 + h01 * c01) + h02 * c02;
      const Mask4 newton = (trace > zero) & (h00 > zero) & (c22 > zero) & (det > zero);
      const Double4 inv_det = 1 / det, inv_scale = 1.0 / scale;
      Double4 omega[3] = {((c00 * torque[0] + c01 * torque[1]) + c02 * torque[2]) * inv_det,
                          ((c01 * torque[0] + c11 * torque[1]) + c12 * torque[2]) * inv_det,
                          ((c02 * torque[0] + c12 * torque[1]) + c22 * torque[2]) * inv_det};
      for (int k = 0; k < 3; ++k) omega[k] = newton ? omega[k] : torque[k] * inv_scale;
      Double4 angle = (omega[0] * omega[0] + omega[1] * omega[1]) + omega[2] * omega[2];
      sqrt_lanes(angle);
      active &= angle - angle == zero;  // finite
      const Mask4 capped = angle > kMaxStep;
      const Double4 cap = kMaxStep / angle;
      for (int k = 0; k < 3; ++k) omega[k] = capped ? omega[k] * cap : omega[k];
      angle = capped ? zero + kMaxStep : angle;
      // increment(omega, angle, series_turns) * q
      const Double4 a2 = angle * angle;
      Double4 half_sinc, iw;
      if (series_turns) {
        half_turn_factors(a2, half_sinc, iw);
      } else {
        half_sinc = 0.5 - a2 * (1.0 / 48) + a2 * a2 * (1.0 / 3840);
        iw = 1 - a2 * (1.0 / 8) + a2 * a2 * (1.0 / 384);
      }
      Double4 ix = half_sinc * omega[0], iy = half_sinc * omega[1], iz = half_sinc * omega[2];
      for (int l = 0; !series_turns && l < 4; ++l) {
        if (!(active[l] && angle[l] >= 1e-2)) continue;
        const Eigen::Quaterniond big =
            increment(Eigen::Vector3d(omega[0][l], omega[1][l], omega[2][l]), angle[l], false);
        ix[l] = big.x(), iy[l] = big.y(), iz[l] = big.z(), iw[l] = big.w();
      }
      const Double4 &x = q[0], &y = q[1], &z = q[2], &w = q[3];
      Double4 p[4] = {(iw * x + iy * z) - (iz * y - ix * w), (iw * y + iy * w) + (iz * x - ix * z),
                      (iw * z - iy * x) + (iz * w + ix * y), (iw * w - iy * y) - (iz * z + ix * x)};
      Double4 norm = (p[0] * p[0] + p[2] * p[2]) + (p[1] * p[1] + p[3] * p[3]);
      const Mask4 positive = norm > zero;
      sqrt_lanes(norm);
      for (int k = 0; k < 4; ++k) q[k] = active ? (positive ? p[k] / norm : p[k]) : q[k];
      active &= ~((angle < kEps) | (newton & (angle < newton_stop)));
    }
  });
}

}  // namespace treeanim
