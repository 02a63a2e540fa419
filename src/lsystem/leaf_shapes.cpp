// Leaf shapes: cpfg Bézier surfaces tessellated once, and the sphere and disc of @O, @o, @c.
#include "lsystem/leaf_shapes.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

namespace treeanim {
namespace {

// Points closer than this fraction of the shape's extent are one point (patch seams).
constexpr double kWeldTolerance = 1e-9;

// Cubic Bernstein weights at u.
std::array<double, 4> bernstein(double u) {
  const double v = 1.0 - u;
  return {v * v * v, 3.0 * u * v * v, 3.0 * u * u * v, u * u * u};
}

// The file's frame => the leaf frame: the contact point to the origin, SIZE to `scale`, cpfg's
// left (HEADING x UP) to -x, HEADING to +y, UP to +z. cpfg draws the file's left along the
// turtle's L, and the leaf frame's +x is -L.
Eigen::Vector3d to_leaf_frame(const BezierSurface& s, double factor, const Eigen::Vector3d& p) {
  const Eigen::Vector3d d = (p - s.contact) * factor;
  const Eigen::Vector3d left = s.heading.cross(s.up);
  return {-d.dot(left), d.dot(s.heading), d.dot(s.up)};
}

// Patch grids of (s+1) x (t+1) points each, appended to points; two triangles per quad.
void tessellate(const std::array<Eigen::Vector3d, 16>& control, int s_quads, int t_quads,
                std::vector<Eigen::Vector3d>& points, std::vector<uint32_t>& triangles) {
  const uint32_t first = static_cast<uint32_t>(points.size());
  const uint32_t row = static_cast<uint32_t>(t_quads + 1);
  for (int a = 0; a <= s_quads; ++a) {
    const std::array<double, 4> bs = bernstein(static_cast<double>(a) / s_quads);
    for (int b = 0; b <= t_quads; ++b) {
      const std::array<double, 4> bt = bernstein(static_cast<double>(b) / t_quads);
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      for (size_t i = 0; i < 4; ++i)
        for (size_t j = 0; j < 4; ++j) p += (bs[i] * bt[j]) * control[4 * i + j];
      points.push_back(p);
    }
  }
  for (uint32_t a = 0; a < static_cast<uint32_t>(s_quads); ++a)
    for (uint32_t b = 0; b < static_cast<uint32_t>(t_quads); ++b) {
      const uint32_t p00 = first + a * row + b, p10 = p00 + row;
      triangles.insert(triangles.end(), {p00, p10, p10 + 1, p00, p10 + 1, p00 + 1});
    }
}

// Union-find root with path halving; roots are the smallest index of their set.
uint32_t root(std::vector<uint32_t>& parent, uint32_t v) {
  while (parent[v] != v) v = parent[v] = parent[parent[v]];
  return v;
}

// Welds points within tolerance of each other (each to the first of its set), drops the
// triangles that collapse and the points no triangle uses. Deterministic: equal points joined
// first (patches stacked on each other give thousands at one place, which the sweep would
// compare pair by pair), then a sweep in x order over one point of each place.
void weld(std::vector<Eigen::Vector3d>& points, std::vector<uint32_t>& triangles) {
  const uint32_t n = static_cast<uint32_t>(points.size());
  Eigen::Vector3d lo = points[0], hi = points[0];
  for (const Eigen::Vector3d& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double tolerance = kWeldTolerance * std::max((hi - lo).maxCoeff(), 1e-300);
  std::vector<uint32_t> order(n), parent(n);
  std::iota(order.begin(), order.end(), 0u);
  std::iota(parent.begin(), parent.end(), 0u);
  auto join = [&](uint32_t i, uint32_t j) {
    const uint32_t a = root(parent, i), b = root(parent, j);
    parent[std::max(a, b)] = std::min(a, b);
  };
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return std::lexicographical_compare(points[a].data(), points[a].data() + 3, points[b].data(), points[b].data() + 3);
  });
  std::vector<uint32_t> places;  // the first point of each place, in x order
  for (size_t i = 0; i < n; ++i) {
    if (i > 0 && points[order[i]] == points[order[i - 1]]) join(order[i - 1], order[i]);
    else places.push_back(order[i]);
  }
  for (size_t i = 0; i < places.size(); ++i)
    for (size_t j = i + 1; j < places.size() && points[places[j]].x() - points[places[i]].x() <= tolerance; ++j)
      if ((points[places[j]] - points[places[i]]).cwiseAbs().maxCoeff() <= tolerance) join(places[i], places[j]);
  std::vector<uint32_t> kept;
  kept.reserve(triangles.size());
  for (size_t t = 0; t < triangles.size(); t += 3) {
    const uint32_t a = root(parent, triangles[t]), b = root(parent, triangles[t + 1]), c = root(parent, triangles[t + 2]);
    if (a != b && b != c && a != c) kept.insert(kept.end(), {a, b, c});
  }
  constexpr uint32_t kUnused = ~0u;
  std::vector<uint32_t> id(n, kUnused);
  for (uint32_t v : kept) id[v] = 0;
  std::vector<Eigen::Vector3d> compact;
  for (uint32_t v = 0; v < n; ++v)
    if (id[v] != kUnused) {
      id[v] = static_cast<uint32_t>(compact.size());
      compact.push_back(points[v]);
    }
  for (uint32_t& v : kept) v = id[v];
  points = std::move(compact);
  triangles = std::move(kept);
}

// Winds every triangle the other way when the shape's summed normal points to -z, so that its
// front faces the turtle's U as a leaf's does.
void face_up(const std::vector<Eigen::Vector3d>& points, std::vector<uint32_t>& triangles) {
  double z = 0;
  for (size_t t = 0; t < triangles.size(); t += 3) {
    const Eigen::Vector3d& a = points[triangles[t]];
    z += (points[triangles[t + 1]] - a).cross(points[triangles[t + 2]] - a).z();
  }
  if (z < 0)
    for (size_t t = 0; t < triangles.size(); t += 3) std::swap(triangles[t + 1], triangles[t + 2]);
}

}  // namespace

