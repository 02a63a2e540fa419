// Benchmark of tree building: scene files => per scene the derivation + turtle time, the
// model time and the counts (segments, leaves, vertices, clusters, triangles).
// Usage: bench_tree [--repeat N] scene.json...   (prints the best of N runs, default 5)
// Reads only /lsystem, /tree and /seed, so it needs no other stage of the pipeline.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "common/errors.h"
#include "lsystem/lsystem.h"
#include "scene/lsystem_section.h"
#include "scene/tree_section.h"
#include "tree/build_tree_model.h"

namespace {

using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// One scene file => its best grow and model times over `repeat` runs, and the counts printed.
void bench_scene(const std::string& file, int repeat) {
  std::ifstream in(file);
  if (!in) throw treeanim::InputError(file + ": cannot open");
  treeanim::Json document = treeanim::Json::parse(in);
  const std::filesystem::path dir = std::filesystem::path(file).parent_path();
  treeanim::SceneReader reader(document, dir.empty() ? "." : dir, file);
  treeanim::SceneObject root = reader.root();
  const uint64_t seed = uint64_t(document.value("seed", 1));
  const treeanim::LsystemOptions lsystem = treeanim::read_lsystem_options(root.object("lsystem"), seed);
  const treeanim::TreeOptions tree = treeanim::read_tree_options(root.object("tree"));
  double best_grow = std::numeric_limits<double>::infinity(), best_model = best_grow;
  for (int r = 0; r < repeat; ++r) {
    const auto t0 = Clock::now();
    treeanim::GrowthStats stats;
    const treeanim::Skeleton skeleton = treeanim::grow_skeleton(lsystem, &stats);
    const auto t1 = Clock::now();
    const treeanim::TreeModel model = treeanim::build_tree_model(skeleton, tree);
    const auto t2 = Clock::now();
    best_grow = std::min(best_grow, seconds(t0, t1));
    best_model = std::min(best_model, seconds(t1, t2));
    if (r == 0) {
      size_t leaf_clusters = size_t(std::count(model.cluster_kind.begin(), model.cluster_kind.end(), uint8_t(treeanim::kClusterLeaf)));
      std::printf("%s: modules %zu segments %zu leaves %zu vertices %zu clusters %zu (leaf %zu) triangles %zu memberships %zu\n",
                  file.c_str(), stats.modules, skeleton.segment_count(), skeleton.leaf_count(),
                  model.vertex_count(), model.cluster_count(), leaf_clusters, model.triangle_count(),
                  model.membership_count());
    }
  }
  std::printf("%s: best of %d: derivation+turtle %.2f ms, model %.2f ms, total %.2f ms\n", file.c_str(), repeat,
              1e3 * best_grow, 1e3 * best_model, 1e3 * (best_grow + best_model));
}

}  // namespace

int main(int argc, char** argv) {
  int repeat = 5;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--repeat" && i + 1 < argc)
      repeat = std::max(1, std::atoi(argv[++i]));
    else
      files.push_back(arg);
  }
  try {
    for (const std::string& f : files) bench_scene(f, repeat);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_tree: %s\n", e.what());
    return 2;
  }
  return 0;
}
