// The samples of hsm.particles "samples" (docs/solver.md, "Particles"): per group of vertices
// in the same clusters, a few points with the group's mass, centre and second moments.
#include "sim/particle_model.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <vector>

namespace treeanim {

namespace {

// Vertices of one group, in mesh order, and its samples' first id and count.
struct VertexGroup {
  std::vector<uint32_t> vertices;
  uint32_t first_sample = 0, samples = 0;
};

// Vertex v => what makes two vertices exchangeable: its clusters (ascending), its anchor, its
// leaf, the cluster of the segment it was built for (the chain reads whether a cluster's
// base ring was its parent's: bar_chain.cpp).
std::vector<uint32_t> group_key(const TreeModel& mesh, uint32_t v) {
  std::vector<uint32_t> key;
  for (uint32_t s = mesh.vertex_cluster_offsets[v]; s < mesh.vertex_cluster_offsets[v + 1]; ++s)
    key.push_back(mesh.member_cluster[mesh.vertex_memberships[s]]);
  const int32_t segment = mesh.vertex_segment[v];
  key.push_back(mesh.vertex_anchored[v]);
  key.push_back(static_cast<uint32_t>(mesh.vertex_leaf[v] + 1));
  key.push_back(segment >= 0 ? mesh.segment_cluster[segment] + 1 : 0);
  return key;
}

// Vertices kept as they are: each leaf's shared vertex (the chain's joint of the leaf, and the
// vertex a detachment releases) and the first vertex at each end of each axis (the tree's
// height above a root joint and its size, bar_chain.cpp and the runaway guard).
std::vector<uint8_t> kept_vertices(const TreeModel& mesh) {
  const size_t V = mesh.vertex_count();
  std::vector<uint8_t> kept(V, 0);
  for (uint32_t v : mesh.leaf_attachment_vertex) kept[v] = 1;
  for (int k = 0; k < 3 && V > 0; ++k) {
    Eigen::Index lo = 0, hi = 0;
    mesh.rest_positions.row(k).minCoeff(&lo);
    mesh.rest_positions.row(k).maxCoeff(&hi);
    kept[size_t(lo)] = kept[size_t(hi)] = 1;
  }
  return kept;
}

// The group's vertices => its samples' rest positions (3 x n): equal masses whose centre and
// second moments about it are the group's. Planar groups (a ring) take three points at thirds
// of an ellipse in the plane, the others four at the corners of a tetrahedron stretched along
// the principal axes; a group of no more vertices than that keeps its vertices.
Eigen::Matrix3Xd sample_points(const TreeModel& mesh, const std::vector<uint32_t>& vertices) {
  const size_t n = vertices.size();
  double mass = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (uint32_t v : vertices) {
    mass += mesh.vertex_mass[v];
    centre += mesh.vertex_mass[v] * mesh.rest_positions.col(v);
  }
  centre /= mass;
  Eigen::Matrix3d moment = Eigen::Matrix3d::Zero();
  for (uint32_t v : vertices) {
    const Eigen::Vector3d d = mesh.rest_positions.col(v) - centre;
    moment += mesh.vertex_mass[v] * d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(moment);
  const Eigen::Vector3d lambda = eigen.eigenvalues().cwiseMax(0.0);  // ascending
  const Eigen::Matrix3d axes = eigen.eigenvectors();
  const bool planar = lambda[0] <= 1e-9 * lambda[2];
  const size_t count = planar ? 3 : 4;
  Eigen::Matrix3Xd points(3, count);
  if (n <= count) {
    for (size_t i = 0; i < n; ++i) points.col(long(i)) = mesh.rest_positions.col(vertices[i]);
    return points.leftCols(long(n));
  }
  if (planar) {
    // a_k = sqrt(2 / m) (sqrt(l1) e1 cos t_k + sqrt(l2) e2 sin t_k): sum (m/3) a a^T = the moment
    const Eigen::Vector3d e1 = axes.col(2) * std::sqrt(2 * lambda[2] / mass);
    const Eigen::Vector3d e2 = axes.col(1) * std::sqrt(2 * lambda[1] / mass);
    for (int k = 0; k < 3; ++k) {
      const double t = 2 * std::numbers::pi * k / 3;
      points.col(k) = centre + std::cos(t) * e1 + std::sin(t) * e2;
    }
  } else {
    // Regular tetrahedron u_k (sum u u^T = 4/3 I): a_k = sqrt(3 / m) sum_j sqrt(l_j) e_j u_kj
    const double s = 1 / std::sqrt(3.0);
    const double corners[4][3] = {{s, s, s}, {s, -s, -s}, {-s, s, -s}, {-s, -s, s}};
    for (int k = 0; k < 4; ++k) {
      Eigen::Vector3d a = Eigen::Vector3d::Zero();
      for (int j = 0; j < 3; ++j) a += axes.col(j) * (std::sqrt(3 * lambda[j] / mass) * corners[k][j]);
      points.col(k) = centre + a;
    }
  }
  return points;
}

}  // namespace

TreeModel sample_tree_model(const TreeModel& mesh) {
  const size_t V = mesh.vertex_count(), C = mesh.cluster_count();
  // Groups in the order of their first vertex; a kept vertex is a group of its own.
  const std::vector<uint8_t> kept = kept_vertices(mesh);
  std::map<std::vector<uint32_t>, uint32_t> group_of_key;
  std::vector<VertexGroup> groups;
  for (uint32_t v = 0; v < V; ++v) {
    if (kept[v]) {
      groups.push_back({{v}, 0, 0});
      continue;
    }
    const auto [it, added] = group_of_key.emplace(group_key(mesh, v), uint32_t(groups.size()));
    if (added) groups.emplace_back();
    groups[it->second].vertices.push_back(v);
  }

  std::vector<Eigen::Matrix3Xd> points(groups.size());
  uint32_t S = 0;
  for (size_t g = 0; g < groups.size(); ++g) {
    points[g] = sample_points(mesh, groups[g].vertices);
    groups[g].first_sample = S;
    groups[g].samples = uint32_t(points[g].cols());
    S += groups[g].samples;
  }

  TreeModel out;
  out.rest_positions.resize(3, S);
  out.uvs.setZero(2, S);
  out.vertex_segment.resize(S);
  out.vertex_leaf.resize(S);
  out.vertex_mass.resize(S);
  out.vertex_anchored.resize(S);
  out.vertex_drag_area.resize(S);
  std::vector<uint32_t> vertex_group(V);
  for (size_t g = 0; g < groups.size(); ++g) {
    const VertexGroup& group = groups[g];
    double mass = 0, area = 0;
    for (uint32_t v : group.vertices) {
      mass += mesh.vertex_mass[v];
      area += mesh.vertex_drag_area[v];
      vertex_group[v] = uint32_t(g);
    }
    const bool own = group.samples == group.vertices.size();  // the vertices themselves
    for (uint32_t k = 0; k < group.samples; ++k) {
      const uint32_t s = group.first_sample + k, v = group.vertices[own ? k : 0];
      out.rest_positions.col(s) = points[g].col(k);
      out.vertex_segment[s] = mesh.vertex_segment[v];
      out.vertex_leaf[s] = mesh.vertex_leaf[v];
      out.vertex_anchored[s] = mesh.vertex_anchored[v];
      out.vertex_mass[s] = own ? mesh.vertex_mass[v] : mass / group.samples;
      out.vertex_drag_area[s] = own ? mesh.vertex_drag_area[v] : area / group.samples;
    }
  }

  // The clusters: every sample of each group of a member vertex (a group's vertices share
  // their clusters), ascending as the groups are.
  out.cluster_offsets.assign(C + 1, 0);
  std::vector<uint32_t> member_groups;
  for (size_t c = 0; c < C; ++c) {
    member_groups.clear();
    for (uint32_t i = mesh.cluster_offsets[c]; i < mesh.cluster_offsets[c + 1]; ++i)
      member_groups.push_back(vertex_group[mesh.cluster_members[i]]);
    std::sort(member_groups.begin(), member_groups.end());
    member_groups.erase(std::unique(member_groups.begin(), member_groups.end()), member_groups.end());
    for (uint32_t g : member_groups)
      for (uint32_t k = 0; k < groups[g].samples; ++k) out.cluster_members.push_back(groups[g].first_sample + k);
    out.cluster_offsets[c + 1] = uint32_t(out.cluster_members.size());
  }
  out.cluster_kind = mesh.cluster_kind, out.cluster_leaf = mesh.cluster_leaf, out.cluster_parent = mesh.cluster_parent;
  out.cluster_length = mesh.cluster_length, out.cluster_radius = mesh.cluster_radius;
  index_memberships(out);
  out.leaf_cluster = mesh.leaf_cluster;
  out.leaf_attachment_vertex.resize(mesh.leaf_count());
  for (size_t l = 0; l < mesh.leaf_count(); ++l)  // kept: a group of one vertex, one sample
    out.leaf_attachment_vertex[l] = groups[vertex_group[mesh.leaf_attachment_vertex[l]]].first_sample;
  out.segment_start = mesh.segment_start, out.segment_end = mesh.segment_end;
  out.segment_radius_base = mesh.segment_radius_base, out.segment_radius_top = mesh.segment_radius_top;
  out.segment_parent = mesh.segment_parent, out.segment_cluster = mesh.segment_cluster;
  validate_tree_model(out);
  return out;
}

}  // namespace treeanim
