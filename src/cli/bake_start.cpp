#include "cli/bake_start.h"

#include <string>
#include <system_error>

#include "common/errors.h"

namespace treeanim {

namespace fs = std::filesystem;

fs::path journal_path(const fs::path& dir, long long write_first) {
  return dir / ("frames-from-" + std::to_string(write_first) + ".journal");
}

BakeStart find_bake_start(const BakePlan& plan, const Simulator& simulator, std::FILE* log) {
  BakeStart start;
  start.frame = plan.first;
  start.state = simulator.initial_state(static_cast<double>(plan.first) * plan.frame_dt);
  if (!plan.use_checkpoints) return start;
  const auto candidates = list_checkpoints(plan.checkpoint_dir);
  for (const auto& [frame, path] : candidates) {
    if (frame < plan.first || frame > plan.write_last || (!plan.resume && frame > plan.write_first)) continue;
    auto [stored_frame, state] = read_checkpoint(path, plan.key, start.state);
    if (stored_frame != frame)
      throw InputError(path.string() + ": holds frame " + std::to_string(stored_frame) + ", not the frame in its name");
    std::optional<FrameJournal> journal;
    if (frame > plan.write_first) {
      const fs::path journal_file = journal_path(plan.checkpoint_dir, plan.write_first);
      try {
        journal = FrameJournal::open(journal_file, plan.journal);
      } catch (const InputError& error) {
        if (log) std::fprintf(log, "treeanim: not resuming from %s: %s\n", path.c_str(), error.what());
        continue;
      }
      if (journal->size() < frame - plan.write_first) {
        if (log)
          std::fprintf(log, "treeanim: not resuming from %s: the frame journal holds frames %lld to %lld only\n",
                       path.c_str(), plan.write_first, plan.write_first + journal->size() - 1);
        continue;
      }
    }
    start.frame = frame;
    start.state = std::move(state);
    start.checkpoint = path;
    start.journal = std::move(journal);
    return start;
  }
  if (plan.resume && log)
    std::fprintf(log, "treeanim: no usable checkpoint in %s: baking from frame %lld\n", plan.checkpoint_dir.c_str(),
                 plan.first);
  return start;
}

void remove_foreign_checkpoints(const BakePlan& plan, long long start, const SimState& shape, std::FILE* log) {
  for (const auto& [frame, path] : list_checkpoints(plan.checkpoint_dir)) {
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
    if (log) std::fprintf(log, "treeanim: removed %s (%s)\n", path.c_str(), why.c_str());
  }
}

}  // namespace treeanim
