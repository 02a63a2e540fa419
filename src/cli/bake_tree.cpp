// One tree's bake (cli/bake_tree.h): the frame loop with its checkpoints, journal and outputs.
#include "cli/bake_tree.h"

#include <chrono>
#include <csignal>
#include <cstdio>
#include <optional>

#include "cli/bake_start.h"
#include "cli/loop_bake.h"
#include "cli/prepare_tree.h"
#include "cli/signals.h"
#include "common/errors.h"
#include "io/outputs.h"
#include "sim/kernel_isa.h"
#include "sim/simulator.h"
#include "treeanim_version.h"

namespace treeanim {

namespace {

// Solver state (double) => the float frame the sinks write; a placed tree's in its own frame.
FrameData make_frame(const SimState& state, long long frame, bool with_velocities, const TreePlacement* placement) {
  FrameData data;
  data.frame = frame;
  data.time = state.time;
  if (placement) {
    const Eigen::Matrix3d back = placement->rotation.transpose();
    const size_t V = size_t(state.positions.cols());
    data.positions.resize(3 * V);
    if (with_velocities) data.velocities.resize(3 * V);
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
  data.leaf_attached = state.leaf_attached;
  return data;
}

// box, a frame's (V*3) positions => the box holding them too.
void extend_bounds(Eigen::AlignedBox3d& box, const std::vector<float>& positions) {
  for (size_t i = 0; i + 2 < positions.size(); i += 3)
    box.extend(Eigen::Vector3d(positions[i], positions[i + 1], positions[i + 2]));
}

}  // namespace

TreeBakeResult bake_tree(const Scene& scene, const RunRequest& request, const TreePlacement* placement) {
  const auto wall_start = std::chrono::steady_clock::now();
  const bool verbose = request.verbosity == Verbosity::kVerbose;
  std::FILE* log = request.verbosity == Verbosity::kQuiet ? nullptr : stderr;

  const long long first = scene.time.start;
  const long long last = first + scene.time.frames - 1;
  // --frames only chooses what is written: the simulation starts at time.start (or at a
  // checkpoint of this bake), so frame k of a split bake is bit-identical to frame k of the
  // whole bake.
  const auto [write_first, write_last] =
      request.frames ? parse_frame_range(*request.frames, first, last) : std::pair{first, last};
  const PreparedTree tree = prepare_tree(scene);
  if (verbose)
    std::fprintf(stderr, "grown in %.3f s, model built in %.3f s: %zu vertices, %zu clusters; solver loops: %s\n",
                 tree.grow_seconds, tree.model_seconds, tree.model.vertex_count(),
                 tree.model.cluster_count(), kernel_isa_name(kernel_isa()));

  BakeInfo info;
  info.scene_json = scene.resolved.dump(2);
  info.generator = std::string("treeanim ") + TREEANIM_VERSION;
  info.fps = scene.time.fps;
  info.frame_start = write_first;
  info.frame_count = write_last - write_first + 1;
  info.substeps = scene.time.substeps;
  info.seed = scene.seed;
  // Only a bake of the whole loop closes it; --frames writes a part of it.
  info.loop = scene.time.loop && write_first == first && write_last == last;
  info.loop_end_time = double(last + 1) / scene.time.fps;
  info.wind = scene.wind;
  if (placement) info.placement = *placement;
  OutputSet outputs(scene.outputs, request.out_dir, tree.model, info);
  TreeBakeResult result;
  result.frame_start = write_first;
  result.frame_count = info.frame_count;
  result.vertices = tree.model.vertex_count();
  Eigen::AlignedBox3d own_bounds;  // m, in the tree's own frame

  const double frame_dt = 1.0 / scene.time.fps;
  // A placed tree moves in the world's wind: its simulation runs on the model where it stands.
  const std::optional<TreeModel> placed =
      placement ? std::optional<TreeModel>(placed_tree_model(tree.model, *placement)) : std::nullopt;
  Simulator simulator(placed ? *placed : tree.model, scene.hsm, scene.wind, frame_dt, scene.time.substeps);
  BakePlan plan;
  plan.first = first;
  plan.write_first = write_first;
  plan.write_last = write_last;
  plan.frame_dt = frame_dt;
  plan.resume = request.resume;
  plan.use_checkpoints = request.resume || request.frames.has_value();
  plan.checkpoint_dir = !request.checkpoint_dir.empty() ? request.checkpoint_dir
                        : request.out_dir.empty()       ? std::filesystem::path("checkpoints")
                                                        : request.out_dir / "checkpoints";
  plan.key = {scene_hash(info.scene_json, info.generator), info.generator, scene.hsm.precision == Precision::kFloat};
  plan.journal = {plan.key.scene_hash, write_first, tree.model.vertex_count(), tree.model.leaf_count(),
                  outputs.wants_velocities()};
  BakeStart start = find_bake_start(plan, simulator, log);
  SimState& state = start.state;
  // A loop starts from the tree's periodic motion: whole periods run first (not on a resume,
  // whose checkpoint lies past them).
  LoopWarmup warmup;
  if (scene.time.loop && start.checkpoint.empty()) warmup = warm_up_loop(simulator, state, first, scene.time.frames, log);
  SeamMeter seam;
  if (!start.checkpoint.empty() && log)
    std::fprintf(log, "treeanim: resuming at frame %lld from %s\n", start.frame, start.checkpoint.c_str());
  std::optional<FrameJournal> journal;  // this bake's, when it writes checkpoints
  if (request.checkpoint_every > 0) {
    remove_foreign_checkpoints(plan, start.frame, state, log);
    if (start.journal) {
      journal = std::move(start.journal);
      journal->truncate(start.frame - write_first);  // the frames before the checkpoint's
    } else {
      journal = FrameJournal::create(journal_path(plan.checkpoint_dir, write_first), plan.journal);
    }
  }
  outputs.begin();
  // The frames written before the checkpoint are not in it: the journal gives them back.
  for (long long k = write_first; k < start.frame && k <= write_last; ++k) {
    FrameJournal& source = journal ? *journal : *start.journal;
    FrameData data = source.read(k - write_first);
    if (info.loop) seam.add(data.positions);
    extend_bounds(own_bounds, data.positions);
    outputs.push(std::move(data));
  }

  Progress progress(write_last - start.frame + 1, request.verbosity, stderr);
  const auto sim_start = std::chrono::steady_clock::now();
  for (long long frame = start.frame; frame <= write_last; ++frame) {
    if (frame > start.frame) simulator.advance_frame(state, frame);
    if (const int signal_number = pending_signal()) {
      outputs.abort();
      progress.finish();
      std::fprintf(stderr, "treeanim: interrupted by %s at frame %lld; no output was kept%s\n",
                   signal_number == SIGINT ? "SIGINT" : "SIGTERM", frame,
                   journal ? " (--resume continues from the last checkpoint)" : "");
      result.exit_code = signal_number == SIGINT ? kExitSigint : kExitSigterm;
      return result;
    }
    if (frame >= write_first) {
      FrameData data = make_frame(state, frame, outputs.wants_velocities(), placement);
      extend_bounds(own_bounds, data.positions);
      if (scene.time.loop) data.time = double(frame) * frame_dt;  // the warm-up ran periods ahead
      if (info.loop) seam.add(data.positions);  // a loop only: a copy of every frame
      if (journal) journal->append(data);
      outputs.push(std::move(data));
    }
    // The journal reaches the disk before the checkpoint that names its frames as written.
    if (journal && frame > start.frame && (frame - first) % request.checkpoint_every == 0) {
      journal->sync();
      write_checkpoint(checkpoint_path(plan.checkpoint_dir, frame), state, frame, plan.key);
    }
    progress.update(frame - start.frame + 1);
  }
  outputs.finish();
  progress.finish();

  if (request.verbosity != Verbosity::kQuiet) {
    std::printf("baked %lld frames: %zu vertices, %zu clusters, %lld substeps in %.2f s "
                "(simulation + writing %.2f s)\n",
                write_last - write_first + 1, tree.model.vertex_count(),
                tree.model.cluster_count(), (write_last - start.frame) * scene.time.substeps,
                seconds_since(wall_start), seconds_since(sim_start));
    for (const auto& path : outputs.final_paths()) std::printf("  wrote %s\n", path.string().c_str());
    for (const auto& [path, line] : outputs.reports()) std::printf("  %s: %s\n", path.string().c_str(), line.c_str());
    if (info.loop)
      std::printf("  loop: %d warm-up period%s%s; seam %.3g m, %.2f x the median frame step (%.3g m)\n",
                  warmup.periods, warmup.periods == 1 ? "" : "s",
                  warmup.converged || !start.checkpoint.empty() ? "" : " (the motion did not repeat: baked as it stands)",
                  seam.seam(), seam.median_step() > 0 ? seam.seam() / seam.median_step() : 0.0, seam.median_step());
  }
  for (size_t k = 0; k < scene.outputs.size(); ++k) result.files.push_back(outputs.files(k));
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p = own_bounds.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner));
    result.bounds.extend(placement ? Eigen::Vector3d(placement->rotation * p + placement->translation) : p);
  }
  return result;
}

}  // namespace treeanim
