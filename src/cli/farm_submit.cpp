// treeanim farm submit: a forest's bake as farm jobs (docs/farm.md). The job scripts call this
// very executable (/proc/self/exe) on the scene by absolute path: every task runs
// `treeanim run SCENE --shard I/N -o OUT --checkpoint-every K --resume`, then one gather job.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <system_error>

#include "bake/forest_tasks.h"
#include "cli/commands.h"
#include "cli/run_program.h"
#include "cli/shell_words.h"
#include "common/errors.h"
#include "common/message_text.h"
#include "files/free_space.h"
#include "files/staged_files.h"
#include "files/text_output.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

// Everything the scripts name, absolute.
struct FarmJob {
  fs::path treeanim;  // this executable
  fs::path scene;
  fs::path out;
  fs::path farm;      // OUT/farm: the scripts
  fs::path logs;      // OUT/farm/logs: task-I.log, gather.log
  std::string name;   // the scene file's stem
  size_t tasks = 1;
  long long checkpoint_every = 1;
  int cpus = 1;
  std::string overrides;  // " --set 'A=B'" ...
  bool space_check = true;  // false: the tasks run with --no-space-check
};

// The command of task `index` (a shell expression, e.g. "$SLURM_ARRAY_TASK_ID").
// The job's scripts: for Slurm its array's and its gather's, else the plain one.
std::vector<fs::path> script_paths(const FarmJob& job, bool slurm) {
  if (slurm) return {job.farm / (job.name + ".sbatch"), job.farm / (job.name + "-gather.sbatch")};
  return {job.farm / (job.name + ".sh")};
}

std::string task_command(const FarmJob& job, const std::string& index) {
  return shell_word(job.treeanim.string()) + " run " + shell_word(job.scene.string()) + " --shard \"" + index + "/" +
         std::to_string(job.tasks) + "\" -o " + shell_word(job.out.string()) + " --checkpoint-every " +
         std::to_string(job.checkpoint_every) + " --resume --threads " + std::to_string(job.cpus) +
         (job.space_check ? "" : " --no-space-check") + job.overrides;
}

std::string gather_command(const FarmJob& job) {
  return shell_word(job.treeanim.string()) + " farm gather " + shell_word(job.scene.string()) + " -o " +
         shell_word(job.out.string()) + " --tasks " + std::to_string(job.tasks) + " --logs " +
         shell_word(job.logs.string()) + job.overrides;
}

std::string header(const FarmJob& job, const std::string& what) {
  return "#!/bin/bash\n# " + what + " of " + job.scene.string() + ", written by treeanim farm submit (docs/farm.md).\n";
}

std::string array_script(const FarmJob& job, const std::vector<std::string>& sbatch_args) {
  std::string text = header(job, "Slurm job array: " + std::to_string(job.tasks) + " shards of the forest");
  text += "#SBATCH --job-name=treeanim-" + job.name + "\n";
  text += "#SBATCH --array=0-" + std::to_string(job.tasks - 1) + "\n";
  text += "#SBATCH --requeue\n#SBATCH --open-mode=append\n";
  text += "#SBATCH --output=" + (job.logs / "task-%a.log").string() + "\n";
  text += "#SBATCH --cpus-per-task=" + std::to_string(job.cpus) + "\n";
  for (const std::string& arg : sbatch_args) text += "#SBATCH " + arg + "\n";
  return text + "# A requeued task resumes: finished trees are skipped, the tree in progress continues from its checkpoint.\n" +
         "exec " + task_command(job, "$SLURM_ARRAY_TASK_ID") + "\n";
}

std::string gather_script(const FarmJob& job, const std::vector<std::string>& sbatch_args) {
  std::string text = header(job, "Slurm gather job, after every task of the array");
  text += "#SBATCH --job-name=treeanim-" + job.name + "-gather\n";
  text += "#SBATCH --open-mode=append\n#SBATCH --output=" + (job.logs / "gather.log").string() + "\n";
  for (const std::string& arg : sbatch_args) text += "#SBATCH " + arg + "\n";
  return text + "exec " + gather_command(job) + "\n";
}

std::string plain_script(const FarmJob& job) {
  std::string text = header(job, std::to_string(job.tasks) + " tasks and the gather for any queue");
  text += "# usage: " + job.name + ".sh [TASK | gather]: task TASK (0 to " + std::to_string(job.tasks - 1) +
          "), the gather, or without\n# an argument every task in turn and then the gather. A queue runs one "
          "task per job, then the gather.\nset -u\n";
  text += "logs=" + shell_word(job.logs.string()) + "\nmkdir -p \"$logs\"\n";
  text += "task() {\n  " + task_command(job, "$1") + " >> \"$logs/task-$1.log\" 2>&1\n}\n";
  text += "gather() {\n  " + gather_command(job) + " 2>&1 | tee -a \"$logs/gather.log\"\n  return \"${PIPESTATUS[0]}\"\n}\n";
  text += "case \"${1:-all}\" in\n"
          "  all)\n    i=0\n    while [ \"$i\" -lt " + std::to_string(job.tasks) + " ]; do\n"
          "      task \"$i\" || echo \"task $i failed with exit $? (log $logs/task-$i.log)\" >&2\n"
          "      i=$((i + 1))\n    done\n    gather ;;\n"
          "  gather) gather ;;\n"
          "  *) task \"$1\" ;;\n"
          "esac\n";
  return text;
}

