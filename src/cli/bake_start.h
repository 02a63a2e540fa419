#pragma once
// Where a bake starts (docs/checkpoint.md): from time.start, or from the newest usable
// checkpoint with the frame journal that holds the frames written before it.
#include <cstdio>
#include <filesystem>
#include <optional>

#include "io/checkpoint.h"
#include "io/frame_journal.h"
#include "sim/simulator.h"

namespace treeanim {

// The frames of a bake and where its checkpoints live.
struct BakePlan {
  long long first = 0;          // time.start: the frame of the initial state
  long long write_first = 0;    // first frame written (--frames START)
  long long write_last = 0;     // last frame written
  double frame_dt = 0;          // s
  bool resume = false;          // --resume: checkpoints after write_first count too
  bool use_checkpoints = false; // --resume or --frames: look for a checkpoint at all
  std::filesystem::path checkpoint_dir;
  CheckpointKey key;
  JournalLayout journal;        // the layout of this bake's frame journal
};

struct BakeStart {
  long long frame = 0;                  // the frame `state` holds
  SimState state;
  std::filesystem::path checkpoint;     // the checkpoint it came from; empty: the initial state
  std::optional<FrameJournal> journal;  // holds frames [write_first, frame) when frame > write_first
};

// dir, first written frame => the journal file of that bake.
std::filesystem::path journal_path(const std::filesystem::path& dir, long long write_first);

// The newest checkpoint in [first, write_last] that this bake can use (with --frames alone: at
// or before write_first; after write_first only with --resume and a journal that holds the
// frames before it), else the initial state. Notes go to `log` (null: quiet). Throws
// InputError (exit 2) for a candidate that is damaged or of another scene or version.
BakeStart find_bake_start(const BakePlan& plan, const Simulator& simulator, std::FILE* log);

// A bake that writes checkpoints owns its folder: the checkpoints after `start` that another
// scene or version wrote, or that cannot be read, are removed (noted in `log`), so a later
// --resume finds this bake's. Never throws.
void remove_foreign_checkpoints(const BakePlan& plan, long long start, const SimState& shape, std::FILE* log);

}  // namespace treeanim