LeafShape surface_shape(const BezierSurface& surface, char id, double scale, int s_quads, int t_quads) {
  const double factor = scale / surface.size;
  LeafShape shape;
  shape.id = id;
  for (const std::array<Eigen::Vector3d, 16>& patch : surface.patches) {
    std::array<Eigen::Vector3d, 16> control;
    for (size_t k = 0; k < 16; ++k) control[k] = to_leaf_frame(surface, factor, patch[k]);
    tessellate(control, s_quads, t_quads, shape.points, shape.triangles);
  }
  weld(shape.points, shape.triangles);
  face_up(shape.points, shape.triangles);
  shape.end = to_leaf_frame(surface, factor, surface.end);
  return shape;
}

const LeafShape& sphere_shape() {
  static const LeafShape shape = [] {
    LeafShape s;
    // The -y pole first (it faces back along H, toward the branch), the HL ring, the +y pole.
    s.points = {{0, -0.5, 0}, {0.5, 0, 0}, {0, 0, 0.5}, {-0.5, 0, 0}, {0, 0, -0.5}, {0, 0.5, 0}};
    for (uint32_t k = 1; k <= 4; ++k) {
      const uint32_t next = k % 4 + 1;
      s.triangles.insert(s.triangles.end(), {0, k, next, 5, next, k});  // outward
    }
    return s;
  }();
  return shape;
}

const LeafShape& disc_shape() {
  static const LeafShape shape = [] {
    constexpr uint32_t kRim = 8;
    LeafShape s;
    s.points.push_back(Eigen::Vector3d::Zero());
    for (uint32_t k = 0; k < kRim; ++k) {
      const double a = 2.0 * std::numbers::pi * k / kRim;
      s.points.emplace_back(0.5 * std::cos(a), 0.5 * std::sin(a), 0.0);
      s.triangles.insert(s.triangles.end(), {0, k + 1, (k + 1) % kRim + 1});
    }
    return s;
  }();
  return shape;
}

}  // namespace treeanim
