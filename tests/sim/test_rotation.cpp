// Rotation extraction (Müller et al. 2016) on random, inverted, planar, collinear and tiny
// matrices: always a proper rotation, and the true one wherever A determines it.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>

#include "sim/rotation.h"

namespace treeanim {
namespace {

Eigen::Quaterniond random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  return q.normalized();
}

// Symmetric positive definite stretch with eigenvalues in [0.5, 2].
Eigen::Matrix3d random_stretch(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.5, 2.0);
  const Eigen::Matrix3d Q = random_rotation(rng).toRotationMatrix();
  return Q * Eigen::Vector3d(u(rng), u(rng), u(rng)).asDiagonal() * Q.transpose();
}

void expect_proper(const Eigen::Quaterniond& q) {
  const Eigen::Matrix3d R = q.toRotationMatrix();
  ASSERT_TRUE(R.allFinite());
  EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
  EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

double angle_between(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) { return a.angularDistance(b); }

TEST(Rotation, RandomStretchedRotationsFromColdStart) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Quaterniond truth = random_rotation(rng);
    const Eigen::Matrix3d A = truth.toRotationMatrix() * random_stretch(rng);
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    extract_rotation(A, q, 200);
    expect_proper(q);
    // The polar factor of A = R S (S positive definite) is R.
    EXPECT_LT(angle_between(q, truth), 1e-7) << "trial " << trial;
  }
}

TEST(Rotation, RandomMatricesGiveProperLocalOptimum) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n;
  for (int trial = 0; trial < 200; ++trial) {
    Eigen::Matrix3d A;
    for (int i = 0; i < 9; ++i) A(i) = n(rng);
    Eigen::Quaterniond q = random_rotation(rng);
    extract_rotation(A, q, 500);
    expect_proper(q);
    // No small rotation improves tr(R^T A).
    const Eigen::Matrix3d R = q.toRotationMatrix();
    const double best = (R.transpose() * A).trace();
    for (int axis = 0; axis < 3; ++axis)
      for (double angle : {-1e-3, 1e-3}) {
        const Eigen::Matrix3d P = Eigen::AngleAxisd(angle, Eigen::Vector3d::Unit(axis)).toRotationMatrix() * R;
        EXPECT_LE((P.transpose() * A).trace(), best + 1e-12);
      }
  }
}

TEST(Rotation, InvertedClusterGivesNoReflection) {
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Quaterniond truth = random_rotation(rng);
    // A cluster squashed through itself along one axis: det A < 0; the polar factor would be
    // a reflection. Warm-started at the last rotation, the extraction keeps a proper rotation
    // at the true one.
    const Eigen::Matrix3d A = truth.toRotationMatrix() * Eigen::Vector3d(1, 1, -0.3).asDiagonal();
    ASSERT_LT(A.determinant(), 0);
    Eigen::Quaterniond warm = truth;
    extract_rotation(A, warm, 50);
    expect_proper(warm);
    EXPECT_LT(angle_between(warm, truth), 1e-9);
    // From a cold start it still never reflects, and is at least as good as the truth.
    Eigen::Quaterniond cold = Eigen::Quaterniond::Identity();
    extract_rotation(A, cold, 500);
    expect_proper(cold);
    EXPECT_GE((cold.toRotationMatrix().transpose() * A).trace(),
              (truth.toRotationMatrix().transpose() * A).trace() - 1e-9);
  }
}

TEST(Rotation, FullyInvertedMatrixIsFinite) {
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  extract_rotation(-Eigen::Matrix3d::Identity(), q, 50);
  expect_proper(q);
}

TEST(Rotation, PlanarClusterRecoversRotation) {
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 100; ++trial) {
    const Eigen::Quaterniond truth = random_rotation(rng);
    // A flat leaf: A_pq = R sum q q^T has rank 2.
    const Eigen::Matrix3d A = truth.toRotationMatrix() * Eigen::Vector3d(0.7, 0.3, 0).asDiagonal();
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    extract_rotation(A, q, 500);
    expect_proper(q);
    EXPECT_LT(angle_between(q, truth), 1e-6) << "trial " << trial;
  }
}

TEST(Rotation, CollinearClusterKeepsSpinAndAlignsAxis) {
  std::mt19937_64 rng(9);
  for (int trial = 0; trial < 100; ++trial) {
    const Eigen::Quaterniond truth = random_rotation(rng);
    const Eigen::Matrix3d A = truth.toRotationMatrix() * Eigen::Vector3d(1, 0, 0).asDiagonal();
    // Warm start = the truth: nothing moves (no jitter about the undetermined axis).
    Eigen::Quaterniond warm = truth;
    EXPECT_LE(extract_rotation(A, warm, 50), 1);
    EXPECT_LT(angle_between(warm, truth), 1e-12);
    // Cold start: the axis is found, the spin about it is whatever is closest.
    Eigen::Quaterniond cold = Eigen::Quaterniond::Identity();
    extract_rotation(A, cold, 500);
    expect_proper(cold);
    EXPECT_LT((cold.toRotationMatrix().col(0) - truth.toRotationMatrix().col(0)).norm(), 1e-6) << trial;
  }
}

TEST(Rotation, TinyScaleWorks) {
  std::mt19937_64 rng(13);
  for (int trial = 0; trial < 100; ++trial) {
    const Eigen::Quaterniond truth = random_rotation(rng);
    const Eigen::Matrix3d A = 1e-7 * truth.toRotationMatrix() * random_stretch(rng);
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    extract_rotation(A, q, 500);
    expect_proper(q);
    EXPECT_LT(angle_between(q, truth), 1e-6) << "trial " << trial;
  }
}

