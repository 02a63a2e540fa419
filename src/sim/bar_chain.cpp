#include "sim/bar_chain.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace treeanim {

namespace {

// The trunk is cut until no limb below it holds more than 1/64 of the clusters; the limbs
// are dealt into 16 groups, largest first, each to the smallest group so far.
constexpr size_t kWalkLimbShare = 64;
constexpr size_t kWalkGroups = 16;

// Tree => chain.walk_trunk, walk_group_offsets and walk_groups (BarChain).
void cut_for_walks(const TreeModel& tree, BarChain& chain) {
  const size_t C = tree.cluster_count();
  std::vector<uint32_t> size(C, 1);  // clusters in the subtree of each (a parent's index is below its children's)
  for (size_t c = C; c-- > 0;)
    if (tree.cluster_parent[c] >= 0) size[tree.cluster_parent[c]] += size[c];
  std::vector<std::vector<uint32_t>> children(C);
  for (size_t c = 0; c < C; ++c)
    if (tree.cluster_parent[c] >= 0) children[tree.cluster_parent[c]].push_back(static_cast<uint32_t>(c));
  // The frontier starts at the roots; its largest limb is opened while larger than the share.
  std::vector<uint8_t> in_trunk(C, 0);
  auto larger = [&](uint32_t a, uint32_t b) { return size[a] != size[b] ? size[a] < size[b] : a > b; };
  std::vector<uint32_t> frontier;
  for (size_t c = 0; c < C; ++c)
    if (tree.cluster_parent[c] < 0) frontier.push_back(static_cast<uint32_t>(c));
  std::make_heap(frontier.begin(), frontier.end(), larger);
  const size_t share = std::max<size_t>(1, C / kWalkLimbShare);
  while (!frontier.empty() && size[frontier.front()] > share) {
    std::pop_heap(frontier.begin(), frontier.end(), larger);
    const uint32_t opened = frontier.back();
    frontier.pop_back();
    in_trunk[opened] = 1;
    for (uint32_t child : children[opened]) {
      frontier.push_back(child);
      std::push_heap(frontier.begin(), frontier.end(), larger);
    }
  }
  for (uint32_t root : frontier) in_trunk[root] = 1;
  for (size_t c = 0; c < C; ++c)
    if (in_trunk[c]) chain.walk_trunk.push_back(static_cast<uint32_t>(c));
  // Each limb's root => its group; a cluster below the trunk joins its parent's limb.
  std::sort(frontier.begin(), frontier.end(), [&](uint32_t a, uint32_t b) { return larger(b, a); });
  std::vector<size_t> load(kWalkGroups, 0);
  std::vector<uint32_t> group(C, 0);
  for (uint32_t root : frontier) {
    const size_t g = size_t(std::min_element(load.begin(), load.end()) - load.begin());
    group[root] = static_cast<uint32_t>(g);
    load[g] += size[root] - 1;
  }
  std::vector<std::vector<uint32_t>> members(kWalkGroups);
  for (size_t c = 0; c < C; ++c) {
    if (in_trunk[c]) continue;
    group[c] = group[tree.cluster_parent[c]];
    members[group[c]].push_back(static_cast<uint32_t>(c));
  }
  chain.walk_group_offsets.assign(1, 0);
  for (const std::vector<uint32_t>& m : members) {
    chain.walk_groups.insert(chain.walk_groups.end(), m.begin(), m.end());
    chain.walk_group_offsets.push_back(static_cast<uint32_t>(chain.walk_groups.size()));
  }
}

}  // namespace

BarChain build_bar_chain(const TreeModel& tree, const HsmOptions& options, std::span<const double> stiffened) {
  const double youngs_modulus = options.youngs_modulus, yield_strain = options.yield_strain;
  const size_t C = tree.cluster_count();
  BarChain chain;
  chain.cluster_joint.setZero(3, C);
  chain.cluster_compliance.assign(C, 0);
  chain.cluster_max_turn.assign(C, std::numeric_limits<double>::infinity());
  std::vector<int64_t> first(C, -1);  // each cluster's first segment
  for (size_t s = tree.segment_cluster.size(); s-- > 0;)
    if (tree.segment_cluster[s] < C) first[tree.segment_cluster[s]] = static_cast<int64_t>(s);
  std::vector<double> half(C, 0);  // (C) rad/(N m), half the flexibility L / (E I) of each branch cluster
  for (size_t c = 0; c < C; ++c) {
    const uint32_t begin = tree.cluster_offsets[c], end = tree.cluster_offsets[c + 1];
    const int32_t leaf = tree.cluster_leaf[c];
    if (tree.cluster_kind[c] == kClusterLeaf && leaf >= 0) {
      chain.cluster_joint.col(c) = tree.rest_positions.col(tree.leaf_attachment_vertex[leaf]);
      continue;
    }
    if (first[c] >= 0) {
      chain.cluster_joint.col(c) = tree.segment_start[first[c]];
    } else if (end > begin) {  // no segment (a hand-built model): its members' centre
      for (uint32_t s = begin; s < end; ++s) chain.cluster_joint.col(c) += tree.rest_positions.col(tree.cluster_members[s]);
      chain.cluster_joint.col(c) /= double(end - begin);
    }
    if (tree.cluster_kind[c] == kClusterLeaf) continue;
    const double r = tree.cluster_radius[c], second_moment = std::numbers::pi * r * r * r * r / 4;
    half[c] = second_moment > 0 ? tree.cluster_length[c] / (2 * youngs_modulus * second_moment) : 0;
  }
  // Y is up: the tree's top, from which each root's height is measured.
  const double top = tree.vertex_count() ? tree.rest_positions.row(1).maxCoeff() : 0.0;
  for (size_t c = 0; c < C; ++c) {
    if (tree.cluster_kind[c] == kClusterLeaf) continue;
    chain.cluster_compliance[c] = half[c];
    // It continues its parent's axis when its base ring was built for the parent's segment
    // (a lateral has a base ring of its own).
    const int32_t p = tree.cluster_parent[c];
    for (uint32_t s = tree.cluster_offsets[c]; p >= 0 && s < tree.cluster_offsets[c + 1]; ++s) {
      const int32_t segment = tree.vertex_segment[tree.cluster_members[s]];
      if (segment >= 0 && size_t(segment) < tree.segment_cluster.size() &&
          tree.segment_cluster[segment] == static_cast<uint32_t>(p)) {
        chain.cluster_compliance[c] += half[p];
        break;
      }
    }
    const double share = stiffened.empty() ? 1.0 : stiffened[c];
    chain.cluster_compliance[c] *= share;
    const double r = tree.cluster_radius[c];
    // At most a quarter turn, as a leaf's petiole: rigid clusters stand for a bent branch only
    // while each joint turns moderately; a slender twig's yield turn (eps_y L / r) can be
    // several whole turns, and its goal then swung round with the smallest change of load.
    if (r > 0)
      chain.cluster_max_turn[c] = std::min(std::numbers::pi / 2, chain.cluster_compliance[c] * yield_strain *
                                                                     youngs_modulus * std::numbers::pi * r * r * r / 4);
    // The root plate turns the root's joint further under the same moment, up to the same
    // largest turn: the soil gives way about where the stem's base would yield.
    if (p < 0 && half[c] > 0) {
      const double height = std::max(0.0, top - chain.cluster_joint(1, c));
      chain.cluster_compliance[c] += share * options.root_flexibility * height * half[c] * 2 / tree.cluster_length[c];  // 2 half / L = 1 / (E I)
    }
  }
  cut_for_walks(tree, chain);
  return chain;
}

