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

namespace {

// Each vertex's cluster in the limb sums: the deepest of its clusters; -1 for an anchored vertex
// or one in no cluster, which no joint moves.
int32_t limb_cluster(const TreeModel& tree, size_t v) {
  const uint32_t begin = tree.vertex_cluster_offsets[v], end = tree.vertex_cluster_offsets[v + 1];
  if (tree.vertex_anchored[v] || end == begin) return -1;
  return static_cast<int32_t>(tree.member_cluster[tree.vertex_memberships[end - 1]]);
}

// The vertices' weight turned along `load`, shared among their clusters => per cluster, the
// moment about its joint of everything beyond it.
Eigen::Matrix3Xd limb_moments(const TreeModel& tree, const BarChain& chain, const Eigen::Vector3d& load) {
  const size_t C = tree.cluster_count(), V = tree.vertex_count();
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
  // Children before parents (cluster_parent[c] < c).
  for (size_t c = C; c-- > 0;) {
    const int32_t p = tree.cluster_parent[c];
    if (p < 0) continue;
    force.col(p) += force.col(c);
    moment.col(p) += moment.col(c) + (chain.cluster_joint.col(c) - chain.cluster_joint.col(p)).cross(force.col(c));
  }
  return moment;
}

// Rayleigh's sums by walking up from each vertex: the turns of the joints passed so far are its
// deflection u in the limb clamped at the current joint; sum m g.u and m |u|^2 added per joint.
// Work: each vertex times its depth in the cluster tree.
void walked_limb_sums(const TreeModel& tree, const BarChain& chain, const Eigen::Vector3d& load,
                      const Eigen::Matrix3Xd& moment, std::vector<double>& stiffness, std::vector<double>& inertia) {
  for (size_t v = 0; v < tree.vertex_count(); ++v) {
    int32_t c = limb_cluster(tree, v);
    const double m = tree.vertex_mass[v];
    Eigen::Vector3d u = Eigen::Vector3d::Zero();
    for (; c >= 0; c = tree.cluster_parent[c]) {
      u += (chain.cluster_compliance[c] * moment.col(c)).cross(tree.rest_positions.col(v) - chain.cluster_joint.col(c));
      stiffness[c] += m * load.dot(u);
      inertia[c] += m * u.squaredNorm();
    }
  }
}

// Each limb's mass moments about its own joint: mass (C), sum m r (3 x C) and sum m r r^T
// (9 x C, column-major), r = x - j_c, over the vertices whose deepest cluster is in the limb;
// a child's moments moved to its parent's joint by the parallel-axis rule, so that no sum
// subtracts two large numbers however far the limb is from the origin.
struct LimbMoments {
  std::vector<double> mass;
  Eigen::Matrix3Xd first;
  Eigen::Matrix<double, 9, Eigen::Dynamic> second;
};

LimbMoments limb_moments_about_joints(const TreeModel& tree, const BarChain& chain) {
  const size_t C = tree.cluster_count();
  LimbMoments limb = {std::vector<double>(C, 0), Eigen::Matrix3Xd::Zero(3, C),
                      Eigen::Matrix<double, 9, Eigen::Dynamic>::Zero(9, C)};
  for (size_t v = 0; v < tree.vertex_count(); ++v) {
    const int32_t c = limb_cluster(tree, v);
    if (c < 0) continue;
    const double m = tree.vertex_mass[v];
    const Eigen::Vector3d r = tree.rest_positions.col(v) - chain.cluster_joint.col(c);
    limb.mass[c] += m;
    limb.first.col(c) += m * r;
    limb.second.col(c) += (m * r * r.transpose()).reshaped();
  }
  for (size_t c = C; c-- > 0;) {
    const int32_t p = tree.cluster_parent[c];
    if (p < 0) continue;
    const Eigen::Vector3d d = chain.cluster_joint.col(c) - chain.cluster_joint.col(p), r = limb.first.col(c);
    limb.mass[p] += limb.mass[c];
    limb.first.col(p) += r + limb.mass[c] * d;
    limb.second.col(p) += (limb.second.col(c).reshaped(3, 3) + r * d.transpose() + d * r.transpose() +
                           limb.mass[c] * d * d.transpose())
                              .reshaped();
  }
  return limb;
}

// The same sums from each limb's mass moments, children before parents, in work linear in the
// tree. With t = C_c M_c the joint's turn and r = x - j_c, a vertex's u at joint c is its u at the
// child k below plus t x r; so over the limb, with d = j_k - j_c, S = sum m u, T = sum m r x u and
// I = sum m |u|^2 follow from the children's: S_c = sum S_k + t x sum m r,
// T_c = sum (T_k + d x S_k) + sum m r x (t x r), I_c = sum (I_k + 2 t.(T_k + d x S_k)) +
// sum m |t x r|^2, each last sum from the limb's moments about j_c. Equal to walked_limb_sums'
// but for round-off (within 1.4e-14 of them on an axis of 1,024 clusters).
void summed_limb_sums(const TreeModel& tree, const BarChain& chain, const Eigen::Vector3d& load,
                      const Eigen::Matrix3Xd& moment, const LimbMoments& limb, std::vector<double>& stiffness,
                      std::vector<double>& inertia) {
  const size_t C = tree.cluster_count();
  Eigen::Matrix3Xd S = Eigen::Matrix3Xd::Zero(3, C), T = Eigen::Matrix3Xd::Zero(3, C);
  std::vector<double> I(C, 0);
  for (size_t c = C; c-- > 0;) {
    const Eigen::Vector3d t = chain.cluster_compliance[c] * moment.col(c);
    const Eigen::Matrix3d rr = limb.second.col(c).reshaped(3, 3);
    S.col(c) += t.cross(limb.first.col(c));
    T.col(c) += t * rr.trace() - rr * t;
    I[c] += t.squaredNorm() * rr.trace() - t.dot(rr * t);
    stiffness[c] += load.dot(S.col(c));
    inertia[c] += I[c];
    const int32_t p = tree.cluster_parent[c];
    if (p < 0) continue;
    const Eigen::Vector3d moved = T.col(c) + (chain.cluster_joint.col(c) - chain.cluster_joint.col(p)).cross(S.col(c));
    I[p] += I[c] + 2 * (chain.cluster_compliance[p] * moment.col(p)).dot(moved);
    S.col(p) += S.col(c);
    T.col(p) += moved;
  }
}

}  // namespace

