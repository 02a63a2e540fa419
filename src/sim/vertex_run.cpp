#include "sim/vertex_run.h"

namespace treeanim {

std::vector<VertexRun> vertex_runs(const TreeModel& tree, const std::vector<uint8_t>& excluded) {
  const size_t V = tree.vertex_count();
  const std::vector<uint32_t>& offsets = tree.vertex_cluster_offsets;
  std::vector<uint8_t> runs(V, 0);  // (V) 1: in 1 to kMaxRunClusters clusters, not excluded
  for (size_t v = 0; v < V; ++v)
    runs[v] = !excluded[v] && offsets[v + 1] > offsets[v] && offsets[v + 1] - offsets[v] <= kMaxRunClusters;
  // v and v + 1 => whether v + 1 continues v's run: the same clusters, the next membership in each.
  auto continues = [&](size_t v) {
    const uint32_t n = offsets[v + 1] - offsets[v];
    if (!runs[v + 1] || offsets[v + 2] - offsets[v + 1] != n) return false;
    for (uint32_t j = 0; j < n; ++j) {
      const uint32_t slot = tree.vertex_memberships[offsets[v] + j], next = tree.vertex_memberships[offsets[v + 1] + j];
      if (next != slot + 1 || tree.member_cluster[next] != tree.member_cluster[slot]) return false;
    }
    return true;
  };
  std::vector<VertexRun> out;
  for (size_t v = 0; v < V;) {
    if (!runs[v]) {
      ++v;
      continue;
    }
    VertexRun run = {static_cast<uint32_t>(v), 0, offsets[v + 1] - offsets[v], {}, {}};
    for (uint32_t j = 0; j < run.count; ++j) {
      run.first_slot[j] = tree.vertex_memberships[offsets[v] + j];
      run.cluster[j] = tree.member_cluster[run.first_slot[j]];
    }
    while (v + 1 < V && continues(v)) ++v;
    run.end = static_cast<uint32_t>(++v);
    out.push_back(run);
  }
  return out;
}

}  // namespace treeanim
