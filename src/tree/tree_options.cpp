#include "tree/tree_options.h"

namespace treeanim {

TreeOptions scaled_tree_options(TreeOptions options, double factor) {
  options.scale *= factor;
  options.trunk_radius *= factor;
  options.min_radius *= factor;
  options.leaf.size *= factor;
  options.leaf.petiole *= factor;
  return options;
}

}  // namespace treeanim
