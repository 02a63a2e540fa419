#pragma once
#include "lsystem/skeleton.h"
#include "tree/tree_model.h"
#include "tree/tree_options.h"

namespace treeanim {

// skeleton (scene units) + tree options => immutable TreeModel (m, kg): mesh, clusters, masses;
// with MeshSurface::kOmitted no UVs, triangles or materials, and every other array the same.
TreeModel build_tree_model(const Skeleton& skeleton, const TreeOptions& options,
                           MeshSurface surface = MeshSurface::kBuilt);

}  // namespace treeanim
