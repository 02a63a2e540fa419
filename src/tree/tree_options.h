#pragma once
// Scene section /tree (docs/scene.md). Owned by tree/; fields are added as the mesher needs.
#include "common/scene_reader.h"

namespace treeanim {

struct TreeOptions {
  double scale = 1.0;          // metres per scene unit
  int ring_sides = 8;          // vertices per branch ring
  double trunk_radius = 0.1;   // m, trunk base radius when the grammar sets no widths
  double min_radius = 0.002;   // m, no branch thinner
  double wood_density = 700;   // kg/m^3
};

// /tree section => options.
TreeOptions read_tree_options(SceneObject section);

}  // namespace treeanim
