#pragma once
// Correlation of two time series of vectors (air velocities, tip displacements), for the tests
// of the wind field over a forest.
#include <Eigen/Core>
#include <cmath>
#include <vector>

namespace treeanim::testing {

// a[from + i] against b[from + lag + i] over their overlap => the correlation of their
// fluctuations about their means: sum da . db / sqrt(sum |da|^2 sum |db|^2), in [-1, 1].
inline double correlation(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                          size_t from = 0, size_t lag = 0) {
  const size_t n = std::min(a.size() - from, b.size() - from - lag);
  Eigen::Vector3d mean_a = Eigen::Vector3d::Zero(), mean_b = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    mean_a += a[from + i] / double(n);
    mean_b += b[from + lag + i] / double(n);
  }
  double ab = 0, aa = 0, bb = 0;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d da = a[from + i] - mean_a, db = b[from + lag + i] - mean_b;
    ab += da.dot(db);
    aa += da.squaredNorm();
    bb += db.squaredNorm();
  }
  return ab / std::sqrt(aa * bb);
}

// The lag in [0, max_lag) at which b follows a most closely (first of equals).
inline size_t best_lag(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b, size_t from,
                       size_t max_lag) {
  size_t best = 0;
  for (size_t lag = 1; lag < max_lag; ++lag)
    if (correlation(a, b, from, lag) > correlation(a, b, from, best)) best = lag;
  return best;
}

}  // namespace treeanim::testing
