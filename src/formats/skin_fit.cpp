#include "formats/skin_fit.h"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <numeric>
#include <queue>
#include <utility>

namespace treeanim {

namespace {

// Cluster => the cluster heading its group (union-find with path halving; the head is the
// topmost cluster of the group, since a group only ever merges into its parent).
uint32_t head_of(std::vector<uint32_t>& head, uint32_t c) {
  while (head[c] != c) {
    head[c] = head[head[c]];
    c = head[c];
  }
  return c;
}

// Cluster => its group's head, merging the smallest groups into their parents until at most
// max_joints remain (roots merge into the first root when nothing else is left).
std::vector<uint32_t> group_clusters(const TreeModel& model, size_t max_joints) {
  const size_t clusters = model.cluster_count();
  std::vector<uint32_t> head(clusters);
  std::iota(head.begin(), head.end(), 0u);
  std::vector<size_t> size(clusters);
  for (size_t c = 0; c < clusters; ++c) size[c] = model.cluster_offsets[c + 1] - model.cluster_offsets[c];
  using Entry = std::pair<size_t, uint32_t>;  // (vertices, cluster): smallest first, then lowest id
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> smallest;
  for (uint32_t c = 0; c < clusters; ++c)
    if (model.cluster_parent[c] >= 0) smallest.emplace(size[c], c);
  size_t groups = clusters;
  while (groups > max_joints && !smallest.empty()) {
    const auto [vertices, c] = smallest.top();
    smallest.pop();
    if (head[c] != c || vertices != size[c]) continue;  // merged already, or a stale size
    const uint32_t parent = head_of(head, uint32_t(model.cluster_parent[c]));
    head[c] = parent;
    size[parent] += size[c];
    if (model.cluster_parent[parent] >= 0) smallest.emplace(size[parent], parent);
    --groups;
  }
  uint32_t first_root = uint32_t(clusters);
  for (uint32_t c = 0; c < clusters && groups > max_joints; ++c) {
    if (head[c] != c || model.cluster_parent[c] >= 0) continue;
    if (first_root == clusters) {
      first_root = c;
    } else {
      head[c] = first_root;
      --groups;
    }
  }
  for (uint32_t c = 0; c < clusters; ++c) head[c] = head_of(head, c);
  return head;
}

}  // namespace

Skin build_skin(const TreeModel& model, size_t max_joints) {
  const size_t clusters = model.cluster_count(), n = model.vertex_count();
  const std::vector<uint32_t> head = group_clusters(model, std::max<size_t>(1, max_joints));
  // Joints in the cluster order of their heads.
  std::vector<int32_t> joint_of_head(clusters, -1);
  std::vector<uint32_t> joint_head;
  for (uint32_t c = 0; c < clusters; ++c)
    if (head[c] == c) {
      joint_of_head[c] = int32_t(joint_head.size());
      joint_head.push_back(c);
    }
  const size_t joints = joint_head.size();
  Skin skin;
  for (uint32_t c : joint_head) {
    const int32_t parent = model.cluster_parent[c];
    skin.joint_parent.push_back(parent < 0 ? -1 : joint_of_head[head[size_t(parent)]]);
  }

  // Each joint's vertices, once each: the members of its clusters.
  std::vector<std::vector<uint32_t>> members(joints);
  for (size_t c = 0; c < clusters; ++c) {
    auto& list = members[size_t(joint_of_head[head[c]])];
    list.insert(list.end(), model.cluster_members.begin() + model.cluster_offsets[c],
                model.cluster_members.begin() + model.cluster_offsets[c + 1]);
  }
  skin.joint_offsets.push_back(0);
  for (size_t j = 0; j < joints; ++j) {
    auto& list = members[j];
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    double mass = 0;
    for (uint32_t v : list) mass += model.vertex_mass[v];
    Eigen::Vector3d pivot = Eigen::Vector3d::Zero();
    for (uint32_t v : list) {
      // Masses weigh the fit as they weigh the solver's; a massless joint weighs its vertices alike.
      const double weight = mass > 0 ? model.vertex_mass[v] : 1.0;
      skin.joint_vertices.push_back(v);
      skin.joint_vertex_mass.push_back(weight);
      pivot += weight * model.rest_positions.col(v);
    }
    skin.joint_pivot.push_back(list.empty() ? pivot : Eigen::Vector3d(pivot / (mass > 0 ? mass : double(list.size()))));
    skin.joint_offsets.push_back(uint32_t(skin.joint_vertices.size()));
  }

  // Weights: a vertex's share of memberships per joint, the four largest kept.
  skin.vertex_joints.assign(n, {});
  skin.vertex_weights.assign(n, {});
  std::vector<std::pair<double, uint32_t>> shares;  // (share, joint)
  for (size_t v = 0; v < n; ++v) {
    shares.clear();
    const uint32_t begin = model.vertex_cluster_offsets[v], end = model.vertex_cluster_offsets[v + 1];
    for (uint32_t k = begin; k < end; ++k) {
      const uint32_t c = model.member_cluster[model.vertex_memberships[k]];
      const auto joint = uint32_t(joint_of_head[head[c]]);
      auto same = std::find_if(shares.begin(), shares.end(), [&](const auto& s) { return s.second == joint; });
      if (same == shares.end()) shares.emplace_back(1.0, joint);
      else same->first += 1.0;
    }
    if (shares.empty()) shares.emplace_back(1.0, 0u);  // a vertex in no cluster follows the first joint
    std::sort(shares.begin(), shares.end(), [](const auto& a, const auto& b) {
      return a.first != b.first ? a.first > b.first : a.second < b.second;
    });
    shares.resize(std::min<size_t>(shares.size(), kSkinInfluences));
    double total = 0;
    for (const auto& s : shares) total += s.first;
    for (size_t k = 0; k < shares.size(); ++k) {
      skin.vertex_joints[v][k] = uint16_t(shares[k].second);
      skin.vertex_weights[v][k] = float(shares[k].first / total);
    }
  }
  return skin;
}

void fit_joints(const Skin& skin, const TreeModel& model, const float* positions, std::vector<RigidMotion>& motions) {
  motions.resize(skin.joint_count());
  for (size_t j = 0; j < skin.joint_count(); ++j) {
    const uint32_t begin = skin.joint_offsets[j], end = skin.joint_offsets[j + 1];
    double total = 0;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (uint32_t k = begin; k < end; ++k) {
      const float* x = positions + 3 * skin.joint_vertices[k];
      total += skin.joint_vertex_mass[k];
      centre += skin.joint_vertex_mass[k] * Eigen::Vector3d(x[0], x[1], x[2]);
    }
    RigidMotion& motion = motions[j];
    if (!(total > 0)) {
      motion = RigidMotion{};
      continue;
    }
    centre /= total;
    const Eigen::Vector3d& rest_centre = skin.joint_pivot[j];
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // sum of w (x - c)(x0 - c0)^T
    for (uint32_t k = begin; k < end; ++k) {
      const uint32_t v = skin.joint_vertices[k];
      const float* x = positions + 3 * v;
      covariance += skin.joint_vertex_mass[k] * (Eigen::Vector3d(x[0], x[1], x[2]) - centre) *
                    (model.rest_positions.col(v) - rest_centre).transpose();
    }
    // R = U diag(1, 1, det(U V^T)) V^T maximises tr(R^T covariance): the nearest rotation,
    // never a reflection; a degenerate (collinear or single-vertex) joint keeps what SVD gives.
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d u = svd.matrixU();
    if ((u * svd.matrixV().transpose()).determinant() < 0) u.col(2) = -u.col(2);
    motion.rotation = u * svd.matrixV().transpose();
    motion.translation = centre - motion.rotation * rest_centre;
  }
}

Eigen::Vector3d skinned_position(const Skin& skin, const TreeModel& model, const std::vector<RigidMotion>& motions,
                                 size_t v) {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  const Eigen::Vector3d rest = model.rest_positions.col(long(v));
  for (int k = 0; k < kSkinInfluences; ++k) {
    const float weight = skin.vertex_weights[v][size_t(k)];
    if (weight == 0.0f) continue;
    const RigidMotion& m = motions[skin.vertex_joints[v][size_t(k)]];
    p += double(weight) * (m.rotation * rest + m.translation);
  }
  return p;
}

}  // namespace treeanim
