// The treeanim command line (CLI11): the subcommands' arguments, the dispatch to
// cli/commands.h, and the error types of common/errors.h mapped to the exit codes of docs/design.md.
#include "cli/command_line.h"

#include <omp.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <regex>
#include <string>

#include "cli/commands.h"
#include "common/errors.h"
#include "common/message_text.h"
#include "sim/kernel_isa.h"
#include "sim/simulator.h"
#include "sim/volume_grids.h"
#include "sim/wind_volume.h"
#include "treeanim_version.h"

namespace treeanim {

namespace {

// The most threads a bake takes (--threads, --cpus-per-task, OMP_NUM_THREADS).
constexpr int kMaxThreads = 1024;

// What the subcommands parse into.
struct Arguments {
  RunRequest run;
  bool quiet = false, verbose = false;
  std::filesystem::path validate_scene;
  std::vector<std::string> validate_overrides;
  std::filesystem::path info_scene;
  std::vector<std::string> info_overrides;
  bool info_json = false, info_resolved = false;
  bool species_json = false;
  FarmRequest farm;
};

// The subcommands, to tell which one was given.
struct Subcommands {
  CLI::App* run = nullptr;
  CLI::App* validate = nullptr;
  CLI::App* info = nullptr;
  CLI::App* species = nullptr;
  CLI::App* plan = nullptr;    // farm plan
  CLI::App* submit = nullptr;  // farm submit
  CLI::App* gather = nullptr;  // farm gather
};

// A count option's check: CLI::Range called 'abc' or '2.5' "not in range 1 to 1024".
CLI::Validator whole_number(long long lo, long long hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        long long value = 0;
        if (!CLI::detail::lexical_cast(text, value)) return "expected a whole number, got '" + excerpt(text) + "'";
        if (value < lo || value > hi)
          return "expected " + std::to_string(lo) + " ... " + std::to_string(hi) + ", got " + text;
        return "";
      },
      "INT in " + std::to_string(lo) + " ... " + std::to_string(hi));
}

// A path option given as '' names nothing: `-o ''` wrote into the working folder unasked.
std::string non_empty_path(const std::string& path) { return path.empty() ? "expected a path, got ''" : ""; }

