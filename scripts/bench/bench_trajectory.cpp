// A bake's positions in double precision (not a test), for scripts/bench-accuracy: the HDF5
// bake stores float32 positions, which round a point 10 m from the origin to 0.5 µm, above the
// error of a fine step against the reference.
//   bench_trajectory SCENE --out FILE [--frames N] [--set PATH=JSON]...
// FILE: raw little-endian float64, frames 0 .. N-1 (N: the scene's time.frames unless given)
// of the V x 3 vertex positions, in metres, the order of the HDF5 bake's /frames/positions.
// Prints the CPU time the frames took (the step, and the samples' mesh placed each frame).
#include <ctime>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "bench_common.h"

#include "sim/particle_model.h"
#include "sim/sample_skin.h"
#include "sim/simulator.h"

using namespace treeanim;

int main(int argc, char** argv) {
  long long frames = -1;
  std::string out;
  std::vector<std::string> overrides;
  const bool parsed = bench::parse_arguments(argc, argv, "--out FILE [--frames N] [--set PATH=JSON]...", frames,
                                             [&](const std::string& arg, int& i) {
                                               if (i + 1 >= argc) return false;
                                               if (arg == "--out") out = argv[++i];
                                               else if (arg == "--set") overrides.emplace_back(argv[++i]);
                                               else return false;
                                               return true;
                                             });
  if (!parsed || out.empty()) {
    if (parsed) std::fprintf(stderr, "%s: --out FILE is required\n", argv[0]);
    return 2;
  }
  try {
    const Scene scene = load_scene(argv[1], overrides);
    if (frames < 0) frames = scene.time.frames;
    const TreeModel model = bench::scene_model(scene);
    // hsm.particles "samples": the solver moves the samples, the mesh is placed from them.
    const bool sampled = scene.hsm.particles == ParticleMode::kSamples;
    const std::optional<TreeModel> samples = sampled ? std::optional<TreeModel>(sample_tree_model(model)) : std::nullopt;
    const std::optional<SampleSkin> skin = sampled ? std::optional<SampleSkin>(std::in_place, model, *samples) : std::nullopt;
    ClusterFrames skin_frames;
    SimState skinned;
    Simulator sim(samples ? *samples : model, scene.hsm, scene.wind, 1.0 / scene.time.fps, scene.time.substeps);
    SimState state = sim.initial_state(0);
    std::FILE* file = std::fopen(out.c_str(), "wb");
    if (!file) throw std::runtime_error("cannot write " + out);
    // Process CPU time (every thread's), less moved by a shared machine's load than wall time.
    const auto cpu_seconds = [] {
      timespec t{};
      clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
      return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
    };
    double cpu = 0;
    for (long long f = 0; f < frames; ++f) {
      const double began = cpu_seconds();
      if (f > 0) sim.advance_frame(state, f);
      // Column-major 3 x V: each vertex's x, y, z in turn, as the rows of a V x 3 array.
      if (skin) skin->pose(state, false, skin_frames, skinned);
      cpu += cpu_seconds() - began;
      const Eigen::Matrix3Xd& positions = skin ? skinned.positions : state.positions;
      const size_t n = static_cast<size_t>(positions.size());
      if (std::fwrite(positions.data(), sizeof(double), n, file) != n) {
        std::fclose(file);
        throw std::runtime_error("cannot write " + out);
      }
    }
    if (std::fclose(file) != 0) throw std::runtime_error("cannot write " + out);
    std::printf("frames %lld, CPU seconds %.6f\n", frames, cpu);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_trajectory: %s\n", e.what());
    return 1;
  }
  return 0;
}