// The job id at the start of sbatch --parsable's output ("123" or "123;cluster"); "" if none.
std::string job_id(const std::string& out) {
  size_t end = 0;
  while (end < out.size() && out[end] >= '0' && out[end] <= '9') ++end;
  return out.substr(0, end);
}

std::string trimmed(const std::string& text) {
  const size_t last = text.find_last_not_of(" \n\r\t");
  return last == std::string::npos ? "" : text.substr(0, last + 1);
}

// Both jobs are in: their ids, scripts, logs and manifest; with --wait, how the gather job ended
// (its exit status is the command's).
int report_submitted(const FarmJob& job, bool wait, const std::string& array_id, const std::string& gather_id,
                     int gather_status, const fs::path& array, const fs::path& gather) {
  std::printf("submitted job array %s (%zu tasks, logs %s) and gather job %s after it\n  scripts %s, %s\n",
              array_id.c_str(), job.tasks, printable_text((job.logs / "task-<I>.log").string()).c_str(), gather_id.c_str(),
              printable_text(array.string()).c_str(), printable_text(gather.string()).c_str());
  if (!wait) {
    std::printf("  the manifest will be %s; the gather's report: %s\n",
                printable_text((job.out / "forest.json").string()).c_str(),
                printable_text((job.logs / "gather.log").string()).c_str());
    return 0;
  }
  std::printf("gather job %s ended with exit %d; its report: %s\n", gather_id.c_str(), gather_status,
              printable_text((job.logs / "gather.log").string()).c_str());
  return gather_status;
}

int submit_to_slurm(const FarmJob& job, const FarmRequest& request) {
  const fs::path sbatch = find_on_path("sbatch");
  if (sbatch.empty())
    throw InputError("--engine slurm: no sbatch on PATH: run farm submit on a Slurm login node (or install Slurm's "
                     "client commands), or write a plain script with --engine script; nothing was submitted");
  const std::vector<fs::path> scripts = script_paths(job, true);
  const fs::path &array = scripts[0], &gather = scripts[1];
  MadeFolders folders;
  std::error_code made;
  folders.make(job.logs, made);
  if (made) throw OutputError(job.logs.string() + ": cannot create the folder: " + made.message());
  // Submitted from temporaries (sbatch copies a script when it submits), renamed only when both are in.
  const fs::path array_temporary = temporary_path(array), gather_temporary = temporary_path(gather);
  const auto discard = [&] {
    std::error_code ignored;
    fs::remove(array_temporary, ignored);
    fs::remove(gather_temporary, ignored);
    folders.undo();
  };
  try {
    write_text_output(array_temporary, array_script(job, request.sbatch_args), true);
    write_text_output(gather_temporary, gather_script(job, request.sbatch_args), true);
  } catch (...) {
    discard();
    throw;
  }
  const ProgramResult first = run_program(sbatch, {"--parsable", array_temporary.string()});
  const std::string array_id = first.status == 0 ? job_id(first.out) : "";
  if (array_id.empty()) {
    discard();
    throw InputError("--engine slurm: " + sbatch.string() + " refused the job array (exit " +
                     std::to_string(first.status) + "): " + trimmed(first.err + first.out) +
                     "; nothing was submitted: fix what it says (partition, account, limits: --sbatch-arg) and "
                     "submit again");
  }
  std::vector<std::string> args{"--parsable", "--dependency=afterany:" + array_id};
  if (request.wait) args.push_back("--wait");
  args.push_back(gather_temporary.string());
  if (request.wait)  // sbatch --wait returns when the gather job ends: the scripts must be in place by then
    std::printf("submitted job array %s (%zu tasks); waiting for the gather job\n", array_id.c_str(), job.tasks);
  std::fflush(stdout);
  const ProgramResult second = run_program(sbatch, args);
  const std::string gather_id = job_id(second.out);
  if (gather_id.empty()) {
    const fs::path scancel = find_on_path("scancel");
    const ProgramResult cancel = scancel.empty() ? ProgramResult{127, "", "scancel is not on PATH"}
                                                 : run_program(scancel, {array_id});
    const std::string left =
        cancel.status == 0 ? "; the job array " + array_id + " was cancelled, nothing is left submitted"
                           : "; the job array " + array_id + " could not be cancelled (scancel: exit " +
                                 std::to_string(cancel.status) + ", " + trimmed(cancel.err + cancel.out) +
                                 "): it is still queued with no gather behind it; cancel it by hand (scancel " +
                                 array_id + ")";
    // The array's scripts stay while it may still run them.
    if (cancel.status == 0) discard();
    throw InputError("--engine slurm: " + sbatch.string() + " refused the gather job (exit " +
                     std::to_string(second.status) + "): " + trimmed(second.err + second.out) + left);
  }
  std::error_code error;
  fs::rename(array_temporary, array, error);
  if (!error) fs::rename(gather_temporary, gather, error);
  if (error) throw OutputError(array.string() + ": cannot rename the job script into place: " + error.message());
  return report_submitted(job, request.wait, array_id, gather_id, second.status, array, gather);
}

