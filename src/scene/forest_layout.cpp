#include "scene/forest_layout.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "common/random.h"

namespace treeanim {

namespace {

// Points binned in square cells at least as wide as the spacing: a point closer than the
// spacing to p lies in p's cell or one of its 8 neighbours, so each test costs O(1) however
// large the forest. Cells are 1 mm at least: a spacing of 1e-300 m made every cell index
// overflow into one cell, and each test compare every tree placed before.
class GroundGrid {
 public:
  explicit GroundGrid(double spacing) : spacing_(spacing), cell_(spacing > 0 ? std::max(spacing, 1e-3) : 0) {}

  // True when a point already added is closer than the spacing to p; `which` gets its index.
  bool near(const Eigen::Vector2d& p, size_t* which) const {
    if (spacing_ <= 0) return false;
    const long long cx = cell(p.x()), cz = cell(p.y());
    for (long long dx = -1; dx <= 1; ++dx)
      for (long long dz = -1; dz <= 1; ++dz) {
        const auto found = cells_.find(key(cx + dx, cz + dz));
        if (found == cells_.end()) continue;
        for (size_t i : found->second)
          if ((points_[i] - p).squaredNorm() < spacing_ * spacing_) {
            if (which) *which = i;
            return true;
          }
      }
    return false;
  }

  void add(const Eigen::Vector2d& p) {
    points_.push_back(p);
    if (spacing_ > 0) cells_[key(cell(p.x()), cell(p.y()))].push_back(points_.size() - 1);
  }

 private:
  // Clamped far inside long long's range, so that a neighbour's index cannot overflow either.
  long long cell(double v) const { return static_cast<long long>(std::clamp(std::floor(v / cell_), -0x1p62, 0x1p62)); }
  static uint64_t key(long long x, long long z) { return (uint64_t(x) << 32) ^ (uint64_t(z) & 0xffffffffull); }

  double spacing_;                                             // m, 0: no least distance
  double cell_;                                                // m, the cells' width
  std::vector<Eigen::Vector2d> points_;                        // (P) m, in the order added
  std::unordered_map<uint64_t, std::vector<size_t>> cells_;    // cell => indices into points_
};

}  // namespace

std::optional<std::pair<size_t, size_t>> closer_than(const std::vector<Eigen::Vector2d>& points, double spacing) {
  GroundGrid grid(spacing);
  for (size_t i = 0; i < points.size(); ++i) {
    size_t other = 0;
    if (grid.near(points[i], &other)) return std::pair{other, i};
    grid.add(points[i]);
  }
  return std::nullopt;
}

std::vector<Eigen::Vector2d> scatter_points(uint64_t seed, size_t count, const ScatterArea& area, double spacing,
                                            long long attempts, const std::vector<Eigen::Vector2d>& fixed) {
  GroundGrid grid(spacing);
  for (const Eigen::Vector2d& p : fixed) grid.add(p);
  RandomStream random{seed ^ 0x7363617474657200ull};  // "scatter": this purpose's stream
  const Eigen::Vector2d extent = area.max - area.min;
  std::vector<Eigen::Vector2d> placed;
  placed.reserve(count);
  while (placed.size() < count) {
    bool fitted = false;
    for (long long dart = 0; dart < attempts && !fitted; ++dart) {
      const double u = random.uniform(), v = random.uniform();
      const Eigen::Vector2d p(area.min.x() + u * extent.x(), area.min.y() + v * extent.y());
      if (grid.near(p, nullptr)) continue;
      grid.add(p);
      placed.push_back(p);
      fitted = true;
    }
    if (!fitted) break;
  }
  return placed;
}

}  // namespace treeanim
