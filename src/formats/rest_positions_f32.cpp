#include "formats/rest_positions_f32.h"

namespace treeanim {

std::vector<float> rest_positions_f32(const TreeModel& model) {
  const double* rest = model.rest_positions.data();
  return std::vector<float>(rest, rest + 3 * model.vertex_count());
}

}  // namespace treeanim
