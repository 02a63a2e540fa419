// Axis structure and branch radii of a Skeleton.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "tree/tree_build_steps.h"

namespace treeanim {

SegmentTopology segment_topology(const Skeleton& skeleton, double scale) {
  const size_t S = skeleton.segment_count();
  SegmentTopology t;
  t.continuation.assign(S, -1);
  t.starts_axis.assign(S, 1);
  t.lateral_count.assign(S, 0);
  t.leaf_count.assign(S, 0);
  t.direction.resize(S);
  t.length.resize(S);
  for (size_t s = 0; s < S; ++s) {
    const int32_t p = skeleton.segment_parent[s];
    // The turtle state is linear between brackets, so an axis has at most one continuation;
    // a second claimant (malformed input) is meshed as a lateral rather than rejected.
    if (p >= 0 && skeleton.segment_continues_parent[s] && t.continuation[p] < 0) {
      t.continuation[p] = int32_t(s);
      t.starts_axis[s] = 0;
    } else if (p >= 0) {
      ++t.lateral_count[p];
    }
    const Eigen::Vector3d d = (skeleton.segment_end[s] - skeleton.segment_start[s]) * scale;
    t.length[s] = d.norm();
    // A zero-length F has no direction of its own: it keeps its parent's (the trunk's: up).
    if (t.length[s] > 0)
      t.direction[s] = d / t.length[s];
    else
      t.direction[s] = p >= 0 ? t.direction[p] : Eigen::Vector3d::UnitY();
  }
  for (int32_t s : skeleton.leaf_segment)
    if (s >= 0) ++t.leaf_count[s];
  return t;
}

// Pipe model (da Vinci): every tip carries one unit of r^k, a segment carries the sum of its
// children, so r_parent^k = sum r_child^k holds at every branching. Scaled so the heaviest
// root gets trunk_radius. => (S) base radius in metres, before tapering and clamping.
static std::vector<double> pipe_radii(const Skeleton& skeleton, const TreeOptions& options) {
  const size_t S = skeleton.segment_count();
  std::vector<double> load(S, 0.0);
  for (size_t i = S; i-- > 0;) {
    if (load[i] == 0.0) load[i] = 1.0;
    if (skeleton.segment_parent[i] >= 0) load[skeleton.segment_parent[i]] += load[i];
  }
  double root_load = 1.0;
  for (size_t s = 0; s < S; ++s)
    if (skeleton.segment_parent[s] < 0) root_load = std::max(root_load, load[s]);
  const double inv_k = 1.0 / options.pipe_exponent;
  for (double& r : load) r = options.trunk_radius * std::pow(r / root_load, inv_k);
  return load;
}

// Pipe radii only change at branchings, so an internode drawn as several segments would be a
// cylinder ending in a cone. Each run of segments between branchings (or up to the tip) gets
// its step spread linearly over its arc length instead: the pipe value holds at the run's
// base, the run ends at its continuation's value (at a tip: tip_taper times the base).
static void taper_runs(const SegmentTopology& topology, double tip_taper, std::vector<double>& radius) {
  const std::vector<double> step = radius;
  for (size_t first = 0; first < step.size(); ++first) {
    if (!topology.starts_axis[first]) continue;
    for (int32_t j = int32_t(first); j >= 0;) {
      int32_t k = j;
      double run_length = topology.length[j];
      while (topology.lateral_count[k] == 0 && topology.continuation[k] >= 0) {
        k = topology.continuation[k];
        run_length += topology.length[k];
      }
      const int32_t next = topology.continuation[k];
      const double r0 = step[j], r1 = next >= 0 ? step[next] : step[j] * tip_taper;
      double arc = 0;
      for (int32_t i = j;; i = topology.continuation[i]) {
        radius[i] = run_length > 0 ? r0 + (r1 - r0) * (arc / run_length) : r0;
        arc += topology.length[i];
        if (i == k) break;
      }
      j = next;
    }
  }
}

void segment_radii(const Skeleton& skeleton, const SegmentTopology& topology,
                   const TreeOptions& options, TreeModel& model) {
  const size_t S = skeleton.segment_count();
  const bool any_unset = std::any_of(skeleton.segment_width.begin(), skeleton.segment_width.end(),
                                     [](double w) { return std::isnan(w); });
  std::vector<double> pipe;
  if (any_unset) {
    pipe = pipe_radii(skeleton, options);
    taper_runs(topology, options.tip_taper, pipe);
  }
  model.segment_radius_base.resize(S);
  model.segment_radius_top.resize(S);
  for (size_t s = 0; s < S; ++s) {
    const double w = skeleton.segment_width[s];
    const double r = std::isnan(w) ? pipe[s] : 0.5 * w * options.scale * options.width_scale;
    model.segment_radius_base[s] = std::max(r, options.min_radius);
  }
  // The top of a segment is the base of its continuation, so an axis tapers without steps.
  for (size_t s = 0; s < S; ++s) {
    const int32_t c = topology.continuation[s];
    model.segment_radius_top[s] =
        c >= 0 ? model.segment_radius_base[c]
               : std::max(model.segment_radius_base[s] * options.tip_taper, options.min_radius);
  }
}

double truncated_cone_volume(double r_base, double r_top, double length) {
  return std::numbers::pi / 3.0 * (r_top * r_top + r_top * r_base + r_base * r_base) * length;
}

}  // namespace treeanim
