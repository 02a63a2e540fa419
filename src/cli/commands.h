#pragma once
// The subcommands of the treeanim CLI. Each returns the process exit code; input, simulation
// and output errors propagate as exceptions that main() maps to exit codes (DESIGN.md).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "cli/progress.h"

namespace treeanim {

struct RunRequest {
  std::filesystem::path scene;
  std::filesystem::path out_dir;              // "" = paths relative to the working directory
  std::optional<std::string> frames;          // "START:END", inclusive, frames to write
  int threads = 0;                            // 0 = OpenMP default
  std::vector<std::string> overrides;         // --set PATH=VALUE
  long long checkpoint_every = 0;             // frames between checkpoints; 0 = none
  std::filesystem::path checkpoint_dir;       // "" = out_dir/checkpoints
  bool resume = false;                        // start from the newest usable checkpoint
  std::optional<std::string> shard;           // "I/N" or "auto/N": bake the forest's shard I of N only
  Verbosity verbosity = Verbosity::kNormal;
};

// Bakes the scene: simulate and write every output, with checkpoints and resume
// (docs/checkpoint.md). Returns 0, or 130/143 on a signal.
int run_command(const RunRequest& request);
// Loads, derives and builds the model without simulating; prints counts.
int validate_command(const std::filesystem::path& scene, const std::vector<std::string>& overrides);
enum class InfoFormat { kText, kJson, kResolvedScene };
// Prints counts and estimates as text or as one JSON object, or the resolved scene.
int info_command(const std::filesystem::path& scene, const std::vector<std::string>& overrides,
                 InfoFormat format);

// "START:END" => inclusive range within [first, last]; throws InputError naming --frames.
std::pair<long long, long long> parse_frame_range(const std::string& text, long long first,
                                                  long long last);

}  // namespace treeanim
