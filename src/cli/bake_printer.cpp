#include "cli/bake_printer.h"

#include <cstdio>
#include <string>

#include "bake/bake_tree.h"
#include "bake/signals.h"
#include "bake/forest_manifest.h"
#include "bake/prepare_tree.h"
#include "cli/shell_words.h"
#include "common/message_text.h"
#include "sim/kernel_isa.h"

namespace treeanim {

BakePrinter::BakePrinter(const Scene& scene, const BakeConfig& config, const std::filesystem::path& scene_file,
                         const std::vector<std::string>& overrides, Verbosity verbosity)
    : scene_(scene),
      config_(config),
      gather_arguments_(shell_word(scene_file.string()) +
                        (config.out_dir.empty() ? "" : " -o " + shell_word(config.out_dir.string())) +
                        set_arguments(overrides)),
      verbosity_(verbosity),
      long_task_(verbosity, stderr) {
  const bool quiet = verbosity == Verbosity::kQuiet;
  log_.notes = quiet ? nullptr : stderr;
  log_.grown_step = [this](int step, int steps, size_t modules) { long_task_.grown(step, steps, modules); };
  log_.trees_passed = [this](const char* what, size_t done, size_t total) { long_task_.trees(what, done, total); };
  if (verbosity == Verbosity::kVerbose)
    log_.prepared = [](const PreparedTree& tree) {
      std::fprintf(stderr, "grown in %.3f s, model built in %.3f s: %zu vertices, %zu clusters; solver loops: %s\n",
                   tree.grow_seconds, tree.model_seconds, tree.model.vertex_count(), tree.model.cluster_count(),
                   kernel_isa_name(kernel_isa()));
    };
  log_.frames_begin = [this](long long total) { progress_.emplace(total, verbosity_, stderr); };
  log_.frame_done = [this](long long done) { progress_->update(done); };
  log_.frames_end = [this] { progress_->finish(); };
  if (!quiet)
    log_.team_resized = [this](const std::string& line) {
      if (progress_) progress_->note(line);
      else std::fprintf(stderr, "%s\n", line.c_str());
    };
  log_.interrupted = [this](int signal_number, long long frame) {
    const char* name = interrupt_name(signal_number);
    if (frame < 0) {
      std::fprintf(stderr, "treeanim: interrupted by %s between two trees; the trees baked are kept (--resume "
                   "skips them)\n", name);
      return;
    }
    std::fprintf(stderr, "treeanim: interrupted by %s at frame %lld; no output was kept%s\n", name, frame,
                 config_.checkpoints.every > 0 ? " (--resume continues from the last checkpoint)" : "");
  };
  if (quiet) return;
  log_.baked = [this](const TreeBakeResult& result) { print_summary(result); };
  log_.forest_tree = [this](size_t i, size_t count, size_t tree, bool complete) { print_tree(i, count, tree, complete); };
}

void BakePrinter::print_summary(const TreeBakeResult& result) const {
  const std::string samples = result.samples ? " simulated as " + std::to_string(result.samples) + " samples" : "";
  // The bake's own time to the millisecond: scripts/bench-frame divides it by the frames of a short bake.
  std::printf("baked %lld frame%s: %zu vertices%s, %zu clusters, %lld substeps in %.2f s (simulation + writing %.3f s)\n",
              result.written.count(), result.written.count() == 1 ? "" : "s", result.vertices, samples.c_str(),
              result.clusters, result.substeps,
              result.seconds, result.run_seconds);
  for (const SummaryFile& file : result.final_paths) {
    if (file.files == 1) std::printf("  wrote %s\n", printable_text(file.path.string()).c_str());
    else std::printf("  wrote %s ... %s (%lld files)\n", printable_text(file.path.string()).c_str(),
                     printable_text(file.last.filename().string()).c_str(), file.files);
  }
  for (const auto& [path, line] : result.reports) std::printf("  %s: %s\n", printable_text(path.string()).c_str(), line.c_str());
  if (!result.loop) return;
  const LoopSummary& loop = *result.loop;
  // A resumed bake starts from a checkpoint of the warmed-up state: the run that wrote it warmed up.
  char warmup[96];
  if (loop.resumed)
    std::snprintf(warmup, sizeof warmup, "warmed up before the checkpoint it resumed from");
  else
    std::snprintf(warmup, sizeof warmup, "%d warm-up period%s%s", loop.warmup.periods,
                  loop.warmup.periods == 1 ? "" : "s",
                  loop.warmup.converged ? "" : " (the motion did not repeat: baked as it stands)");
  std::printf("  loop: %s; seam %.3g m, %.2f x the median frame step (%.3g m)\n", warmup, loop.seam,
              loop.median_step > 0 ? loop.seam / loop.median_step : 0.0, loop.median_step);
}

void BakePrinter::print_tree(size_t i, size_t count, size_t index, bool complete) const {
  const Forest& forest = *scene_.forest;
  const ForestTree& tree = forest.trees[index];
  if (complete) {
    std::printf("tree %zu/%zu %s: complete, skipped\n", i + 1, count, printable_text(tree.id).c_str());
    return;
  }
  std::printf("tree %zu/%zu %s (%s, seed %llu) at (%.2f, %.2f, %.2f)\n", i + 1, count, printable_text(tree.id).c_str(),
              printable_text(forest.variants[tree.variant].name).c_str(), static_cast<unsigned long long>(tree.seed),
              tree.position.x(), tree.position.y(), tree.position.z());
  std::fflush(stdout);
}

void BakePrinter::shard_begins(const std::vector<size_t>& trees) const {
  if (verbosity_ == Verbosity::kQuiet || !config_.shard) return;
  std::printf("shard %zu/%zu: %zu of the forest's %zu trees\n", config_.shard->index, config_.shard->count,
              trees.size(), scene_.forest->trees.size());
}

void BakePrinter::forest_baked(const ForestBakeResult& result) const {
  if (verbosity_ == Verbosity::kQuiet) return;
  const std::filesystem::path& out = config_.out_dir;
  if (config_.shard)
    std::printf("shard %zu/%zu: %zu trees baked, %zu complete before; once every shard is done: treeanim farm "
                "gather %s\n",
                config_.shard->index, config_.shard->count, result.baked, result.skipped,
                printable_text(gather_arguments_).c_str());
  else
    std::printf("forest: %zu trees (%zu baked, %zu complete before); manifest %s\n", scene_.forest->trees.size(),
                result.baked, result.skipped, printable_text(forest_manifest_path(out).string()).c_str());
}

}  // namespace treeanim
