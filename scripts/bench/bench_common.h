#pragma once
// Helpers of the solver benchmarks (bench_sim, bench/bullet/bench_bullet): timing, the
// command line, the tree of a scene.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>

#include "common/seconds_since.h"
#include "lsystem/lsystem.h"
#include "scene/scene.h"
#include "tree/build_tree_model.h"

namespace treeanim::bench {

using treeanim::seconds_since;  // common/seconds_since.h

// argv = NAME SCENE [options], `usage` its options => false (after a message) when the scene
// is missing or an option is unknown. "--frames N" sets `frames`; `option(arg, i)` takes
// the others (it may consume argv[i + 1] by advancing i) and returns false for an unknown one.
inline bool parse_arguments(int argc, char** argv, const char* usage, long long& frames,
                            const std::function<bool(const std::string&, int&)>& option) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s SCENE %s\n", argv[0], usage);
    return false;
  }
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--frames" && i + 1 < argc) frames = std::atoll(argv[++i]);
    else if (!option(arg, i)) {
      std::fprintf(stderr, "%s: unknown argument '%s'\nusage: %s SCENE %s\n", argv[0], arg.c_str(), argv[0], usage);
      return false;
    }
  }
  return true;
}

// Scene => its grown tree model (build_tree_model validates it).
inline TreeModel scene_model(const Scene& scene) {
  GrowthStats growth;
  return build_tree_model(grow_skeleton(scene.lsystem, &growth), scene.tree);
}

}  // namespace treeanim::bench
