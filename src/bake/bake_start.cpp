#include "bake/bake_start.h"

#include <string>
#include <system_error>

#include "common/errors.h"
#include "common/message_text.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

// The journal of a checkpoint at `frame` after the first written frame, when it holds every
// frame before it; else nullopt, with the reason noted.
std::optional<FrameJournal> journal_before(const BakePlan& plan, const JournalLayout& layout, long long frame,
                                           const fs::path& checkpoint, std::FILE* notes) {
  std::optional<FrameJournal> journal;
  try {
    journal = FrameJournal::open(journal_path(plan.checkpoints.dir, plan.written.first), layout);
  } catch (const InputError& error) {
    if (notes) std::fprintf(notes, "treeanim: not resuming from %s: %s\n", printable_text(checkpoint.string()).c_str(),
                            printable_text(error.what()).c_str());
    return std::nullopt;
  }
  if (journal->size() < frame - plan.written.first) {
    if (notes)
      std::fprintf(notes, "treeanim: not resuming from %s: the frame journal holds frames %lld to %lld only\n",
                   printable_text(checkpoint.string()).c_str(), plan.written.first,
                   plan.written.first + journal->size() - 1);
    return std::nullopt;
  }
  return journal;
}

}  // namespace

fs::path journal_path(const fs::path& dir, long long write_first) {
  return dir / ("frames-from-" + std::to_string(write_first) + ".journal");
}

BakeStart start_bake(const BakePlan& plan, const JournalLayout& layout, const Simulator& simulator, std::FILE* notes) {
  BakeStart start;
  start.frame = plan.first;
  start.state = simulator.initial_state(frame_time(plan, plan.first));
  if (!plan.use_checkpoints) return start;
  const bool resume = plan.checkpoints.resume;
  // Checkpoints after the frames to write (the newest first) are passed over, with one note.
  fs::path newest_later;
  long long later = 0;
  auto tell_later = [&] {
    if (later == 0 || !notes) return;
    const std::string newest = printable_text(newest_later.string());
    if (later == 1)
      std::fprintf(notes, "treeanim: not resuming from %s: it is after frame %lld, the last to write\n", newest.c_str(),
                   plan.written.last);
    else
      std::fprintf(notes,
                   "treeanim: not resuming from %s or the %lld other checkpoints after frame %lld, the last to write\n",
                   newest.c_str(), later - 1, plan.written.last);
  };
  for (const auto& [frame, path] : list_checkpoints(plan.checkpoints.dir)) {
    if (resume && frame > plan.written.last) {
      if (later++ == 0) newest_later = path;
      continue;
    }
    if (frame < plan.first || (!resume && frame > plan.written.first)) continue;
    auto [stored_frame, state] = read_checkpoint(path, plan.key, start.state);
    if (stored_frame != frame)
      throw InputError(path.string() + ": holds frame " + std::to_string(stored_frame) + ", not the frame in its name");
    std::optional<FrameJournal> journal;
    if (frame > plan.written.first) {
      journal = journal_before(plan, layout, frame, path, notes);
      if (!journal) continue;
    }
    start.frame = frame;
    start.state = std::move(state);
    start.checkpoint = path;
    start.journal = std::move(journal);
    tell_later();
    if (notes) std::fprintf(notes, "treeanim: resuming at frame %lld from %s\n", start.frame,
                            printable_text(path.string()).c_str());
    return start;
  }
  tell_later();
  if (resume && notes)
    std::fprintf(notes, "treeanim: no usable checkpoint in %s: baking from frame %lld\n",
                 printable_text(plan.checkpoints.dir.string()).c_str(), plan.first);
  return start;
}

void remove_foreign_checkpoints(const BakePlan& plan, long long start, const SimState& shape, std::FILE* notes) {
  for (const auto& [frame, path] : list_checkpoints(plan.checkpoints.dir)) {
    if (frame <= start) continue;
    std::string why;
    try {
      read_checkpoint(path, plan.key, shape);
      continue;  // this bake's: the same bits it would write
    } catch (const std::exception& error) {
      why = error.what();
    }
    std::error_code ignored;
    fs::remove(path, ignored);
    if (notes) std::fprintf(notes, "treeanim: removed %s (%s)\n", printable_text(path.string()).c_str(),
                            printable_text(why).c_str());
  }
}

void open_bake_journal(const BakePlan& plan, const JournalLayout& layout, BakeStart& start, std::FILE* notes) {
  if (plan.checkpoints.every <= 0) return;
  remove_foreign_checkpoints(plan, start.frame, start.state, notes);
  if (start.journal)
    start.journal->truncate(start.frame - plan.written.first);  // the frames before the checkpoint's
  else if (std::max(start.frame, plan.written.first) < last_checkpoint(plan))  // a checkpoint to come needs it
    start.journal = FrameJournal::create(journal_path(plan.checkpoints.dir, plan.written.first), layout);
}

}  // namespace treeanim