std::vector<double> limb_frequencies(const TreeModel& tree, const BarChain& chain, size_t most_walked) {
  const size_t C = tree.cluster_count(), V = tree.vertex_count();
  // The walks' work: the sum over the vertices of their depth in the cluster tree.
  std::vector<size_t> depth(C, 1);
  for (size_t c = 0; c < C; ++c)
    if (tree.cluster_parent[c] >= 0) depth[c] = depth[tree.cluster_parent[c]] + 1;
  size_t walked = 0;
  for (size_t v = 0; v < V; ++v)
    if (const int32_t c = limb_cluster(tree, v); c >= 0) walked += depth[c];
  const bool walk = walked <= most_walked;
  const LimbMoments limb = walk ? LimbMoments() : limb_moments_about_joints(tree, chain);
  std::vector<double> stiffness(C, 0), inertia(C, 0);  // (C) sum m g.u, sum m |u|^2 of each limb
  for (const Eigen::Vector3d load : {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitZ()}) {
    const Eigen::Matrix3Xd moment = limb_moments(tree, chain, load);
    if (walk)
      walked_limb_sums(tree, chain, load, moment, stiffness, inertia);
    else
      summed_limb_sums(tree, chain, load, moment, limb, stiffness, inertia);
  }
  std::vector<double> frequency(C, std::numeric_limits<double>::infinity());
  for (size_t c = 0; c < C; ++c)
    if (inertia[c] > 0 && stiffness[c] > 0) frequency[c] = std::sqrt(stiffness[c] / inertia[c]);
  return frequency;
}

}  // namespace treeanim
