#pragma once
// Per-vertex normals of a frame, for outputs that carry them ("normals": true).
#include <vector>

#include "tree/tree_model.h"

namespace treeanim {

// Area-weighted unit normals of the model's triangles at `positions` (V*3 float, m) => `normals`
// (V*3 float). The sum of a vertex's triangle cross products weights each triangle by its area.
// A leaf is one sheet of triangles (docs/tree.md), so its vertices get its front face's normal;
// a renderer shades the back with the flipped normal (a double-sided material). A vertex on no
// triangle of non-zero area takes `fallback` (V*3; the rest normals), or +Y when that is empty,
// so every normal is finite and of unit length.
void vertex_normals(const TreeModel& model, const float* positions, const std::vector<float>& fallback,
                    std::vector<float>& normals);

// The normals of the rest pose (float, as the sinks write it), +Y where no triangle says more.
std::vector<float> rest_normals(const TreeModel& model);

}  // namespace treeanim