// Every tree's outputs, checkpoints and journal: what the tasks will write under the output folder.
double forest_bytes(const Scene& scene, const ForestEstimate& estimate, long long checkpoint_every) {
  const long long checkpoints = (scene.time.frames - 1) / checkpoint_every;
  double bytes = 0;
  for (size_t t = 0; t < estimate.tree_bytes.size(); ++t)
    bytes += estimate.tree_bytes[t] + double(checkpoints) * estimate.tree_checkpoint_bytes[t] +
             double(scene.time.frames) * estimate.tree_record_bytes[t];
  return bytes;
}

// A path or --sbatch-arg the scripts write into comments and #SBATCH lines, where no quoting
// holds: a line break there would end the line and run the rest as a command.
void refuse_control_characters(const std::string& text, const std::string& what) {
  const auto control = [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; };
  if (std::none_of(text.begin(), text.end(), control)) return;
  std::string shown;  // on one line, as printable_text would not put a line break
  for (const char c : text) {
    char escaped[5];
    std::snprintf(escaped, sizeof escaped, "\\x%02x", static_cast<unsigned char>(c));
    shown += control(c) ? std::string(escaped) : std::string(1, c);
  }
  throw InputError(what + " " + printable_text(shown) + " holds a control character (a line break, a tab): the job "
                   "scripts name it on comment and #SBATCH lines, which it would break; rename it");
}

// What the job writes under OUT/farm => InputError, before anything is written, where a file
// stands in the place of its folders or a folder in the place of a script (the tasks failed one
// by one on a file named logs, and the gather after them).
void check_job_targets(const FarmJob& job, const std::vector<fs::path>& scripts) {
  for (const fs::path& folder : {job.out, job.farm, job.logs}) {
    std::error_code error;
    const fs::file_status status = fs::status(folder, error);
    if (fs::exists(status) && !fs::is_directory(status))
      throw InputError(folder.string() + " is not a folder, left untouched; expected the folder of the job's " +
                       (folder == job.logs ? "logs" : "files") + ", or nothing there");
  }
  for (const fs::path& script : scripts) check_text_output_target(script);
}

}  // namespace

int farm_submit_command(const FarmRequest& request) {
  const Scene scene = load_scene(request.scene, request.overrides);
  if (!scene.forest) throw InputError(request.scene.string() + ": no /forest: farm submit bakes a forest's trees");
  const ForestEstimate estimate = estimate_forest(scene);  // a bad grammar fails here, not in every task
  FarmJob job;
  std::error_code error;
  job.treeanim = fs::read_symlink("/proc/self/exe", error);
  if (error) throw OutputError("/proc/self/exe: cannot find this executable: " + error.message());
  job.scene = fs::absolute(request.scene).lexically_normal();
  job.out = fs::absolute(request.out_dir.empty() ? fs::path(".") : request.out_dir).lexically_normal();
  if (job.out.has_filename() == false) job.out = job.out.parent_path();
  job.farm = job.out / "farm";
  job.logs = job.farm / "logs";
  job.name = request.scene.stem().string();
  job.tasks = request.tasks;
  job.checkpoint_every =
      request.checkpoint_every > 0 ? request.checkpoint_every : std::max(1LL, (scene.time.frames + 7) / 8);
  job.cpus = request.cpus_per_task;
  job.overrides = set_arguments(request.overrides);
  job.space_check = !request.no_space_check;
  refuse_control_characters(job.scene.string(), "the scene");
  refuse_control_characters(job.out.string(), "the output folder");
  for (const std::string& arg : request.sbatch_args) refuse_control_characters(arg, "--sbatch-arg");
  if (job.space_check)
    check_free_space({{job.out / "forest.json", forest_bytes(scene, estimate, job.checkpoint_every)}});

  check_job_targets(job, script_paths(job, request.engine == "slurm"));
  if (request.engine == "slurm") return submit_to_slurm(job, request);
  if (request.wait) throw InputError("--wait: only with --engine slurm (run the script itself to wait for it)");
  if (!request.sbatch_args.empty())
    throw InputError("--sbatch-arg: only with --engine slurm (a plain script has no #SBATCH lines)");
  const fs::path script = script_paths(job, false).front();
  write_text_output(script, plain_script(job), true);
  // The commands as shell words, to copy as they are (a ' or $( in the path stays text).
  const std::string shown = printable_text(script.string()), word = printable_text(shell_word(script.string()));
  std::printf("wrote %s: %zu tasks then the gather; run it (every task in turn), or give your queue one job per "
              "task (%s I, I = 0 to %zu) and then %s gather\n",
              shown.c_str(), job.tasks, word.c_str(), job.tasks - 1, word.c_str());
  return 0;
}

}  // namespace treeanim