// A warm start a substep's turn away (below 1e-3 rad): the samples' tolerance takes one
// Newton step and leaves of the order of its square; the vertices' takes a second, to round-off.
TEST(Rotation, AWarmStartASubstepAwayTakesOneStepWithTheSamplesTolerance) {
  // About the optimum of tr(R^T A) for a symmetric stretch the objective is even, so one Newton
  // step from a turn a away leaves some a^3 / 2: the samples' stop (a step below 5e-2 rad,
  // turned by the series of its sine and cosine) leaves at most some 6e-5 rad, the vertices'
  // (1e-6) takes a second step to round-off.
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> turn(1e-5, 4e-2);
  double worst_one = 0, worst_cubed = 0, worst_two = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const Eigen::Quaterniond truth = random_rotation(rng);
    const Eigen::Matrix3d A = truth.toRotationMatrix() * random_stretch(rng);
    const double a = turn(rng);
    const Eigen::Quaterniond off(Eigen::AngleAxisd(a, random_rotation(rng) * Eigen::Vector3d::UnitX()));
    Eigen::Quaterniond samples = off * truth, vertices = samples;
    EXPECT_EQ(extract_rotation(A, samples, 12, kNewtonStopSamples, true), 1) << "trial " << trial;
    // the vertices stop after a step below 1e-6 rad: their second where one leaves less (a^3 / 2), else their third
    const int steps = extract_rotation(A, vertices, 12, kNewtonStopRoundOff);
    if (a < 9e-3) EXPECT_EQ(steps, a < 1e-6 ? 1 : 2) << "trial " << trial;
    else EXPECT_LE(steps, 3) << "trial " << trial;
    worst_one = std::max(worst_one, angle_between(samples, truth));
    // above the round-off of the angle (some 1e-14 rad), a^3 bounds what one step leaves
    worst_cubed = std::max(worst_cubed, (angle_between(samples, truth) - 1e-13) / (a * a * a));
    worst_two = std::max(worst_two, angle_between(vertices, truth));
  }
  EXPECT_LT(worst_one, 1e-4);
  EXPECT_LT(worst_cubed, 1.0);
  EXPECT_LT(worst_two, 1e-12);
  std::printf("one step: %.3g rad at most (above 1e-13 rad, %.3g a^3); two: %.3g rad\n", worst_one, worst_cubed, worst_two);
}

TEST(Rotation, ZeroMatrixKeepsWarmStart) {
  Eigen::Quaterniond q(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()));
  const Eigen::Quaterniond before = q;
  EXPECT_EQ(extract_rotation(Eigen::Matrix3d::Zero(), q, 10), 0);
  EXPECT_EQ(q.coeffs(), before.coeffs());
}

// The solver finds its clusters' rotations four at a time: each lane must give the bits the
// scalar extraction gives, whatever the matrix (stretched, flattened, collinear, not finite),
// the warm start (near, far, cold), the iteration limit and the tolerance, since golden bakes
// were made with the scalar one and a bake's bytes may not depend on its neighbours.
TEST(Rotation, FourLanesGiveTheScalarBitsWhateverTheirNeighbours) {
  std::mt19937_64 rng(17);
  std::normal_distribution<double> n;
  std::uniform_real_distribution<double> u(0, 1);
  int differing = 0, lanes = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const int iterations = 1 + int(u(rng) * 12);
    const bool samples = u(rng) < 0.5;
    const double stop = samples ? kNewtonStopSamples : kNewtonStopRoundOff;
    Double4 A[9], q[4];
    Eigen::Matrix3d scalar_A[4];
    Eigen::Quaterniond scalar_q[4];
    for (int l = 0; l < 4; ++l) {
      const Eigen::Quaterniond truth = random_rotation(rng);
      const double kind = u(rng);
      Eigen::Matrix3d stretch = Eigen::Matrix3d::Identity();
      for (int i = 0; i < 9; ++i) stretch(i) += n(rng) * (kind < 0.5 ? 0.03 : 0.3);
      Eigen::Matrix3d M = truth.toRotationMatrix() * stretch;
      if (kind > 0.9) M.col(2).setZero();  // planar
      if (kind > 0.95) M = n(rng) * truth.toRotationMatrix() * Eigen::Vector3d(1, 0, 0).asDiagonal();  // collinear
      if (kind > 0.99) M(1, 1) = std::numeric_limits<double>::quiet_NaN();
      Eigen::Quaterniond warm = truth;
      const double away = kind < 0.3 ? 1e-4 : kind < 0.6 ? 1e-2 : 1.0;
      warm.coeffs() += away * Eigen::Vector4d(n(rng), n(rng), n(rng), n(rng));
      warm.normalize();
      if (u(rng) < 0.1) warm = Eigen::Quaterniond::Identity();
      scalar_A[l] = M;
      scalar_q[l] = warm;
      for (int i = 0; i < 9; ++i) A[i][l] = M(i);
      for (int k = 0; k < 4; ++k) q[k][l] = warm.coeffs()[k];
    }
    extract_rotations(A, q, iterations, stop, samples);
    for (int l = 0; l < 4; ++l, ++lanes) {
      extract_rotation(scalar_A[l], scalar_q[l], iterations, stop, samples);
      for (int k = 0; k < 4; ++k) {
        const double lane = q[k][l], scalar = scalar_q[l].coeffs()[k];
        if (std::memcmp(&lane, &scalar, sizeof lane) != 0) {
          ++differing;
          break;
        }
      }
    }
  }
  EXPECT_EQ(differing, 0) << "of " << lanes << " lanes";
}

}  // namespace
}  // namespace treeanim
