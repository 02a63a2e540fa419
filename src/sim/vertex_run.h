#pragma once
// Runs of consecutive vertices in the same clusters, which a loop takes with their clusters'
// values read once (the solver's goal writes, SolverModel::vertex_runs; the samples' mesh, SampleSkin).
#include <cstdint>
#include <vector>

#include "tree/tree_model.h"

namespace treeanim {

// The most clusters a vertex of a run may be in: a branch's vertices are in one, the rings
// where two clusters overlap in two.
constexpr uint32_t kMaxRunClusters = 4;

// Vertices [begin, end) in the same `count` clusters: vertex v's membership in cluster[j] is
// first_slot[j] + (v - begin).
struct VertexRun {
  uint32_t begin, end, count;
  uint32_t first_slot[kMaxRunClusters], cluster[kMaxRunClusters];
};

// The tree's vertices in 1 to kMaxRunClusters clusters, but those `excluded` flags (V), as
// runs: consecutive vertices in the same clusters, in the same order, with consecutive
// memberships in each, ascending.
std::vector<VertexRun> vertex_runs(const TreeModel& tree, const std::vector<uint8_t>& excluded);

}  // namespace treeanim
