#pragma once
// A direction given as a vector whose length does not matter (a wind key's, a tropism's).
#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <optional>

namespace treeanim {

// v / |v|, as Eigen's normalized() computes it, and where |v|^2 overflows or underflows
// ((1e300, 1e300, 0), (1e-300, 0, 0)) scaled by its largest component first => nullopt for
// zero or a component that is not finite.
inline std::optional<Eigen::Vector3d> unit_direction(const Eigen::Vector3d& v) {
  if (!v.allFinite()) return std::nullopt;
  const double squared = v.squaredNorm();
  if (squared >= std::numeric_limits<double>::min() && std::isfinite(squared))
    return Eigen::Vector3d(v / std::sqrt(squared));
  const double largest = v.cwiseAbs().maxCoeff();
  if (largest == 0) return std::nullopt;
  const Eigen::Vector3d scaled = v / largest;
  return Eigen::Vector3d(scaled / scaled.norm());
}

}  // namespace treeanim
