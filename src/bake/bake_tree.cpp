#include "bake/bake_tree.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <utility>

#include "bake/checkpoint.h"
#include "bake/frame_thread.h"
#include "bake/prepare_tree.h"
#include "bake/signals.h"
#include "common/errors.h"
#include "common/seconds_since.h"
#include "files/free_space.h"
#include "sim/particle_model.h"
#include "sim/simulator.h"

namespace treeanim {

namespace {

// Mesh state (double) => the positions and velocities of the float frame the outputs write,
// into `data` (its arrays reused); a placed tree's in its own frame.
void output_vertices(const SimState& state, bool with_velocities, const TreePlacement* placement, FrameData& data) {
  const size_t V = size_t(state.positions.cols());
  data.velocities.resize(with_velocities ? 3 * V : 0);
  if (placement) {
    const Eigen::Matrix3d back = placement->rotation.transpose();
    data.positions.resize(3 * V);
    for (size_t v = 0; v < V; ++v) {
      const Eigen::Vector3d p = back * (state.positions.col(v) - placement->translation);
      for (int k = 0; k < 3; ++k) data.positions[3 * v + k] = static_cast<float>(p[k]);
      if (!with_velocities) continue;
      const Eigen::Vector3d u = back * state.velocities.col(v);
      for (int k = 0; k < 3; ++k) data.velocities[3 * v + k] = static_cast<float>(u[k]);
    }
  } else {
    data.positions.assign(state.positions.data(), state.positions.data() + state.positions.size());
    if (with_velocities)
      data.velocities.assign(state.velocities.data(), state.velocities.data() + state.velocities.size());
  }
}

// Each cluster's frame (x = R (x0 - t0) + t0 + shift, where the tree stands) => the motion
// x = R x0 + t in the tree's own frame, as floats (FrameData::cluster_motions).
void add_cluster_motions(const ClusterFrames& frames, const Eigen::Matrix3Xd& rest_centres,
                         const TreePlacement* placement, FrameData& data) {
  const long C = frames.rotation.cols();
  data.cluster_motions.resize(7 * size_t(C));
  const TreePlacement identity;
  const TreePlacement& p = placement ? *placement : identity;
  for (long c = 0; c < C; ++c) {
    const Eigen::Vector4d q = frames.rotation.col(c);
    const Eigen::Quaterniond world(q[3], q[0], q[1], q[2]);
    const Eigen::Matrix3d R = world.toRotationMatrix();
    const Eigen::Vector3d t = rest_centres.col(c) + frames.shift.col(c) - R * rest_centres.col(c);
    // Own frame: x = P^T (R (P x0 + p) + t - p) = (P^T R P) x0 + P^T (R p + t - p).
    const Eigen::Quaterniond own = Eigen::Quaterniond(p.rotation.transpose()) * world * Eigen::Quaterniond(p.rotation);
    const Eigen::Vector3d shift = p.rotation.transpose() * (R * p.translation + t - p.translation);
    float* out = &data.cluster_motions[7 * size_t(c)];
    for (int k = 0; k < 4; ++k) out[k] = float(own.coeffs()[k]);
    for (int k = 0; k < 3; ++k) out[4 + k] = float(shift[k]);
  }
}

// The mesh of frame `frame` of `state` (placed from the samples when the bake has a skin),
// converted, journalled when a checkpoint after it needs it, pushed.
void place_frame(const BakePlan& plan, BakeStart& start, BakeFrames& frames, const SimState& state, long long frame,
                 const TreePlacement* placement) {
  const bool velocities = frames.outputs.wants_velocities();
  FrameData data = frames.outputs.spare_frame();
  data.frame = frame;
  // The frame's time as docs/scene.md gives it, frame x (1 / fps): the state's sums a step per
  // frame (2.8e-17 s off at frame 0 from a negative start), and a loop's warm-up ran periods ahead.
  data.time = frame_time(plan, frame);
  data.leaf_attached = state.leaf_attached;
  if (frames.skin && !placement) {
    // Each vertex rounded to float as the skin places it, in its parallel loops.
    data.positions.resize(3 * frames.skin->vertex_count());
    data.velocities.resize(velocities ? data.positions.size() : 0);
    frames.skin->pose(state, frames.skin_frames, data.positions.data(), velocities ? data.velocities.data() : nullptr);
  } else {
    if (frames.skin) frames.skin->pose(state, velocities, frames.skin_frames, frames.skinned);
    output_vertices(frames.skin ? frames.skinned : state, velocities, placement, data);
  }
  if (frames.cluster_motions) add_cluster_motions(frames.skin_frames, frames.skin->rest_centres(), placement, data);
  else data.cluster_motions.clear();
  if (frame < last_checkpoint(plan)) start.journal->append(data);
  frames.push(std::move(data));
}

// The frame `start.state` holds, written: a skinned mesh on the frame thread (when there is
// one), else here.
void write_frame(const BakePlan& plan, BakeStart& start, BakeFrames& frames, long long frame,
                 const TreePlacement* placement, FrameThread* frame_thread) {
  if (frames.sampled && !plan.reads_mesh) {
    // Nothing reads the mesh: no vertex is placed; the bounds are the samples' (in the world,
    // as the state holds them), extended one by one as AlignedBox::extend does (std::min and
    // std::max per axis), in plain doubles.
    if (!frames.measures_bounds) return;
    Eigen::Vector3d low = frames.bounds.min(), high = frames.bounds.max();
    for (long s = 0; s < start.state.positions.cols(); ++s) {
      const Eigen::Vector3d x = start.state.positions.col(s);
      for (int i = 0; i < 3; ++i) low[i] = std::min(low[i], x[i]), high[i] = std::max(high[i], x[i]);
    }
    frames.bounds = Eigen::AlignedBox3d(low, high);
    return;
  }
  if (frame_thread) frame_thread->submit(start.state, frames.outputs.wants_velocities(), frame);
  else place_frame(plan, start, frames, start.state, frame, placement);
}

}  // namespace

BakeFrames::BakeFrames(const Scene& scene, const BakeConfig& config, const BakePlan& plan, const TreeModel& model,
                       const TreePlacement* placement)
    : info(bake_info(scene, plan, model, placement)),
      output_count(scene.outputs.size()),
      measures_bounds(placement != nullptr),
      placement(placement ? *placement : TreePlacement{}),
      outputs(scene.outputs, config.out_dir, model, info,
              // locked whenever the bake reads its checkpoints, not only when it writes them: a
              // resume must not read a folder another bake is writing
              plan.checkpoints.every > 0 || plan.use_checkpoints ? plan.checkpoints.dir : std::filesystem::path()) {}

void BakeFrames::push(FrameData data) {
  if (info.loop) seam.add(data.positions);  // a loop only: a copy of every frame
  if (measures_bounds)
    for (size_t i = 0; i + 2 < data.positions.size(); i += 3)
      bounds.extend(Eigen::Vector3d(placement.rotation * Eigen::Vector3d(data.positions[i], data.positions[i + 1],
                                                                         data.positions[i + 2]) +
                                    placement.translation));
  outputs.push(std::move(data));
}

JournalLayout journal_layout(const BakePlan& plan, const TreeModel& model, bool velocities, bool cluster_motions) {
  return {plan.key.scene_hash, plan.written.first, model.vertex_count(), model.leaf_count(), velocities,
          cluster_motions ? model.cluster_count() : 0};
}

void check_room(const BakePlan& plan, const BakeStart& start, const TreeModel& simulated, const JournalLayout& layout,
                const BakeFrames& frames) {
  std::vector<SpaceNeed> needs;
  for (const auto& [path, bytes] : frames.outputs.estimated_bytes()) needs.push_back({path, bytes});
  if (plan.checkpoints.every > 0) {
    const long long every = plan.checkpoints.every;
    const long long checkpoints = (plan.written.last - plan.first) / every - (start.frame - plan.first) / every;
    const long long records = std::max(0LL, last_checkpoint(plan) - std::max(start.frame, plan.written.first));
    needs.push_back({journal_path(plan.checkpoints.dir, plan.written.first),
                     double(checkpoints) * estimated_checkpoint_bytes(simulated.vertex_count(), simulated.cluster_count(),
                                                                      simulated.leaf_count()) +
                         double(records) * double(journal_record_bytes(layout))});
  }
  check_free_space(needs);
}

LoopWarmup warm_up(const BakePlan& plan, Simulator& simulator, BakeStart& start, std::FILE* notes,
                   ThreadGovernor& governor) {
  if (!plan.loop || !start.checkpoint.empty()) return {};
  return warm_up_loop(simulator, start.state, plan.first, plan.last - plan.first + 1, notes, governor);
}

void replay_journal(const BakePlan& plan, const JournalLayout& layout, BakeStart& start, BakeFrames& frames,
                    std::FILE* notes) {
  open_bake_journal(plan, layout, start, notes);
  frames.outputs.begin();
  for (long long k = plan.written.first; k < start.frame && k <= plan.written.last; ++k)
    frames.push(start.journal->read(k - plan.written.first));
}

int run_frames(const BakePlan& plan, Simulator& simulator, BakeStart& start, BakeFrames& frames,
               const TreePlacement* placement, const BakeLog& log, ThreadGovernor& governor) {
  // A skinned mesh is placed on a thread of its own while the solver steps on, when the
  // solver's team leaves a core free for it; on every core, a thread more would preempt a member
  // of the team and stall it at each barrier, so the team places the mesh between frames. The
  // state of the vertices themselves is the mesh, converted where it is.
  std::optional<FrameThread> frame_thread;
  if (frames.skin && omp_get_max_threads() < omp_get_num_procs())
    frame_thread.emplace([&](const SimState& state, long long frame) {
      place_frame(plan, start, frames, state, frame, placement);
    });
  FrameThread* const thread = frame_thread ? &*frame_thread : nullptr;
  log.frames_begin(plan.written.last - start.frame + 1);
  for (long long frame = start.frame; frame <= plan.written.last; ++frame) {
    if (frame > start.frame) simulator.advance_frame(start.state, frame);
    if (const int signal_number = pending_signal()) {
      frame_thread.reset();
      frames.outputs.abort();
      log.frames_end();
      log.interrupted(signal_number, frame);
      return interrupted_exit_code(signal_number);
    }
    if (frame >= plan.written.first) write_frame(plan, start, frames, frame, placement, thread);
    // The journal reaches the disk before the checkpoint that names its frames as written.
    if (plan.checkpoints.every > 0 && frame > start.frame && (frame - plan.first) % plan.checkpoints.every == 0) {
      if (thread) thread->finish();
      if (start.journal) start.journal->sync();  // none when the written frames start after the last checkpoint
      write_checkpoint(checkpoint_path(plan.checkpoints.dir, frame), start.state, frame, plan.key);
    }
    log.frame_done(frame - start.frame + 1);
    governor.frame_done(frame);
  }
  if (thread) thread->finish();
  return 0;
}

TreeBakeResult finish_bake(const BakePlan& plan, const BakeStart& start, const LoopWarmup& warmup,
                           BakeFrames& frames, const BakeLog& log) {
  TreeBakeResult result;
  // A signal while the files are completed (a skin's fit, a page: seconds) stops the bake as
  // one between frames does; one after they are in place leaves them (exit 0).
  if (!frames.outputs.finish(pending_signal)) {
    log.frames_end();
    log.interrupted(pending_signal(), plan.written.last);
    result.exit_code = interrupted_exit_code(pending_signal());
    return result;
  }
  log.frames_end();
  result.written = plan.written;
  result.substeps = (plan.written.last - start.frame) * frames.info.substeps;
  result.final_paths = frames.outputs.final_paths();
  result.reports = frames.outputs.reports();
  for (size_t k = 0; k < frames.output_count; ++k) result.files.push_back(frames.outputs.files(k));
  if (plan.closes_loop)
    result.loop = LoopSummary{warmup, !start.checkpoint.empty(), frames.seam.seam(), frames.seam.median_step()};
  if (frames.measures_bounds) result.bounds = frames.bounds;
  return result;
}

TreeBakeResult bake_tree(const Scene& scene, const BakeConfig& config, const TreePlacement* placement,
                         const BakeLog& log, ThreadGovernor* governor) {
  const auto began = std::chrono::steady_clock::now();
  std::optional<ThreadGovernor> own_governor;
  if (!governor) {
    if (config.threads > 0) omp_set_num_threads(config.threads);
    governor = &own_governor.emplace(omp_get_max_threads(), log.team_resized);
  }
  const BakePlan plan = plan_bake(scene, config);
  // hsm.particles "samples": the solver moves the samples, the mesh follows their clusters.
  const bool sampled = scene.hsm.particles == ParticleMode::kSamples;
  // Nothing reads the mesh of a samples bake that writes nothing (BakePlan::reads_mesh): it is
  // built without its surface, and its model goes back as the samples are drawn, so the bake
  // holds the samples alone.
  const bool give_up_mesh = sampled && !plan.reads_mesh;
  PreparedTree tree = prepare_tree(scene, give_up_mesh ? MeshSurface::kOmitted : MeshSurface::kBuilt, log.grown_step);
  tree.skeleton = Skeleton();  // the model is built from it; nothing in a bake reads it again
  log.prepared(tree);
  if (plan.checkpoints.every > 0) check_checkpoint_folder(plan.checkpoints.dir);  // every input noted by now
  // From the outputs' locks on, a signal waits for the frame loop, which removes what they made.
  const DeferredInterrupts deferred;
  BakeFrames frames(scene, config, plan, tree.model, placement);
  frames.sampled = sampled;
  frames.cluster_motions = sampled && frames.outputs.wants_cluster_motions();
  const JournalLayout layout = journal_layout(plan, tree.model, frames.outputs.wants_velocities(), frames.cluster_motions);
  const size_t vertices = tree.model.vertex_count(), clusters = tree.model.cluster_count();
  // A placed tree moves in the world's wind: its simulation runs on the model where it stands.
  // A model given up is moved there, not copied: the bake never holds two.
  std::optional<TreeModel> placed;
  if (placement) {
    placed = give_up_mesh ? placed_tree_model(std::move(tree.model), *placement) : placed_tree_model(tree.model, *placement);
    if (give_up_mesh) tree.model = TreeModel();
  }
  TreeModel& mesh = placed ? *placed : tree.model;
  std::optional<TreeModel> samples;
  if (sampled) samples = give_up_mesh ? sample_tree_model(std::move(mesh)) : sample_tree_model(std::as_const(mesh));
  const std::optional<SampleSkin> skin =
      sampled && !give_up_mesh ? std::optional<SampleSkin>(std::in_place, mesh, *samples) : std::nullopt;
  if (skin) frames.skin = &*skin;
  const TreeModel& simulated = samples ? *samples : mesh;
  Simulator simulator(simulated, scene.hsm, scene.wind, plan.frame_dt, scene.time.substeps);

  BakeStart start = start_bake(plan, layout, simulator, log.notes);
  if (config.space_check) check_room(plan, start, simulated, layout, frames);
  const LoopWarmup warmup = warm_up(plan, simulator, start, log.notes, *governor);
  replay_journal(plan, layout, start, frames, log.notes);
  const auto run_began = std::chrono::steady_clock::now();
  TreeBakeResult result;
  result.exit_code = run_frames(plan, simulator, start, frames, placement, log, *governor);
  if (result.exit_code != 0) return result;
  result = finish_bake(plan, start, warmup, frames, log);
  if (result.exit_code != 0) return result;
  result.vertices = vertices;
  result.samples = samples ? samples->vertex_count() : 0;
  result.clusters = clusters;
  result.seconds = seconds_since(began);
  result.run_seconds = seconds_since(run_began);
  log.baked(result);
  return result;
}

}  // namespace treeanim
