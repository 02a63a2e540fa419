#pragma once
// Grown trees and gusty winds for whole-bake tests (tests/sim, tests/io): header-only, so any
// test executable can use them.
#include <filesystem>

#include "lsystem/lsystem.h"
#include "sim/sim_options.h"
#include "tree/build_tree_model.h"

namespace treeanim::testing {

// The Table-1 monopodial grammar grown `iterations` seasons with `leaves` per node.
inline TreeModel grown_tree(int iterations, int leaves, int segments_per_cluster,
                            MeshSurface surface = MeshSurface::kBuilt) {
  LsystemOptions lsystem;
  lsystem.grammar = std::filesystem::path(TREEANIM_SOURCE_DIR) / "grammars/table1-monopodial.lsys";
  lsystem.iterations = iterations;
  lsystem.tropism_elasticity = 0.01;
  lsystem.defines = {{"K", 4}, {"NP", leaves}, {"LT", 1}};
  GrowthStats stats;
  const Skeleton skeleton = grow_skeleton(lsystem, &stats);
  TreeOptions tree;
  tree.trunk_radius = 0.1;
  tree.cluster.segments_per_cluster = segments_per_cluster;
  return build_tree_model(skeleton, tree, surface);
}

// Gusts of `speed` (m/s) until blow_until (s), calm from calm_from (s).
inline WindOptions gust_then_calm(double speed, double blow_until, double calm_from) {
  WindOptions wind;
  wind.keys = {{0, speed, {1, 0, 0.2}, speed * 0.3}, {blow_until, speed, {1, 0, 0.2}, speed * 0.3},
               {calm_from, 0, {1, 0, 0.2}, 0}};
  return wind;
}

}  // namespace treeanim::testing
