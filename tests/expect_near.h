#pragma once
// A point where another is expected, within tol (m); the failure prints both.
#include <Eigen/Core>
#include <gtest/gtest.h>

namespace treeanim {

inline void expect_near(const Eigen::Vector3d& actual, const Eigen::Vector3d& expected, double tol = 1e-12) {
  EXPECT_LE((actual - expected).norm(), tol) << "actual " << actual.transpose() << " expected " << expected.transpose();
}

}  // namespace treeanim
