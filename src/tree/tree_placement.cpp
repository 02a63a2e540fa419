#include "tree/tree_placement.h"

#include <cmath>
#include <numbers>

namespace treeanim {

TreePlacement make_tree_placement(const Eigen::Vector3d& position, double rotation_degrees) {
  TreePlacement placement;
  // Whole quarter turns exactly: sin(pi) is 1.2e-16, and a tree turned by 180 degrees should
  // keep its zeros.
  const double turns = rotation_degrees / 90.0;
  double c = std::cos(rotation_degrees * std::numbers::pi / 180.0), s = std::sin(rotation_degrees * std::numbers::pi / 180.0);
  if (turns == std::floor(turns)) {
    const long long quarter = ((static_cast<long long>(std::fmod(turns, 4.0)) % 4) + 4) % 4;
    c = quarter == 0 ? 1 : quarter == 2 ? -1 : 0;
    s = quarter == 1 ? 1 : quarter == 3 ? -1 : 0;
  }
  placement.rotation << c, 0, s, 0, 1, 0, 0.0 - s, 0, c;  // 0 - s: no -0 in the manifest
  placement.translation = position;
  return placement;
}

TreeModel placed_tree_model(TreeModel model, const TreePlacement& placement) {
  model.rest_positions = (placement.rotation * model.rest_positions).colwise() + placement.translation;
  for (size_t s = 0; s < model.segment_count(); ++s) {
    model.segment_start[s] = placement.rotation * model.segment_start[s] + placement.translation;
    model.segment_end[s] = placement.rotation * model.segment_end[s] + placement.translation;
  }
  return model;
}

}  // namespace treeanim
