#pragma once
// The rest pose as the sinks write it: every output stores positions in float.
#include <vector>

#include "tree/tree_model.h"

namespace treeanim {

// TreeModel rest positions (double) => (V*3) float.
std::vector<float> rest_positions_f32(const TreeModel& model);

}  // namespace treeanim
