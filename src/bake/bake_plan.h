#pragma once
// The plan of one tree's bake: which frames it simulates and writes, and where its
// checkpoints live (docs/checkpoint.md).
#include <filesystem>

#include "bake/bake_config.h"
#include "bake/checkpoint.h"
#include "formats/outputs.h"
#include "scene/scene.h"

namespace treeanim {

struct BakePlan {
  long long first = 0;         // time.start: the frame of the initial state
  long long last = 0;          // the scene's last frame
  FrameRange written;          // the frames written (--frames, else first to last)
  double frame_dt = 0;         // s
  bool loop = false;           // time.loop: the wind is periodic and whole periods run first
  bool closes_loop = false;    // a loop baked whole: the last frame flows into the first
  bool use_checkpoints = false;  // --resume or --frames: look for a checkpoint at all
  CheckpointPolicy checkpoints;
  CheckpointKey key;
  // Something reads each frame's mesh: an output, the frame journal or a loop's seam.
  bool reads_mesh = false;
};

// scene, config => the plan. --frames only chooses what is written: the simulation starts at
// time.start (or at a checkpoint of this bake), so frame k of a split bake is bit-identical to
// frame k of the whole bake.
BakePlan plan_bake(const Scene& scene, const BakeConfig& config);

// The plan without its key (left empty): the frames and checkpoints, for what a forest looks at
// of each of its trees before the first grows, without the key's dump of the scene and read of
// every input file (a million trees' keys took most of a minute).
BakePlan plan_frames(const Scene& scene, const BakeConfig& config);

// The frame of the last checkpoint a bake of `plan` writes (a multiple of checkpoints.every
// after time.start, up to the last written frame), plan.first when it writes none. The frame
// journal holds the written frames before it, the ones a resume from a checkpoint replays:
// none when the bake writes no checkpoint (--checkpoint-every past its frames).
long long last_checkpoint(const BakePlan& plan);

// The simulation time of `frame` (s).
double frame_time(const BakePlan& plan, long long frame);

// scene, plan, the tree's model and where it stands (null: at the origin) => what the outputs
// record of the bake (its materials and leaf colours, the wind at the tree, too).
BakeInfo bake_info(const Scene& scene, const BakePlan& plan, const TreeModel& model, const TreePlacement* placement);

}  // namespace treeanim
