#pragma once
// What `treeanim run` prints of a bake: notes and progress on stderr, the summary on stdout
// (nothing but an interruption when quiet).
#include <filesystem>
#include <optional>
#include <vector>

#include "bake/bake_config.h"
#include "bake/bake_forest.h"
#include "bake/bake_log.h"
#include "cli/progress.h"

namespace treeanim {

class BakePrinter {
 public:
  // scene: the scene baked (a forest's trees are named in its lines); config: its bake's;
  // scene_file and overrides: as given, for the gather command a shard's last line shows.
  BakePrinter(const Scene& scene, const BakeConfig& config, const std::filesystem::path& scene_file,
              const std::vector<std::string>& overrides, Verbosity verbosity);
  BakePrinter(const BakePrinter&) = delete;
  BakePrinter& operator=(const BakePrinter&) = delete;

  // The log to hand to the bake; valid while the printer lives.
  const BakeLog& log() const { return log_; }
  // A shard's trees, before they are baked.
  void shard_begins(const std::vector<size_t>& trees) const;
  // A forest's bake has ended (with exit code 0).
  void forest_baked(const ForestBakeResult& result) const;

 private:
  void print_tree(size_t i, size_t count, size_t index, bool complete) const;
  void print_summary(const TreeBakeResult& result) const;

  const Scene& scene_;
  const BakeConfig& config_;
  std::string gather_arguments_;  // SCENE [-o OUT] [--set ...], as shell words
  Verbosity verbosity_;
  std::optional<Progress> progress_;
  LongTaskProgress long_task_;  // a derivation's steps, a forest's passes over its trees
  BakeLog log_;
};

}  // namespace treeanim
