// Shape matching against Bullet's soft-body clusters (optional; not a test): the same
// vertices, masses and clusters, one thread each.
//   bench_bullet_float|bench_bullet_double SCENE [--frames N] [--particles vertices|samples]
// With --particles samples ours steps the samples (docs/solver.md, "Particles") and Bullet the
// mesh, whose nodes are then placed from our cluster frames (SampleSkin, timed on its own line).
// Ours: Simulator::advance_frame, in the precision Bullet was built with (hsm.precision is
// overridden to match btScalar); per substep it predicts every vertex (damping, drag, wind,
// the global term), matches every cluster and averages the goals of shared vertices, so its
// time is an upper bound of our shape matching alone (docs/solver.md, "Costs": the cluster
// work is ~55 % of a step). Bullet: btSoftBody::updateClusters() on a body whose nodes are
// set to our positions of each frame in turn, once all of ours are stepped. With m_matching
// > 0 it computes each cluster's centre, its A matrix, the polar decomposition, the world
// inertia and momenta, and moves every node toward its goal (Müller's step, written in
// sequence, not averaged). m_collide is off and the body is in no world, so no collision work
// is timed.
#include <omp.h>

#include <BulletSoftBody/btSoftBody.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <new>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "../bench_common.h"
#include "sim/particle_model.h"
#include "sim/sample_skin.h"
#include "sim/simulator.h"
#include "sim/stiffness.h"

using namespace treeanim;
using bench::seconds_since;

namespace {

using Clock = std::chrono::steady_clock;

// Model + per-step local rates => a Bullet soft body with the model's nodes, masses and
// clusters (every membership a cluster node; matching = our per-step rate alpha).
btSoftBody* make_body(btSoftBodyWorldInfo& info, const TreeModel& model, const std::vector<double>& cluster_alpha) {
  const size_t V = model.vertex_count();
  btAlignedObjectArray<btVector3> x;
  btAlignedObjectArray<btScalar> m;
  x.resize(static_cast<int>(V));
  m.resize(static_cast<int>(V));
  for (size_t v = 0; v < V; ++v) {
    x[static_cast<int>(v)] = btVector3(btScalar(model.rest_positions(0, v)), btScalar(model.rest_positions(1, v)),
                                       btScalar(model.rest_positions(2, v)));
    // Bullet's cluster centres divide by the cluster mass: no massless node.
    m[static_cast<int>(v)] = btScalar(std::max(model.vertex_mass[v], 1e-9));
  }
  auto* body = new btSoftBody(&info, static_cast<int>(V), &x[0], &m[0]);
  for (size_t c = 0; c < model.cluster_count(); ++c) {
    void* memory = btAlignedAlloc(sizeof(btSoftBody::Cluster), 16);
    auto* cluster = new (memory) btSoftBody::Cluster();
    cluster->m_collide = false;
    cluster->m_matching = btScalar(cluster_alpha[c]);
    for (uint32_t s = model.cluster_offsets[c]; s < model.cluster_offsets[c + 1]; ++s)
      cluster->m_nodes.push_back(&body->m_nodes[static_cast<int>(model.cluster_members[s])]);
    body->m_clusters.push_back(cluster);
  }
  body->initializeClusters();
  return body;
}

}  // namespace

int main(int argc, char** argv) {
  long long frames = 24;
  bool samples = false;
  if (!bench::parse_arguments(argc, argv, "[--frames N] [--particles vertices|samples]", frames,
                              [&](const std::string& arg, int& i) {
                                if (arg != "--particles" || i + 1 >= argc) return false;
                                const std::string mode = argv[++i];
                                samples = mode == "samples";
                                return samples || mode == "vertices";
                              }))
    return 2;
  try {
    omp_set_num_threads(1);
    Scene scene = load_scene(argv[1], {});
    constexpr bool kDouble = std::is_same_v<btScalar, double>;
    scene.hsm.precision = kDouble ? Precision::kDouble : Precision::kFloat;
    scene.hsm.sleep = false;  // time the full step
    const TreeModel model = bench::scene_model(scene);
    const TreeModel sampled = samples ? sample_tree_model(model) : TreeModel();
    const TreeModel& simulated = samples ? sampled : model;
    const std::optional<SampleSkin> skin = samples ? std::optional<SampleSkin>(std::in_place, model, sampled) : std::nullopt;
    const double frame_dt = 1.0 / scene.time.fps;
    const int substeps = scene.time.substeps;
    const StepRates rates = compute_step_rates(model, scene.hsm, frame_dt / substeps);

    btSoftBodyWorldInfo info;
    btSoftBody* body = make_body(info, model, rates.cluster_alpha);
    Simulator sim(simulated, scene.hsm, scene.wind, frame_dt, substeps);
    SimState state = sim.initial_state(0), mesh_state;
    ClusterFrames cluster_frames;
    for (long long f = 1; f <= 2; ++f) sim.advance_frame(state, f);  // warm caches and rotations

    // Each side steps frame after frame on its own data, as a bake does: first ours, keeping
    // every frame's mesh, then Bullet's clusters matched on those meshes. (Run in turns, frame
    // by frame, Bullet's pass over its ~50 MB of nodes evicted our state before each of our
    // frames, while copying our positions into its nodes warmed them before each of its own.)
    double ours = 0, skinning = 0, bullet = 0;
    const size_t V = model.vertex_count();
    std::vector<btScalar> meshes(size_t(frames) * 3 * V);
    for (long long f = 3; f < frames + 3; ++f) {
      const auto start = Clock::now();
      sim.advance_frame(state, f);
      ours += seconds_since(start);
      const auto skin_start = Clock::now();
      if (skin) skin->pose(state, false, cluster_frames, mesh_state);
      skinning += seconds_since(skin_start);
      const SimState& placed = samples ? mesh_state : state;
      btScalar* mesh = &meshes[size_t(f - 3) * 3 * V];
      for (size_t i = 0; i < 3 * V; ++i) mesh[i] = btScalar(placed.positions.data()[i]);
    }
    for (long long f = 0; f < frames; ++f) {
      const btScalar* mesh = &meshes[size_t(f) * 3 * V];
      for (size_t v = 0; v < V; ++v)
        body->m_nodes[static_cast<int>(v)].m_x = btVector3(mesh[3 * v], mesh[3 * v + 1], mesh[3 * v + 2]);
      const auto bullet_start = Clock::now();
      for (int k = 0; k < substeps; ++k) body->updateClusters();
      bullet += seconds_since(bullet_start);
    }
    const double steps = double(frames * substeps);
    std::printf("%s: %zu vertices, %zu clusters, %zu memberships; %s precision, 1 thread; ours on the %s (%zu)\n",
                argv[1], model.vertex_count(), model.cluster_count(), model.membership_count(),
                kDouble ? "double" : "float", samples ? "samples" : "vertices", simulated.vertex_count());
    std::printf("  treeanim, whole substep (prediction, wind, drag, matching, averaging): %.3f ms\n", 1e3 * ours / steps);
    if (samples)
      std::printf("  treeanim, the mesh placed from the cluster frames, per frame / %d:      %.3f ms\n", substeps,
                  1e3 * skinning / steps);
    std::printf("  Bullet %d.%02d updateClusters (cluster matching, no collision):          %.3f ms (%.2fx ours)\n",
                BT_BULLET_VERSION / 100, BT_BULLET_VERSION % 100, 1e3 * bullet / steps, bullet / ours);
    body->releaseClusters();
    delete body;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_bullet: %s\n", e.what());
    return 1;
  }
  return 0;
}
