#pragma once
// One tree's bake: simulate and write every output, with checkpoints and resume
// (docs/checkpoint.md). `treeanim run` of a one-tree scene is one call; a forest calls it per tree.
#include <Eigen/Geometry>
#include <filesystem>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "scene/scene.h"
#include "tree/tree_placement.h"

namespace treeanim {

// What a finished bake wrote, for the forest manifest.
struct TreeBakeResult {
  int exit_code = 0;                                    // 0, or 130/143 when interrupted
  std::vector<std::vector<std::filesystem::path>> files;  // (outputs) every file of each output
  Eigen::AlignedBox3d bounds;                           // m, world box of every written frame's vertices
  long long frame_start = 0;                            // first frame written
  long long frame_count = 0;                            // frames written
  size_t vertices = 0;
};

// Bakes `scene` as `request` says (its checkpoint_dir is this tree's, "" = the default). With a
// placement the tree is simulated where it stands and its outputs are written in its own frame.
// Throws InputError, SimulationError, OutputError; nothing of a failed bake keeps a final name.
TreeBakeResult bake_tree(const Scene& scene, const RunRequest& request, const TreePlacement* placement);

}  // namespace treeanim
