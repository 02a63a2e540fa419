#pragma once
// Scene section /tree (docs/scene.md) => the tree stage's options.
#include "scene/scene_reader.h"
#include "tree/tree_options.h"

namespace treeanim {

// /tree section => options.
TreeOptions read_tree_options(SceneObject section);

}  // namespace treeanim
