#pragma once
// The forest stage (docs/outputs.md "Forest stage"): forest.usda beside the forest manifest, a
// prim per tree referencing that tree's USD layer, placed where the forest puts the tree, so one
// stage opens the whole forest.
#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace treeanim {

// One tree of the stage.
struct ForestStageTree {
  std::string id;                                        // the forest's tree id (the prim is named after it)
  std::string layer;                                     // the tree's .usda, relative to the stage's folder or absolute
  Eigen::Vector3d translation = Eigen::Vector3d::Zero(); // m, world position of the tree's base
  double rotation_degrees = 0;                           // about +Y, counter-clockwise seen from above
};

// The stage's timing: the time codes the tree layers hold.
struct ForestStageTime {
  double fps = 24;
  long long start = 0;  // first time code
  long long end = 0;    // last time code
};

// trees, timing => the stage's USDA text. A tree's scale is grown into its layer, so no prim scales.
std::string forest_usda(const std::vector<ForestStageTree>& trees, const ForestStageTime& time);

// Writes forest_usda() to `path` atomically. Throws OutputError naming the path.
void write_forest_usda(const std::filesystem::path& path, const std::vector<ForestStageTree>& trees,
                       const ForestStageTime& time);

}  // namespace treeanim
