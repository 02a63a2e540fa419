#pragma once
// treeanim run of a forest (docs/farm.md): its trees (or those of one shard) baked one after
// another, each grown, simulated, written and freed before the next, a manifest part per tree.
#include "cli/commands.h"
#include "scene/scene.h"

namespace treeanim {

// Bakes the trees of request.shard (all without one). With --resume a tree whose part says it
// is complete is skipped and the tree in progress resumes from its checkpoint. Without a shard,
// writes OUT/forest.json at the end. Returns 0, or 130/143 on a signal.
int run_forest(const Scene& scene, const RunRequest& request);

}  // namespace treeanim
