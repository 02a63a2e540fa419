#pragma once
// Where a tree of a forest stands: a turn about +Y, then a translation. The simulation runs on
// the placed (world) copy of the model, so the wind is sampled where the tree stands; the
// outputs keep the tree's own frame, which the forest manifest places again (docs/outputs.md
// "Forest manifest"). A tree's scale is not part of it: it is grown into the model.
#include <Eigen/Core>

#include "tree/tree_model.h"

namespace treeanim {

struct TreePlacement {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();    // world from tree, a turn about +Y
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();     // m, the tree's base in the world
};

// position (m), rotation (degrees, counter-clockwise about +Y seen from above) => placement.
TreePlacement make_tree_placement(const Eigen::Vector3d& position, double rotation_degrees);

// The model moved to where it stands: rest positions and skeleton turned and translated;
// masses, areas, clusters and everything else as they are.
TreeModel placed_tree_model(TreeModel model, const TreePlacement& placement);

}  // namespace treeanim
