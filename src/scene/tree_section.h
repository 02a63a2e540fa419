#pragma once
// Scene section /tree (docs/scene.md) => the tree stage's options.
#include "scene/scene_reader.h"
#include "tree/tree_options.h"

namespace treeanim {

// /tree section => options; a key the section leaves out takes its value from `defaults` (a
// species' preset, or the built-in defaults).
TreeOptions read_tree_options(SceneObject section, TreeOptions defaults = {});

}  // namespace treeanim
