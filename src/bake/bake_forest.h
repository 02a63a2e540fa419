#pragma once
// The bake of a forest (docs/farm.md): its trees, or those of one shard (forest_tasks.h), baked
// one after another, each grown, simulated, written and freed before the next, a manifest part
// per tree.
#include <cstddef>
#include <vector>

#include "bake/bake_config.h"
#include "bake/bake_log.h"
#include "scene/scene.h"

namespace treeanim {

struct ForestBakeResult {
  int exit_code = 0;   // 0, or 130/143/129 when a tree's bake was interrupted
  size_t baked = 0;    // trees baked by this process
  size_t skipped = 0;  // trees complete before (--resume)
};

// Every file the forest would write has one writer (the manifest, each tree's outputs and
// part), wherever it bakes, and each tree's is absent or a regular file that is none of the
// inputs: InputError as a whole forest's bake reports it (`passed`: as each tree's are). Writes
// nothing.
void check_forest_writers(const Scene& scene, const TreesPassed& passed);

// Bakes `trees` (shard_trees()) of the forest. With --resume a tree whose part says it is
// complete is skipped and the tree in progress resumes from its checkpoint. Without a shard,
// writes OUT/forest.json at the end (OutputError when a tree's files went missing meanwhile).
ForestBakeResult bake_forest(const Scene& scene, const BakeConfig& config, const std::vector<size_t>& trees,
                             const BakeLog& log);

}  // namespace treeanim
