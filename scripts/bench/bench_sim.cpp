// Solver timing (not a test): scene file => grown tree => time per substep at the given
// thread counts, peak memory, and the speed of a calm, settled half.
//   bench_sim SCENE [--frames N] [--threads 1,2] [--precision float|double] [--particles vertices|samples]
//             [--calm-half]
// With samples (hsm.particles) the counts and times are the samples' (docs/solver.md, "Particles").
#include <omp.h>
#include <sys/resource.h>

#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "bench_common.h"
#include "sim/particle_model.h"
#include "sim/simulator.h"
#include "sim/stiffness.h"

using namespace treeanim;
using bench::seconds_since;

namespace {

double peak_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;
}

// Frames [first, last] of a bake => wall seconds.
double bake(Simulator& sim, SimState& state, long long first, long long last) {
  const auto start = std::chrono::steady_clock::now();
  for (long long f = first; f <= last; ++f) sim.advance_frame(state, f);
  return seconds_since(start);
}

}  // namespace

int main(int argc, char** argv) {
  long long frames = 48;
  std::vector<int> threads{1, 2};
  bool calm_half = false;
  std::string precision;  // empty: the scene's /hsm/precision
  std::string particles;  // empty: the scene's /hsm/particles
  const bool parsed = bench::parse_arguments(
      argc, argv, "[--frames N] [--threads 1,2] [--precision float|double] [--particles vertices|samples] [--calm-half]", frames,
      [&](const std::string& arg, int& i) {
        if (arg == "--threads" && i + 1 < argc) {
          threads.clear();
          std::stringstream list(argv[++i]);
          for (std::string item; std::getline(list, item, ',');) threads.push_back(std::atoi(item.c_str()));
        } else if (arg == "--precision" && i + 1 < argc &&
                   (std::string(argv[i + 1]) == "float" || std::string(argv[i + 1]) == "double")) {
          precision = argv[++i];
        } else if (arg == "--particles" && i + 1 < argc &&
                   (std::string(argv[i + 1]) == "vertices" || std::string(argv[i + 1]) == "samples")) {
          particles = argv[++i];
        } else if (arg == "--calm-half") {
          calm_half = true;
        } else {
          return false;
        }
        return true;
      });
  if (!parsed) return 2;
  try {
    Scene scene = load_scene(argv[1], {});
    if (!precision.empty()) scene.hsm.precision = precision == "float" ? Precision::kFloat : Precision::kDouble;
    if (!particles.empty())
      scene.hsm.particles = particles == "samples" ? ParticleMode::kSamples : ParticleMode::kVertices;
    const TreeModel model = scene.hsm.particles == ParticleMode::kSamples ? sample_tree_model(bench::scene_model(scene))
                                                                          : bench::scene_model(scene);
    const double frame_dt = 1.0 / scene.time.fps;
    const int substeps = scene.time.substeps;
    const StepRates rates = compute_step_rates(model, scene.hsm, frame_dt / substeps);
    std::printf("%s: %zu vertices, %zu clusters, %zu memberships, %zu leaves; %d substeps/frame; "
                "%.0f%% of branch clusters at alpha = 1; %s precision\n",
                argv[1], model.vertex_count(), model.cluster_count(), model.membership_count(), model.leaf_count(),
                substeps, 100 * rates.capped_fraction, scene.hsm.precision == Precision::kFloat ? "float" : "double");
    if (calm_half) {
      // Wind for the first half, calm for the second: time the settled tail against the
      // windy first half (sleeping on, as in the scene).
      scene.wind.keys = {{0, 8, {1, 0, 0.2}, 2}, {frames * frame_dt / 2, 8, {1, 0, 0.2}, 2},
                         {frames * frame_dt / 2 + 0.5, 0, {1, 0, 0.2}, 0}};
      Simulator sim(model, scene.hsm, scene.wind, frame_dt, substeps);
      SimState state = sim.initial_state(0);
      const long long half = frames / 2;
      const double windy = bake(sim, state, 1, half);
      long long settled = half + 1;
      while (settled <= frames && !state.island_asleep.empty() && !state.island_asleep[0])
        sim.advance_frame(state, settled++);
      const double calm = bake(sim, state, settled, frames);
      std::printf("windy half: %.3f ms/frame; calm after settling at frame %lld: %.4f ms/frame (%.0fx faster)\n",
                  1e3 * windy / half, settled, 1e3 * calm / std::max(1LL, frames - settled + 1),
                  (windy / half) / (calm / std::max(1LL, frames - settled + 1)));
      return 0;
    }
    for (int t : threads) {
      omp_set_num_threads(t);
      scene.hsm.sleep = false;  // time the full step
      Simulator sim(model, scene.hsm, scene.wind, frame_dt, substeps);
      SimState state = sim.initial_state(0);
      bake(sim, state, 1, 2);  // warm caches and the rotation warm starts
      const std::clock_t cpu = std::clock();
      const double wall = bake(sim, state, 3, frames + 2);
      const double cpu_s = double(std::clock() - cpu) / CLOCKS_PER_SEC;
      std::printf("threads %d: %.3f ms per substep (wall), %.3f ms CPU per substep\n", t,
                  1e3 * wall / double(frames * substeps), 1e3 * cpu_s / double(frames * substeps));
    }
    std::printf("peak memory (model + solver, no outputs): %.1f MiB\n", peak_mib());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_sim: %s\n", e.what());
    return 1;
  }
  return 0;
}
