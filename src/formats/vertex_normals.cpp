#include "formats/vertex_normals.h"

#include <cmath>

#include "formats/rest_positions_f32.h"

namespace treeanim {

void vertex_normals(const TreeModel& model, const float* positions, const std::vector<float>& fallback,
                    std::vector<float>& normals) {
  const size_t n = model.vertex_count();
  // Summed in double, in triangle order: the same bytes for any thread count.
  std::vector<double> sum(3 * n, 0.0);
  for (size_t t = 0; t < model.triangle_count(); ++t) {
    const uint32_t* corner = &model.triangles[3 * t];
    const float* a = positions + 3 * corner[0];
    const float* b = positions + 3 * corner[1];
    const float* c = positions + 3 * corner[2];
    const double e1[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
    const double e2[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
    const double cross[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                             e1[0] * e2[1] - e1[1] * e2[0]};
    for (int k = 0; k < 3; ++k)
      for (int axis = 0; axis < 3; ++axis) sum[3 * corner[k] + axis] += cross[axis];
  }
  normals.resize(3 * n);
  for (size_t v = 0; v < n; ++v) {
    const double* s = &sum[3 * v];
    const double length = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    // Below this a sum is rounding noise of a collapsed triangle, not a direction.
    if (std::isfinite(length) && length > 1e-30) {
      for (int axis = 0; axis < 3; ++axis) normals[3 * v + axis] = float(s[axis] / length);
    } else if (!fallback.empty()) {
      for (int axis = 0; axis < 3; ++axis) normals[3 * v + axis] = fallback[3 * v + axis];
    } else {
      normals[3 * v] = 0.0f;
      normals[3 * v + 1] = 1.0f;
      normals[3 * v + 2] = 0.0f;
    }
  }
}

std::vector<float> rest_normals(const TreeModel& model) {
  const std::vector<float> rest = rest_positions_f32(model);
  std::vector<float> normals;
  vertex_normals(model, rest.data(), {}, normals);
  return normals;
}

}  // namespace treeanim
