#pragma once
// Shared front half of run, validate and info: scene => skeleton => tree model.
#include <functional>

#include "lsystem/lsystem.h"
#include "scene/scene.h"
#include "tree/tree_model.h"

namespace treeanim {

struct PreparedTree {
  GrowthStats growth;
  Skeleton skeleton;       // scene units
  TreeModel model;         // m, kg; validated
  double grow_seconds = 0;   // derivation + turtle
  double model_seconds = 0;  // mesh, clusters, masses
};

// scene => derived skeleton and validated TreeModel, with or without its surface; `grown_step`
// is told of each derivation step (its number, of how many, and the modules it made). Throws
// InputError.
PreparedTree prepare_tree(const Scene& scene, MeshSurface surface = MeshSurface::kBuilt,
                          const std::function<void(int step, int steps, size_t modules)>& grown_step = {});

// Counts and estimates of `info --json` (DESIGN keys: derivation.*, skeleton.*, mesh.*, model.*,
// estimate.*).
Json tree_summary(const Scene& scene, const PreparedTree& tree);

}  // namespace treeanim
