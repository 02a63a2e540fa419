// treeanim command-line front end: parses arguments (CLI11), runs a subcommand and maps the
// error types of common/errors.h to the exit codes of DESIGN.md.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "cli/commands.h"
#include "common/errors.h"
#include "treeanim_version.h"

namespace {

using namespace treeanim;

int report(const char* kind, const std::exception& error, int code) {
  std::fprintf(stderr, "treeanim: %s%s\n", kind, error.what());
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"treeanim " TREEANIM_VERSION
               " - grows trees from L-systems and bakes their motion in wind with hierarchical "
               "shape matching"};
  app.set_version_flag("--version", "treeanim " TREEANIM_VERSION);
  app.require_subcommand(1);
  app.footer(
      "Exit codes: 0 success, 2 bad input, 3 simulation failed, 4 output failed, 130/143 "
      "interrupted.\nRun 'treeanim SUBCOMMAND --help' for examples.");

  RunRequest run;
  bool quiet = false, verbose = false;
  CLI::App* run_app = app.add_subcommand("run", "Simulate a scene and write its outputs");
  run_app->add_option("scene", run.scene, "Scene file (JSON)")->required();
  run_app->add_option("-o,--out", run.out_dir,
                      "Folder that relative output paths are resolved against (created if needed)");
  run_app->add_option("--frames", run.frames,
                      "Write only frames START:END (inclusive); the simulation still starts at "
                      "time.start");
  run_app->add_option("--threads", run.threads, "OpenMP threads (default: OMP_NUM_THREADS or all cores)")
      ->check(CLI::Range(1, 1024));
  run_app->add_option("--set", run.overrides,
                      "Override a scene value: PATH=VALUE, PATH dotted (time.frames=48), VALUE "
                      "JSON or a plain string; repeatable");
  run_app->add_option("--checkpoint-every", run.checkpoint_every,
                      "Write the complete simulation state every N frames (docs/checkpoint.md)")
      ->check(CLI::Range(1LL, 1'000'000'000LL));
  run_app->add_option("--checkpoint-dir", run.checkpoint_dir,
                      "Folder of the checkpoints (default: OUT/checkpoints, or ./checkpoints without -o)");
  run_app->add_flag("--resume", run.resume,
                    "Continue from the newest usable checkpoint and complete every output; without "
                    "one, bake from the start");
  run_app->add_option("--shard", run.shard,
                      "Bake only task I of N of a forest's trees (0-based, balanced by estimated cost; I may be "
                      "'auto' for $SLURM_ARRAY_TASK_ID); docs/farm.md");
  CLI::Option* quiet_flag = run_app->add_flag("-q,--quiet", quiet, "No progress or summary");
  run_app->add_flag("-v,--verbose", verbose, "Stage timings and details")->excludes(quiet_flag);
  run_app->footer(
      "Examples:\n"
      "  treeanim run configs/demo.json\n"
      "  treeanim run configs/demo.json -o out/ --frames 0:47 --threads 2\n"
      "  treeanim run configs/demo.json -o out/ --checkpoint-every 24 --resume\n"
      "  treeanim run configs/forest-demo.json -o out/ --shard 2/4 --checkpoint-every 8 --resume\n"
      "  treeanim run scene.json --set lsystem.iterations=6 --set time.substeps=8 --quiet");

  std::filesystem::path validate_scene;
  std::vector<std::string> validate_overrides;
  CLI::App* validate_app =
      app.add_subcommand("validate", "Load the scene, derive the tree and build the model; no simulation");
  validate_app->add_option("scene", validate_scene, "Scene file (JSON)")->required();
  validate_app->add_option("--set", validate_overrides, "Override a scene value: PATH=VALUE");
  validate_app->footer(
      "Examples:\n"
      "  treeanim validate configs/demo.json\n"
      "  treeanim validate scene.json --set lsystem.iterations=8");

  std::filesystem::path info_scene;
  std::vector<std::string> info_overrides;
  bool info_json = false, info_resolved = false;
  CLI::App* info_app = app.add_subcommand("info", "Print counts (modules, segments, vertices, clusters) and estimates");
  info_app->add_option("scene", info_scene, "Scene file (JSON)")->required();
  info_app->add_option("--set", info_overrides, "Override a scene value: PATH=VALUE");
  CLI::Option* json_flag = info_app->add_flag("--json", info_json, "Print one JSON object");
  info_app->add_flag("--resolved-scene", info_resolved,
                     "Print the scene with every default filled in (what outputs record)")
      ->excludes(json_flag);
  info_app->footer(
      "Examples:\n"
      "  treeanim info configs/table1-13548.json\n"
      "  treeanim info configs/demo.json --json | jq .mesh.vertices\n"
      "  treeanim info configs/demo.json --resolved-scene --set time.fps=30");

  FarmRequest farm;
  CLI::App* farm_app = app.add_subcommand("farm", "Bake a forest on a render farm: plan, submit, gather (docs/farm.md)");
  farm_app->require_subcommand(1);
  CLI::App* plan_app = farm_app->add_subcommand("plan", "Split a forest into tasks balanced by estimated cost; print them");
  CLI::App* submit_app =
      farm_app->add_subcommand("submit", "Write the farm job scripts (a task per shard, then a gather) and submit them");
  CLI::App* gather_app =
      farm_app->add_subcommand("gather", "Check every tree of a forest is baked and write OUT/forest.json");
  for (CLI::App* sub : {plan_app, submit_app, gather_app}) {
    sub->add_option("scene", farm.scene, "Scene file (JSON) with a /forest")->required();
    sub->add_option("--set", farm.overrides, "Override a scene value: PATH=VALUE");
  }
  plan_app->add_option("--tasks", farm.tasks, "Farm tasks")->required()->check(CLI::Range(1, 1'000'000));
  plan_app->add_option("--json", farm.json, "Also write the plan as JSON to this file");
  plan_app->footer("Example:\n  treeanim farm plan configs/forest-demo.json --tasks 4 --json plan.json");
  submit_app->add_option("--engine", farm.engine, "slurm: write sbatch scripts and submit them; script: a plain shell script for any queue")
      ->required()->check(CLI::IsMember({"slurm", "script"}));
  submit_app->add_option("--tasks", farm.tasks, "Farm tasks (Slurm array size)")->required()->check(CLI::Range(1, 1'000'000));
  submit_app->add_option("-o,--out", farm.out_dir, "Output folder of every task (default: the working folder)");
  submit_app->add_flag("--wait", farm.wait, "Wait for the gather job and exit with its status (slurm)");
  submit_app->add_option("--checkpoint-every", farm.checkpoint_every, "Frames between checkpoints (default: frames / 8)")
      ->check(CLI::Range(1LL, 1'000'000'000LL));
  submit_app->add_option("--cpus-per-task", farm.cpus_per_task, "Cores of each task (its threads)")->check(CLI::Range(1, 1024));
  submit_app->add_option("--sbatch-arg", farm.sbatch_args, "An extra #SBATCH option, e.g. --partition=bake; repeatable");
  submit_app->footer(
      "Examples:\n"
      "  treeanim farm submit configs/forest-demo.json --engine slurm --tasks 4 -o /shared/out --wait\n"
      "  treeanim farm submit configs/forest-demo.json --engine script --tasks 4 -o out/");
  gather_app->add_option("-o,--out", farm.out_dir, "Output folder of the tasks (default: the working folder)");
  gather_app->add_option("--tasks", farm.tasks, "Tasks the forest was split into: name the task of each missing tree")
      ->check(CLI::Range(1, 1'000'000));
  gather_app->add_option("--logs", farm.logs, "Folder of the tasks' logs (task-I.log), named for failed tasks");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? kExitOk : kExitUsage;
  }

  try {
    if (*run_app) {
      run.verbosity = quiet ? Verbosity::kQuiet : verbose ? Verbosity::kVerbose : Verbosity::kNormal;
      return run_command(run);
    }
    if (*validate_app) return validate_command(validate_scene, validate_overrides);
    if (*plan_app) return farm_plan_command(farm);
    if (*submit_app) return farm_submit_command(farm);
    if (*gather_app) return farm_gather_command(farm);
    return info_command(info_scene, info_overrides,
                        info_resolved ? InfoFormat::kResolvedScene
                        : info_json   ? InfoFormat::kJson
                                      : InfoFormat::kText);
  } catch (const InputError& error) {
    return report("error: ", error, kExitInput);
  } catch (const SimulationError& error) {
    return report("simulation failed: ", error, kExitSimulation);
  } catch (const OutputError& error) {
    return report("output failed: ", error, kExitOutput);
  } catch (const std::bad_alloc& error) {
    return report("out of memory: ", error, kExitSimulation);
  } catch (const std::exception& error) {
    // Not a documented failure: a bug. Report it rather than abort with a core dump.
    return report("internal error: ", error, kExitSimulation);
  }
}
