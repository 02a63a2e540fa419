#pragma once
// The subcommands of the treeanim CLI. Each returns the process exit code; input, simulation
// and output errors propagate as exceptions that run_command_line (cli/command_line.h) maps to
// exit codes (docs/design.md).
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
  bool no_space_check = false;                // skip the estimate of the bake's files against the free space
  std::optional<std::string> shard;           // "I/N" or "auto/N": bake the forest's shard I of N only
  Verbosity verbosity = Verbosity::kNormal;
};

// Bakes the scene (bake/): simulate and write every output, with checkpoints and resume
// (docs/checkpoint.md); prints its progress and summary. Returns 0, or 130/143/129 on a signal.
int run_command(const RunRequest& request);
// Loads, derives and builds the model without simulating; prints counts.
int validate_command(const std::filesystem::path& scene, const std::vector<std::string>& overrides);
enum class InfoFormat { kText, kJson, kResolvedScene };
// Prints counts and estimates as text or as one JSON object, or the resolved scene.
int info_command(const std::filesystem::path& scene, const std::vector<std::string>& overrides,
                 InfoFormat format);

// Prints the species library (name, height range, vertices, clusters and first sway frequency at
// the default height), as a table or as a JSON array.
int species_command(bool json);

// treeanim farm plan | submit | gather (docs/farm.md).
struct FarmRequest {
  std::filesystem::path scene;
  std::vector<std::string> overrides;         // --set PATH=VALUE, passed on to every task
  size_t tasks = 0;                           // farm tasks the forest is split into
  std::filesystem::path out_dir;              // -o; "" = the working folder
  std::filesystem::path json;                 // plan: also write the plan here
  std::string engine;                         // submit: "slurm" or "script"
  bool wait = false;                          // submit: wait for the gather job and return its status
  long long checkpoint_every = 0;             // submit: frames between checkpoints; 0 = frames / 8
  int cpus_per_task = 1;                      // submit: cores (OpenMP threads) of each task
  std::vector<std::string> sbatch_args;       // submit: extra #SBATCH options (--partition=x)
  std::filesystem::path logs;                 // gather: the tasks' logs (task-I.log) to point at
  bool no_space_check = false;                // submit: skip the forest's estimate (and the tasks' own)
};

// Prints (and with --json writes) the tasks: trees per task, estimated core-hours and bytes.
int farm_plan_command(const FarmRequest& request);
// Writes the job scripts and, for slurm, submits the array and the gather job behind it.
int farm_submit_command(const FarmRequest& request);
// Checks every tree's bake is complete and writes OUT/forest.json; else names what is missing
// (with the tasks and their logs) and returns 4.
int farm_gather_command(const FarmRequest& request);

}  // namespace treeanim
