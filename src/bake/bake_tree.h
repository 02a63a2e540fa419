#pragma once
// One tree's bake (docs/checkpoint.md) as named stages over a plan: plan (bake_plan.h), start
// from a checkpoint or afresh (bake_start.h), warm up (loops), replay the journal, run the frame
// loop, finish. `treeanim run` of a one-tree scene is one bake_tree; a forest bakes each tree.
#include <Eigen/Geometry>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bake/bake_config.h"
#include "bake/bake_log.h"
#include "bake/bake_plan.h"
#include "bake/bake_start.h"
#include "bake/loop_bake.h"
#include "bake/thread_governor.h"
#include "formats/outputs.h"
#include "scene/scene.h"
#include "sim/sample_skin.h"
#include "tree/tree_placement.h"

namespace treeanim {

// Where the frames of a bake go: its outputs, and what the summary and the manifest measure.
struct BakeFrames {
  // Checks every output target (InputError, OutputError) before anything is simulated.
  // placement: where the tree stands (null: a lone tree at the origin).
  BakeFrames(const Scene& scene, const BakeConfig& config, const BakePlan& plan, const TreeModel& model,
             const TreePlacement* placement);
  // A frame measured (a placed tree's bounds, a whole loop's seam), then queued to the outputs.
  void push(FrameData data);

  const BakeInfo info;
  const size_t output_count;
  // A placed tree reports the world box of its frames to the forest's manifest; a lone tree has no use for it.
  const bool measures_bounds;
  const TreePlacement placement;  // world from the tree's own frame, where its outputs' vertices are
  bool sampled = false;  // hsm.particles "samples": the solver steps samples, not the mesh
  // Each frame carries its clusters' motions (FrameData::cluster_motions), journalled with it:
  // a samples bake with an output that keys them.
  bool cluster_motions = false;
  // The mesh placed from the samples' clusters when something reads it (null: the state is the
  // mesh's, or nothing reads it), and its scratch.
  const SampleSkin* skin = nullptr;
  ClusterFrames skin_frames;
  SimState skinned;
  OutputSet outputs;
  SeamMeter seam;              // a loop baked whole: every frame
  // m, every written frame's vertices placed in the world, each vertex where it stands: a box of
  // the tree's own frame turned with it would hold up to √2 times the turned tree's width.
  Eigen::AlignedBox3d bounds;
};

// A loop baked whole: how it was brought to repeat and how well it closes.
struct LoopSummary {
  LoopWarmup warmup;
  bool resumed = false;      // from a checkpoint: the warm-up ran in an earlier process
  double seam = 0;           // m
  double median_step = 0;    // m
};

// What a finished bake did and wrote: its summary and the forest manifest's part.
struct TreeBakeResult {
  int exit_code = 0;                                      // 0, or 130/143/129 when interrupted
  FrameRange written;                                     // the frames written
  size_t vertices = 0;
  size_t samples = 0;                                     // hsm.particles "samples": the particles simulated; 0 otherwise
  size_t clusters = 0;
  long long substeps = 0;                                 // simulated by this process
  double seconds = 0;                                     // s, the whole bake
  double run_seconds = 0;                                 // s, the frame loop and the outputs' finish
  std::vector<SummaryFile> final_paths;                   // each output's files, a sequence by its first and last
  std::vector<std::pair<std::filesystem::path, std::string>> reports;  // (path, what its output says)
  std::vector<std::vector<std::filesystem::path>> files;  // (outputs) every file of each output
  std::optional<LoopSummary> loop;                        // a loop baked whole
  Eigen::AlignedBox3d bounds;                             // m, world box of a placed tree's written frames
};

// The journal of `plan` for a model whose outputs want velocities or not, and the clusters'
// motions (a bake on samples for a skinned output of a joint per cluster) or not.
JournalLayout journal_layout(const BakePlan& plan, const TreeModel& model, bool velocities,
                             bool cluster_motions = false);

// Room: the bytes that the outputs and, with checkpoints, the checkpoints (each the state of
// `simulated`, the model the solver steps) and journal records still to write from `start` will
// take, against the free space of each filesystem they go to (files/free_space.h). Throws
// OutputError when some filesystem lacks room.
void check_room(const BakePlan& plan, const BakeStart& start, const TreeModel& simulated, const JournalLayout& layout,
                const BakeFrames& frames);

// Warm up: a loop that starts afresh (not from a checkpoint, which lies past the warm-up) runs
// whole periods until the tree's motion repeats; else nothing.
LoopWarmup warm_up(const BakePlan& plan, Simulator& simulator, BakeStart& start, std::FILE* notes,
                   ThreadGovernor& governor);

// Replay: this bake's journal opened when it writes checkpoints (open_bake_journal), the outputs
// begun, and the frames written before start.frame, which no checkpoint holds, pushed from the journal.
void replay_journal(const BakePlan& plan, const JournalLayout& layout, BakeStart& start, BakeFrames& frames,
                    std::FILE* notes);

// Run: frames start.frame to written.last simulated and pushed (a placed tree's in its own frame),
// journalled and checkpointed when the plan says. Returns 0, or 130/143/129 after a signal, the
// outputs then removed. After each frame the governor may resize the solver's team.
int run_frames(const BakePlan& plan, Simulator& simulator, BakeStart& start, BakeFrames& frames,
               const TreePlacement* placement, const BakeLog& log, ThreadGovernor& governor);

// Finish: the outputs' final names, and what the bake wrote (bounds in the world).
TreeBakeResult finish_bake(const BakePlan& plan, const BakeStart& start, const LoopWarmup& warmup,
                           BakeFrames& frames, const BakeLog& log);

// Bakes `scene` as `config` says. With a placement the tree is simulated where it stands and its
// outputs are written in its own frame. Throws InputError, SimulationError, OutputError; nothing
// of a failed bake keeps a final name.
// `governor`: the forest's, which carries what it measured from tree to tree; null: the
// bake sets config.threads and sizes its team itself.
TreeBakeResult bake_tree(const Scene& scene, const BakeConfig& config, const TreePlacement* placement,
                         const BakeLog& log, ThreadGovernor* governor = nullptr);

}  // namespace treeanim
