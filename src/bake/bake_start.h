#pragma once
// Where a bake starts (docs/checkpoint.md): from time.start, or from the newest usable
// checkpoint with the frame journal that holds the frames written before it.
#include <cstdio>
#include <filesystem>
#include <optional>

#include "bake/bake_plan.h"
#include "bake/frame_journal.h"
#include "sim/simulator.h"

namespace treeanim {

struct BakeStart {
  long long frame = 0;                  // the frame `state` holds
  SimState state;
  std::filesystem::path checkpoint;     // the checkpoint it came from; empty: the initial state
  // Holds frames [written.first, frame) when frame > written.first; a bake that writes
  // checkpoints appends its frames to it (open_bake_journal).
  std::optional<FrameJournal> journal;
};

// dir, first written frame => the journal file of that bake.
std::filesystem::path journal_path(const std::filesystem::path& dir, long long write_first);

// The newest checkpoint in [first, written.last] that this bake can use (with --frames alone: at
// or before written.first; after it only with --resume and a journal in `layout` that holds the
// frames before it), else the initial state. Notes go to `notes` (null: quiet). Throws
// InputError (exit 2) for a candidate that is damaged or of another scene or version.
BakeStart start_bake(const BakePlan& plan, const JournalLayout& layout, const Simulator& simulator, std::FILE* notes);

// A bake that writes checkpoints owns its folder: the checkpoints after `start` that another
// scene or version wrote, or that cannot be read, are removed (noted in `notes`), so a later
// --resume finds this bake's. Never throws.
void remove_foreign_checkpoints(const BakePlan& plan, long long start, const SimState& shape, std::FILE* notes);

// A bake that writes checkpoints (else nothing): foreign checkpoints removed, and start.journal
// this bake's, cut to the frames before start.frame, or created empty when a checkpoint to come
// needs frames in it (last_checkpoint), else left null.
void open_bake_journal(const BakePlan& plan, const JournalLayout& layout, BakeStart& start, std::FILE* notes);

}  // namespace treeanim