double tree_reach(const TreeModel& tree, const BarChain& chain) {
  const size_t C = tree.cluster_count();
  std::vector<double> path(C, 0);  // (C) m, from the root's joint to the cluster's joint
  double reach = 0;
  for (size_t c = 0; c < C; ++c) {
    const int32_t p = tree.cluster_parent[c];
    if (p >= 0) path[c] = path[p] + (chain.cluster_joint.col(c) - chain.cluster_joint.col(p)).norm();
    for (uint32_t s = tree.cluster_offsets[c]; s < tree.cluster_offsets[c + 1]; ++s)
      reach = std::max(reach, path[c] + (tree.rest_positions.col(tree.cluster_members[s]) - chain.cluster_joint.col(c)).norm());
  }
  return reach;
}

std::vector<double> limb_frequencies(const TreeModel& tree, const BarChain& chain) {
  const size_t C = tree.cluster_count(), V = tree.vertex_count();
  std::vector<double> stiffness(C, 0), inertia(C, 0);  // (C) sum m g.u, sum m |u|^2 of each limb
  for (const Eigen::Vector3d load : {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitZ()}) {
    // Each vertex's weight, turned along `load`, shared among its clusters; children before
    // parents (cluster_parent[c] < c), the moment about each joint of everything beyond it.
    Eigen::Matrix3Xd force = Eigen::Matrix3Xd::Zero(3, C), moment = Eigen::Matrix3Xd::Zero(3, C);
    for (size_t v = 0; v < V; ++v) {
      const uint32_t begin = tree.vertex_cluster_offsets[v], end = tree.vertex_cluster_offsets[v + 1];
      if (tree.vertex_anchored[v] || end == begin) continue;
      const Eigen::Vector3d f = load * (tree.vertex_mass[v] / double(end - begin));
      for (uint32_t s = begin; s < end; ++s) {
        const uint32_t c = tree.member_cluster[tree.vertex_memberships[s]];
        force.col(c) += f;
        moment.col(c) += (tree.rest_positions.col(v) - chain.cluster_joint.col(c)).cross(f);
      }
    }
    for (size_t c = C; c-- > 0;) {
      const int32_t p = tree.cluster_parent[c];
      if (p < 0) continue;
      force.col(p) += force.col(c);
      moment.col(p) += moment.col(c) + (chain.cluster_joint.col(c) - chain.cluster_joint.col(p)).cross(force.col(c));
    }
    // Each vertex moves with the deepest of its clusters; walking up from there, the turns of
    // the joints passed so far are its deflection in the limb clamped at the current joint.
    for (size_t v = 0; v < V; ++v) {
      const uint32_t begin = tree.vertex_cluster_offsets[v], end = tree.vertex_cluster_offsets[v + 1];
      if (tree.vertex_anchored[v] || end == begin) continue;
      int32_t c = static_cast<int32_t>(tree.member_cluster[tree.vertex_memberships[end - 1]]);
      const double m = tree.vertex_mass[v];
      Eigen::Vector3d u = Eigen::Vector3d::Zero();
      for (; c >= 0; c = tree.cluster_parent[c]) {
        u += (chain.cluster_compliance[c] * moment.col(c)).cross(tree.rest_positions.col(v) - chain.cluster_joint.col(c));
        stiffness[c] += m * load.dot(u);
        inertia[c] += m * u.squaredNorm();
      }
    }
  }
  std::vector<double> frequency(C, std::numeric_limits<double>::infinity());
  for (size_t c = 0; c < C; ++c)
    if (inertia[c] > 0 && stiffness[c] > 0) frequency[c] = std::sqrt(stiffness[c] / inertia[c]);
  return frequency;
}

}  // namespace treeanim