CLI::App* add_run(CLI::App& app, Arguments& args) {
  CLI::App* run_app = app.add_subcommand("run", "Simulate a scene and write its outputs");
  run_app->add_option("scene", args.run.scene, "Scene file (JSON)")->required();
  run_app->add_option("-o,--out", args.run.out_dir,
                      "Folder that relative output paths are resolved against (created if needed)")
      ->check(non_empty_path);
  run_app->add_option("--frames", args.run.frames,
                      "Write only frames START:END (inclusive); the simulation starts at time.start, or "
                      "at the newest checkpoint at or before START (docs/checkpoint.md)");
  run_app->add_option("--threads", args.run.threads, "OpenMP threads (default: OMP_NUM_THREADS or all cores)")
      ->check(whole_number(1, kMaxThreads));
  run_app->add_option("--set", args.run.overrides,
                      "Override a scene value: PATH=VALUE, PATH dotted (time.frames=48), VALUE "
                      "JSON or a plain string; repeatable, one PATH=VALUE each")
      ->allow_extra_args(false);
  run_app->add_option("--checkpoint-every", args.run.checkpoint_every,
                      "Write the complete simulation state every N frames (docs/checkpoint.md)")
      ->check(whole_number(1, 1'000'000'000));
  run_app->add_option("--checkpoint-dir", args.run.checkpoint_dir,
                      "Folder of the checkpoints (default: OUT/checkpoints, or ./checkpoints without -o)")
      ->check(non_empty_path);
  run_app->add_flag("--resume", args.run.resume,
                    "Continue from the newest usable checkpoint and complete every output; without "
                    "one, bake from the start");
  run_app->add_flag("--no-space-check", args.run.no_space_check,
                    "Bake even when the outputs' estimated size (with checkpoints and journal) exceeds the "
                    "free space of their filesystems");
  run_app->add_option("--shard", args.run.shard,
                      "Bake only task I of N of a forest's trees (0-based, balanced by estimated cost; I may be "
                      "'auto' for $SLURM_ARRAY_TASK_ID); docs/farm.md");
  CLI::Option* quiet_flag = run_app->add_flag("-q,--quiet", args.quiet, "No progress or summary");
  run_app->add_flag("-v,--verbose", args.verbose, "Stage timings and details")->excludes(quiet_flag);
  run_app->footer(
      "Examples:\n"
      "  treeanim run configs/demo.json\n"
      "  treeanim run configs/demo.json -o out/ --frames 0:47 --threads 2\n"
      "  treeanim run configs/demo.json -o out/ --checkpoint-every 24 --resume\n"
      "  treeanim run configs/forest-demo.json -o out/ --shard 2/4 --checkpoint-every 8 --resume\n"
      "  treeanim run scene.json --set lsystem.iterations=6 --set time.substeps=8 --quiet");
  return run_app;
}

CLI::App* add_validate(CLI::App& app, Arguments& args) {
  CLI::App* validate_app =
      app.add_subcommand("validate", "Load the scene, derive the tree and build the model; no simulation");
  validate_app->add_option("scene", args.validate_scene, "Scene file (JSON)")->required();
  validate_app->add_option("--set", args.validate_overrides, "Override a scene value: PATH=VALUE")
      ->allow_extra_args(false);
  validate_app->footer(
      "Examples:\n"
      "  treeanim validate configs/demo.json\n"
      "  treeanim validate scene.json --set lsystem.iterations=8");
  return validate_app;
}

CLI::App* add_info(CLI::App& app, Arguments& args) {
  CLI::App* info_app = app.add_subcommand("info", "Print counts (modules, segments, vertices, clusters) and estimates");
  info_app->add_option("scene", args.info_scene, "Scene file (JSON)")->required();
  info_app->add_option("--set", args.info_overrides, "Override a scene value: PATH=VALUE")
      ->allow_extra_args(false);
  CLI::Option* json_flag = info_app->add_flag("--json", args.info_json, "Print one JSON object");
  info_app->add_flag("--resolved-scene", args.info_resolved,
                     "Print the scene with every default filled in (what outputs record)")
      ->excludes(json_flag);
  info_app->footer(
      "Examples:\n"
      "  treeanim info configs/table1-13548.json\n"
      "  treeanim info configs/demo.json --json | jq .mesh.vertices\n"
      "  treeanim info configs/demo.json --resolved-scene --set time.fps=30");
  return info_app;
}

CLI::App* add_species(CLI::App& app, Arguments& args) {
  CLI::App* species_app = app.add_subcommand(
      "species", "List the species library: name, height range, vertices, clusters, first sway frequency");
  species_app->add_flag("--json", args.species_json, "Print a JSON array of objects, one per species");
  species_app->footer(
      "Examples:\n"
      "  treeanim species\n"
      "  treeanim species --json | jq -r '.[].name'\n"
      "A scene then starts from one: {\"species\": \"english_oak\"} or\n"
      "{\"species\": {\"name\": \"english_oak\", \"height\": 22}} (docs/species.md).");
  return species_app;
}

void add_farm_submit(CLI::App* submit, FarmRequest& farm) {
  submit->add_option("--engine", farm.engine, "slurm: write sbatch scripts and submit them; script: a plain shell script for any queue")
      ->required()->check(CLI::IsMember({"slurm", "script"}));
  submit->add_option("--tasks", farm.tasks, "Farm tasks (Slurm array size)")->required()->check(whole_number(1, 1'000'000));
  submit->add_option("-o,--out", farm.out_dir, "Output folder of every task (default: the working folder)")
      ->check(non_empty_path);
  submit->add_flag("--no-space-check", farm.no_space_check,
                   "Submit even when the forest's estimated files exceed the output folder's free space (the "
                   "tasks then skip their own check too)");
  submit->add_flag("--wait", farm.wait, "Wait for the gather job and exit with its status (slurm)");
  submit->add_option("--checkpoint-every", farm.checkpoint_every, "Frames between checkpoints (default: frames / 8)")
      ->check(whole_number(1, 1'000'000'000));
  submit->add_option("--cpus-per-task", farm.cpus_per_task, "Cores of each task (its threads)")->check(whole_number(1, kMaxThreads));
  submit->add_option("--sbatch-arg", farm.sbatch_args, "An extra #SBATCH option, e.g. --partition=bake; repeatable");
  submit->footer(
      "Examples:\n"
      "  treeanim farm submit configs/forest-demo.json --engine slurm --tasks 4 -o /shared/out --wait\n"
      "  treeanim farm submit configs/forest-demo.json --engine script --tasks 4 -o out/");
}

void add_farm(CLI::App& app, FarmRequest& farm, Subcommands& commands) {
  CLI::App* farm_app = app.add_subcommand("farm", "Bake a forest on a render farm: plan, submit, gather (docs/farm.md)");
  farm_app->require_subcommand(1);
  commands.plan = farm_app->add_subcommand("plan", "Split a forest into tasks balanced by estimated cost; print them");
  commands.submit = farm_app->add_subcommand("submit", "Write the farm job scripts (a task per shard, then a gather) and submit them");
  commands.gather = farm_app->add_subcommand("gather", "Check every tree of a forest is baked and write OUT/forest.json");
  for (CLI::App* sub : {commands.plan, commands.submit, commands.gather}) {
    sub->add_option("scene", farm.scene, "Scene file (JSON) with a /forest")->required();
    sub->add_option("--set", farm.overrides, "Override a scene value: PATH=VALUE")
      ->allow_extra_args(false);
  }
  commands.plan->add_option("--tasks", farm.tasks, "Farm tasks")->required()->check(whole_number(1, 1'000'000));
  commands.plan->add_option("--json", farm.json, "Also write the plan as JSON to this file")->check(non_empty_path);
  commands.plan->footer("Example:\n  treeanim farm plan configs/forest-demo.json --tasks 4 --json plan.json");
  add_farm_submit(commands.submit, farm);
  commands.gather->add_option("-o,--out", farm.out_dir, "Output folder of the tasks (default: the working folder)")
      ->check(non_empty_path);
  CLI::Option* tasks =
      commands.gather
          ->add_option("--tasks", farm.tasks, "Tasks the forest was split into: name the task of each missing tree")
          ->check(whole_number(1, 1'000'000));
  commands.gather->add_option("--logs", farm.logs, "Folder of the tasks' logs (task-I.log), named for failed tasks")
      ->check(non_empty_path)
      ->needs(tasks);  // a log is named by its task, which --tasks decides
  commands.gather->footer(
      "Example (after every shard's `run --shard I/4 -o out`):\n"
      "  treeanim farm gather configs/forest-demo.json -o out --tasks 4 --logs out/logs");
}

// A command whose standard output is what it makes (info, species, farm plan) => its exit code,
// once that output is written whole: `info --json > meta.json` on a full disk must not exit 0
// with an empty file.
int written_to_stdout(int code) {
  std::cout.flush();
  if (std::fflush(stdout) != 0 || std::ferror(stdout) || std::cout.fail())
    throw OutputError("standard output: the command's output could not be written whole (is the disk full, or "
                      "the pipe closed?)");
  return code;
}

int dispatch(const Subcommands& commands, Arguments& args) {
  if (*commands.run) {
    args.run.verbosity = args.quiet ? Verbosity::kQuiet : args.verbose ? Verbosity::kVerbose : Verbosity::kNormal;
    return run_command(args.run);
  }
  if (*commands.validate) return validate_command(args.validate_scene, args.validate_overrides);
  if (*commands.species) return written_to_stdout(species_command(args.species_json));
  if (*commands.plan) return written_to_stdout(farm_plan_command(args.farm));
  if (*commands.submit) return farm_submit_command(args.farm);
  if (*commands.gather) return farm_gather_command(args.farm);
  return written_to_stdout(info_command(args.info_scene, args.info_overrides,
                                       args.info_resolved ? InfoFormat::kResolvedScene
                                       : args.info_json   ? InfoFormat::kJson
                                                          : InfoFormat::kText));
}

int report(const char* kind, const std::exception& error, int code) {
  std::fprintf(stderr, "treeanim: %s%s\n", kind, shown_message(error.what()).c_str());
  return code;
}

// libgomp takes OMP_NUM_THREADS as it stands: a count past --threads' range crashed it as it
// made the threads (99999: SIGSEGV in the first parallel region), and a value it cannot read
// (0, -1, 'abc') it ignored with a warning, baking on every core. `bakes`: the command simulates
// (run), and a value it cannot read is refused too; the others only grow trees, on libgomp's
// default => what is wrong, or "".
std::string omp_threads_error(const Arguments& args, bool bakes) {
  const char* text = std::getenv("OMP_NUM_THREADS");
  if (args.run.threads > 0 || text == nullptr) return "";
  const std::string expected = "expected 1 ... " + std::to_string(kMaxThreads) +
                               " threads, or a comma-separated list of them (" +
                               (bakes ? "or give run --threads N" : "or unset it") + ")";
  // libgomp's syntax: positive whole numbers, one a nesting level, spaces around each.
  static const std::regex kCounts(R"(\s*\+?0*[1-9][0-9]*\s*(,\s*\+?0*[1-9][0-9]*\s*)*)");
  if (!std::regex_match(text, kCounts)) return bakes ? "OMP_NUM_THREADS is '" + excerpt(text) + "': " + expected : "";
  const int asked = omp_get_max_threads();
  if (asked <= kMaxThreads) return "";
  return "OMP_NUM_THREADS asks for " + std::to_string(asked) + " threads: " + expected;
}

// Runs the subcommand; a failure's exception => its message and exit code.
int run_reporting_errors(const Subcommands& commands, Arguments& args) {
  try {
    if (const std::string isa = asked_isa_error(); !isa.empty()) throw InputError(isa);
    if (const std::string blocks = asked_blocks_error(); !blocks.empty()) throw InputError(blocks);
    if (const std::string threads = omp_threads_error(args, bool(*commands.run)); !threads.empty())
      throw InputError(threads);
    return dispatch(commands, args);
  } catch (const InputError& error) {
    return report("error: ", error, kExitInput);
  } catch (const SimulationError& error) {
    return report("simulation failed: ", error, kExitSimulation);
  } catch (const OutputError& error) {
    return report("output failed: ", error, kExitOutput);
  } catch (const std::bad_alloc&) {
    // Memory the machine does not have: no input is wrong, the tree or bake is too large here.
    std::fprintf(stderr, "treeanim: out of memory: the tree or its bake needs more memory than this machine "
                         "gives (a smaller tree: lsystem.iterations, lsystem.max_modules; fewer trees; a coarser "
                         "wind volume)\n");
    return kExitSimulation;
  } catch (const std::exception& error) {
    // Not a documented failure: a bug. Report it rather than abort with a core dump.
    return report("internal error: ", error, kExitSimulation);
  }
}

}  // namespace

int run_command_line(int argc, char** argv) {
  // The wind volume's reader checking a file in a process of its own (sim/volume_grids.h).
  if (argc == 2 && std::string(argv[1]) == kVolumeTrialArgument) return serve_volume_trials();
  allow_volume_trials();
  CLI::App app{"treeanim " TREEANIM_VERSION
               " - grows trees from L-systems and bakes their motion in wind with hierarchical "
               "shape matching"};
  app.set_version_flag("--version", "treeanim " TREEANIM_VERSION);
  app.require_subcommand(1);
  app.footer(
      "Exit codes: 0 success, 2 bad input, 3 simulation failed, 4 output failed, 130/143/129 "
      "interrupted.\nRun 'treeanim SUBCOMMAND --help' for examples.");
  Arguments args;
  Subcommands commands;
  commands.run = add_run(app, args);
  commands.validate = add_validate(app, args);
  commands.info = add_info(app, args);
  commands.species = add_species(app, args);
  add_farm(app, args.farm, commands);
  // CLI11 prints the version as it meets the flag, before it looks at the rest: `--version
  // extra` printed it and exited 0, as if nothing else had been given.
  for (int i = 1; i < argc && argc > 2; ++i)
    if (std::string(argv[i]) == "--version") {
      std::fprintf(stderr, "treeanim: --version takes no other arguments\n");
      return kExitUsage;
    }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    if (app.exit(error) != 0) return kExitUsage;
    try {  // --help and --version: their text is the command's output, which may not fit (/dev/full)
      return written_to_stdout(kExitOk);
    } catch (const OutputError& failure) {
      return report("output failed: ", failure, kExitOutput);
    }
  }
  return run_reporting_errors(commands, args);
}

}  // namespace treeanim
