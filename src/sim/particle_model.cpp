// The samples of hsm.particles "samples" (docs/solver.md, "Particles"): per group of vertices
// in the same clusters, a few points with the group's mass, centre and second moments.
#include "sim/particle_model.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <numeric>
#include <span>
#include <type_traits>
#include <vector>

namespace treeanim {

namespace {

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
Eigen::Matrix3Xd sample_points(const TreeModel& mesh, std::span<const uint32_t> vertices) {
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

// The mesh's vertices in groups, each group's vertices in mesh order, the groups in the order
// of their first vertex; a kept vertex is a group of its own.
struct VertexGroups {
  std::vector<uint32_t> of_vertex;  // (V) the group of each vertex
  std::vector<uint32_t> offsets;    // (G+1) into vertices
  std::vector<uint32_t> vertices;   // (V)
  size_t count() const { return offsets.size() - 1; }
  std::span<const uint32_t> operator[](size_t g) const {
    return {vertices.data() + offsets[g], offsets[g + 1] - offsets[g]};
  }
};

VertexGroups group_vertices(const TreeModel& mesh) {
  const size_t V = mesh.vertex_count();
  const std::vector<uint8_t> kept = kept_vertices(mesh);
  VertexGroups groups;
  groups.of_vertex.resize(V);
  uint32_t G = 0;
  std::map<std::vector<uint32_t>, uint32_t> group_of_key;
  for (uint32_t v = 0; v < V; ++v) {
    if (kept[v]) {
      groups.of_vertex[v] = G++;
      continue;
    }
    const auto [it, added] = group_of_key.emplace(group_key(mesh, v), G);
    G += uint32_t(added);
    groups.of_vertex[v] = it->second;
  }
  groups.offsets.assign(size_t(G) + 1, 0);
  for (uint32_t g : groups.of_vertex) ++groups.offsets[g + 1];
  std::partial_sum(groups.offsets.begin(), groups.offsets.end(), groups.offsets.begin());
  std::vector<uint32_t> next(groups.offsets.begin(), groups.offsets.end() - 1);
  groups.vertices.resize(V);
  for (uint32_t v = 0; v < V; ++v) groups.vertices[next[groups.of_vertex[v]]++] = v;
  return groups;
}

// An array of the mesh that the samples copy, or take when the mesh is given up.
template <class T>
T take(const T& kept) {
  return kept;
}
template <class T>
T take(T& given_up) {
  return std::move(given_up);
}

// Mesh: const TreeModel (kept), or TreeModel, whose arrays go back once the samples have read them.
template <class Mesh>
TreeModel draw_samples(Mesh& mesh) {
  constexpr bool give_up = !std::is_const_v<Mesh>;
  const auto release = [](auto& array) {
    if constexpr (give_up) array = std::decay_t<decltype(array)>();
  };
  const size_t C = mesh.cluster_count();
  VertexGroups groups = group_vertices(mesh);
  const size_t G = groups.count();
  release(mesh.vertex_cluster_offsets), release(mesh.vertex_memberships), release(mesh.member_cluster);

  // Each group's samples, from first_sample[g] on; a group of its vertices' own count keeps them.
  std::vector<uint32_t> first_sample(G + 1, 0);
  std::vector<double> points;  // (3 x S)
  points.reserve(12 * G);
  for (size_t g = 0; g < G; ++g) {
    const Eigen::Matrix3Xd group_points = sample_points(mesh, groups[g]);
    points.insert(points.end(), group_points.data(), group_points.data() + group_points.size());
    first_sample[g + 1] = uint32_t(points.size() / 3);
  }
  const size_t S = points.size() / 3;
  release(mesh.rest_positions);

  TreeModel out;
  out.rest_positions = Eigen::Map<const Eigen::Matrix3Xd>(points.data(), 3, Eigen::Index(S));
  points = {};
  out.vertex_segment.resize(S);
  out.vertex_leaf.resize(S);
  out.vertex_mass.resize(S);
  out.vertex_anchored.resize(S);
  out.vertex_drag_area.resize(S);
  for (size_t g = 0; g < G; ++g) {
    const std::span<const uint32_t> vertices = groups[g];
    double mass = 0, area = 0;
    for (uint32_t v : vertices) {
      mass += mesh.vertex_mass[v];
      area += mesh.vertex_drag_area[v];
    }
    const uint32_t samples = first_sample[g + 1] - first_sample[g];
    const bool own = samples == vertices.size();  // the vertices themselves
    for (uint32_t k = 0; k < samples; ++k) {
      const uint32_t s = first_sample[g] + k, v = vertices[own ? k : 0];
      out.vertex_segment[s] = mesh.vertex_segment[v];
      out.vertex_leaf[s] = mesh.vertex_leaf[v];
      out.vertex_anchored[s] = mesh.vertex_anchored[v];
      out.vertex_mass[s] = own ? mesh.vertex_mass[v] : mass / samples;
      out.vertex_drag_area[s] = own ? mesh.vertex_drag_area[v] : area / samples;
    }
  }
  groups.vertices = {};
  release(mesh.vertex_mass), release(mesh.vertex_drag_area), release(mesh.vertex_anchored);
  release(mesh.vertex_segment), release(mesh.vertex_leaf);

  // The clusters: every sample of each group of a member vertex (a group's vertices share
  // their clusters), ascending as the groups are.
  out.cluster_offsets.assign(C + 1, 0);
  std::vector<uint32_t> member_groups;
  for (size_t c = 0; c < C; ++c) {
    member_groups.clear();
    for (uint32_t i = mesh.cluster_offsets[c]; i < mesh.cluster_offsets[c + 1]; ++i)
      member_groups.push_back(groups.of_vertex[mesh.cluster_members[i]]);
    std::sort(member_groups.begin(), member_groups.end());
    member_groups.erase(std::unique(member_groups.begin(), member_groups.end()), member_groups.end());
    for (uint32_t g : member_groups)
      for (uint32_t s = first_sample[g]; s < first_sample[g + 1]; ++s) out.cluster_members.push_back(s);
    out.cluster_offsets[c + 1] = uint32_t(out.cluster_members.size());
  }
  release(mesh.cluster_members);
  const size_t L = mesh.leaf_count();
  out.leaf_attachment_vertex.resize(L);
  for (size_t l = 0; l < L; ++l)  // kept: a group of one vertex, one sample
    out.leaf_attachment_vertex[l] = first_sample[groups.of_vertex[mesh.leaf_attachment_vertex[l]]];
  out.leaf_cluster = take(mesh.leaf_cluster);
  out.cluster_kind = take(mesh.cluster_kind), out.cluster_leaf = take(mesh.cluster_leaf);
  out.cluster_parent = take(mesh.cluster_parent);
  out.cluster_length = take(mesh.cluster_length), out.cluster_radius = take(mesh.cluster_radius);
  index_memberships(out);
  out.segment_start = take(mesh.segment_start), out.segment_end = take(mesh.segment_end);
  out.segment_radius_base = take(mesh.segment_radius_base), out.segment_radius_top = take(mesh.segment_radius_top);
  out.segment_parent = take(mesh.segment_parent), out.segment_cluster = take(mesh.segment_cluster);
  if constexpr (give_up) mesh = TreeModel();
  validate_tree_model(out);
  return out;
}

}  // namespace

TreeModel sample_tree_model(const TreeModel& mesh) { return draw_samples(mesh); }

TreeModel sample_tree_model(TreeModel&& mesh) { return draw_samples(mesh); }

}  // namespace treeanim
