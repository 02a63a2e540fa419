#include "sim_test_models.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <numbers>

namespace treeanim::testing {

namespace {
constexpr double kWood = 700;       // kg/m^3
constexpr double kLeafMass = 0.2;   // kg/m^2 of leaf
}  // namespace

uint32_t ModelBuilder::add_ring(const Eigen::Vector3d& centre, const Eigen::Vector3d& axis, double r, int sides,
                                bool anchor) {
  const uint32_t first = static_cast<uint32_t>(positions.size());
  const Eigen::Vector3d a = axis.normalized(), u = a.unitOrthogonal(), w = a.cross(u);
  for (int k = 0; k < sides; ++k) {
    const double phi = 2 * std::numbers::pi * k / sides;
    positions.push_back(centre + r * (std::cos(phi) * u + std::sin(phi) * w));
    anchored.push_back(anchor);
    vertex_leaf.push_back(-1);
  }
  return first;
}

uint32_t ModelBuilder::add_segment(uint32_t ring_a, uint32_t ring_b, int sides, int32_t p, double r, double l) {
  std::vector<uint32_t> m;
  for (int k = 0; k < sides; ++k) m.push_back(ring_a + k);
  for (int k = 0; k < sides; ++k) m.push_back(ring_b + k);
  members.push_back(m);
  kind.push_back(kClusterBranch);
  parent.push_back(p);
  length.push_back(l);
  radius.push_back(r);
  area.push_back(2 * r * l);
  mass.push_back(kWood * std::numbers::pi * r * r * l);
  return static_cast<uint32_t>(members.size() - 1);
}

uint32_t ModelBuilder::add_leaf(uint32_t branch, uint32_t petiole, const Eigen::Vector3d& normal, double size) {
  const uint32_t leaf = static_cast<uint32_t>(leaf_cluster.size());
  const Eigen::Vector3d n = normal.normalized(), u = n.unitOrthogonal(), w = n.cross(u);
  const Eigen::Vector3d p = positions[petiole] + 0.01 * u;  // the petiole point, 1 cm off the bark
  const uint32_t first = static_cast<uint32_t>(positions.size());
  for (const Eigen::Vector3d& q : {p, Eigen::Vector3d(p + size * u), Eigen::Vector3d(p + size * (u + w)),
                                   Eigen::Vector3d(p + size * w)}) {
    positions.push_back(q);
    anchored.push_back(0);
    vertex_leaf.push_back(static_cast<int32_t>(leaf));
  }
  members[branch].push_back(first);
  members.push_back({first, first + 1, first + 2, first + 3});
  kind.push_back(kClusterLeaf);
  parent.push_back(static_cast<int32_t>(branch));
  length.push_back(size);
  radius.push_back(0);
  area.push_back(size * size);
  mass.push_back(kLeafMass * size * size);
  leaf_cluster.push_back(static_cast<uint32_t>(members.size() - 1));
  leaf_attachment.push_back(first);
  return leaf;
}

std::vector<uint32_t> ModelBuilder::add_branch(const Eigen::Vector3d& base, const Eigen::Vector3d& axis,
                                               double len, int segments, double r_base, double r_top, int32_t p,
                                               bool anchored_base, int sides) {
  std::vector<uint32_t> clusters;
  const Eigen::Vector3d a = axis.normalized();
  uint32_t ring = add_ring(base, a, r_base, sides, anchored_base);
  for (int s = 0; s < segments; ++s) {
    const double f = double(s + 1) / segments;
    const double r = r_base + (r_top - r_base) * f;
    const uint32_t next = add_ring(base + a * (len * f), a, r, sides);
    const double r_mid = r_base + (r_top - r_base) * (s + 0.5) / segments;
    clusters.push_back(add_segment(ring, next, sides, s == 0 ? p : static_cast<int32_t>(clusters.back()), r_mid,
                                   len / segments));
    ring = next;
  }
  return clusters;
}

TreeModel ModelBuilder::finish() {
  TreeModel m;
  const size_t V = positions.size(), C = members.size();
  m.rest_positions.resize(3, V);
  for (size_t v = 0; v < V; ++v) m.rest_positions.col(v) = positions[v];
  m.uvs.setZero(2, V);
  m.vertex_segment.assign(V, -1);
  m.vertex_leaf = vertex_leaf;
  m.vertex_anchored = anchored;
  m.vertex_mass.assign(V, 0);
  m.vertex_drag_area.assign(V, 0);
  m.cluster_offsets.push_back(0);
  for (size_t c = 0; c < C; ++c) {
    std::vector<uint32_t> sorted = members[c];
    std::sort(sorted.begin(), sorted.end());
    // A leaf's petiole vertex carries the leaf's share, not the branch's.
    auto own = [&](uint32_t v) { return kind[c] == kClusterLeaf || vertex_leaf[v] < 0; };
    const double n = double(std::count_if(sorted.begin(), sorted.end(), own));
    for (uint32_t v : sorted) {
      if (own(v)) {
        m.vertex_mass[v] += mass[c] / n;
        m.vertex_drag_area[v] += area[c] / n;
      }
      m.cluster_members.push_back(v);
    }
    m.cluster_offsets.push_back(static_cast<uint32_t>(m.cluster_members.size()));
  }
  m.cluster_kind = kind;
  m.cluster_parent = parent;
  m.cluster_length = length;
  m.cluster_radius = radius;
  m.cluster_leaf.assign(C, -1);
  for (size_t l = 0; l < leaf_cluster.size(); ++l) m.cluster_leaf[leaf_cluster[l]] = static_cast<int32_t>(l);
  index_memberships(m);
  m.leaf_cluster = leaf_cluster;
  m.leaf_attachment_vertex = leaf_attachment;
  return m;
}

TreeModel small_tree(int leaves_per_branch, Eigen::Vector3d origin) {
  ModelBuilder b;
  const std::vector<uint32_t> trunk =
      b.add_branch(origin, {0, 1, 0}, 3.0, 6, 0.1, 0.05, -1, true);
  const double radii[3] = {0.04, 0.02, 0.008};
  const Eigen::Vector3d dirs[3] = {{1, 0.6, 0}, {-0.5, 0.7, 0.8}, {-0.4, 0.5, -0.9}};
  for (int i = 0; i < 3; ++i) {
    const uint32_t at = trunk[2 + i];
    const Eigen::Vector3d base = origin + Eigen::Vector3d(0, 0.5 * (3 + i), 0);
    const std::vector<uint32_t> branch =
        b.add_branch(base, dirs[i], 1.2, 4, radii[i], radii[i] * 0.5, static_cast<int32_t>(at), false);
    // The lateral's base ring joins the trunk cluster it grows from.
    for (uint32_t k = 0; k < 6; ++k) b.members[at].push_back(b.members[branch[0]][k]);
    const uint32_t tip = branch.back();
    for (int l = 0; l < leaves_per_branch; ++l)
      b.add_leaf(tip, b.members[tip][6 + (l % 6)], Eigen::Vector3d(0.3 * l, 1, 0.5), 0.06);
  }
  return b.finish();
}

}  // namespace treeanim::testing
