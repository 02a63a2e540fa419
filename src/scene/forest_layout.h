#pragma once
// Where the trees of a forest stand on the ground (x, z): the spacing check of listed trees and
// seeded dart throwing for scattered ones. Plain geometry, no scene: tests call it directly.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

namespace treeanim {

// The first pair (in index order of the later point) closer than `spacing`, or none.
std::optional<std::pair<size_t, size_t>> closer_than(const std::vector<Eigen::Vector2d>& points, double spacing);

struct ScatterArea {
  Eigen::Vector2d min = Eigen::Vector2d::Zero();  // m, (x, z) corner
  Eigen::Vector2d max = Eigen::Vector2d::Zero();  // m, (x, z) opposite corner
};

// Dart throwing: up to `count` points uniform in `area`, each at least `spacing` from every
// point of `fixed` and every point placed before it; each point gets at most `attempts` darts,
// and the scatter stops at the first point that gets none in: the result then holds fewer than
// `count`. Deterministic in `seed`.
std::vector<Eigen::Vector2d> scatter_points(uint64_t seed, size_t count, const ScatterArea& area, double spacing,
                                            long long attempts, const std::vector<Eigen::Vector2d>& fixed);

}  // namespace treeanim
