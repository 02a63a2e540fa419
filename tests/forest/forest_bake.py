#!/usr/bin/python3
"""Forest bakes end to end (docs/farm.md), on configs/forest-demo.json:

  shards  the forest baked in one process equals the union of its shards baked separately,
          every output file byte for byte, and farm gather writes the same forest.json
  resume  a shard killed (SIGKILL) in the middle of a tree and run again with --resume skips
          the finished trees, resumes the tree in progress and gives the same files
  plan    farm plan --json: every tree in one task, tasks balanced by cost
  submit  farm submit --engine slurm against a fake sbatch on PATH (records its arguments,
          prints a job id, runs the job at once): the scripts, the dependency, --wait, the bake;
          and --engine script run as a plain shell script
  targets a folder where the second tree's output, its part or the manifest goes: exit 2 naming
          it before the first tree is baked, every file there before left as it was
  seeded  a tree whose own seed makes its variant's grammar fail: exit 2 before any tree is baked

usage: forest_bake.py TREEANIM CASE      (exit 0 pass, 1 fail)
"""
import filecmp
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "..", "..", "configs", "forest-demo.json")


class Failed(Exception):
    pass


def run(treeanim, *args, env=None, check=True):
    done = subprocess.run([treeanim, *args], capture_output=True, text=True, env=env)
    if check and done.returncode != 0:
        raise Failed("%s exited %d: %s" % (" ".join(args), done.returncode, done.stderr[-2000:]))
    return done


def output_files(folder):
    """Every tree's output file below folder (relative), not the manifest, parts, checkpoints or farm scripts."""
    found = []
    for root, dirs, names in os.walk(folder):
        dirs[:] = [d for d in dirs if d not in ("checkpoints", "forest.parts", "farm")]
        found += [os.path.relpath(os.path.join(root, n), folder) for n in names
                  if ".tmp-" not in n and n != "forest.json"]
    return sorted(found)


def same_outputs(reference, other, manifest=True):
    files = output_files(reference)
    if len(files) < 32:
        raise Failed("the reference holds only %d files" % len(files))
    if files != output_files(other):
        raise Failed("different files: %s vs %s" % (files, output_files(other)))
    names = files + (["forest.json"] if manifest else [])
    for name in names:
        if not filecmp.cmp(os.path.join(reference, name), os.path.join(other, name), shallow=False):
            raise Failed("%s differs between %s and %s" % (name, reference, other))


def case_shards(treeanim, tmp):
    one = os.path.join(tmp, "one")
    run(treeanim, "run", SCENE, "-o", one, "-q")
    shards = os.path.join(tmp, "shards")
    for i in range(2):
        run(treeanim, "run", SCENE, "-o", shards, "-q", "--shard", "%d/3" % i)
    # The last shard's closing line is the gather to run, as shell words.
    done = run(treeanim, "run", SCENE, "-o", shards, "--shard", "2/3")
    if "treeanim farm gather '%s' -o '%s'\n" % (SCENE, shards) not in done.stdout:
        raise Failed("the shard's gather hint: %s" % done.stdout[-500:])
    if os.path.exists(os.path.join(shards, "forest.json")):
        raise Failed("a shard wrote forest.json; only farm gather does")
    done = run(treeanim, "farm", "gather", SCENE, "-o", shards)
    if "all 16 trees complete" not in done.stdout:
        raise Failed("gather said: %s" % done.stdout)
    same_outputs(one, shards)
    # A gather given another scene than the folder's (a --set left out or added) is bad input:
    # the forest's manifest, which still describes its trees, stays.
    gathered = open(os.path.join(shards, "forest.json"), "rb").read()
    done = run(treeanim, "farm", "gather", SCENE, "-o", shards, "--set", "wind.turbulence_length=5", check=False)
    if done.returncode != 2 or "every tree's part is of another scene" not in done.stderr:
        raise Failed("gather with another scene: exit %d, %s" % (done.returncode, done.stderr))
    if open(os.path.join(shards, "forest.json"), "rb").read() != gathered:
        raise Failed("a gather with another scene removed or changed the forest's manifest")
    manifest = json.load(open(os.path.join(one, "forest.json")))
    trees = manifest["trees"]
    if len(trees) != 16 or len({t["variant"] for t in trees}) != 3:
        raise Failed("the manifest lists %d trees of %d variants" % (len(trees), len({t["variant"] for t in trees})))
    for tree in trees:
        if not all(os.path.isfile(os.path.join(one, f)) for o in tree["outputs"] for f in o["files"]):
            raise Failed("the manifest names files that are not there: %s" % tree["outputs"])
        if tree["bounds"]["min"][1] < -0.5 or tree["bounds"]["max"][1] <= 0:
            raise Failed("tree %s: bounds %s" % (tree["id"], tree["bounds"]))
        x, z = tree["position"][0], tree["position"][2]
        lo, hi = tree["bounds"]["min"], tree["bounds"]["max"]
        if not (lo[0] <= x <= hi[0] and lo[2] <= z <= hi[2]):
            raise Failed("tree %s at %s lies outside its world bounds %s" % (tree["id"], tree["position"], tree["bounds"]))
    # A whole forest baked again with another scene removes the manifest before it rewrites the
    # first tree: killed then, it leaves no manifest that calls old and new trees one forest.
    parts = os.path.join(one, "forest.parts")
    before = {name: os.stat(os.path.join(parts, name)).st_mtime_ns for name in os.listdir(parts)}
    process = subprocess.Popen([treeanim, "run", SCENE, "-o", one, "-q", "--set", "wind.turbulence_length=5"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and process.poll() is None:
        if any(os.stat(os.path.join(parts, n)).st_mtime_ns != t for n, t in before.items() if os.path.exists(os.path.join(parts, n))):
            process.send_signal(signal.SIGKILL)
            break
        time.sleep(0.0005)
    process.wait()
    if process.returncode != -signal.SIGKILL:
        raise Failed("expected the rebake to be killed after its first tree, got exit %s" % process.returncode)
    if os.path.exists(os.path.join(one, "forest.json")):
        raise Failed("a rebake killed after its first tree left the manifest of the bake before")
    # A removed file makes the gather fail, naming the tree and what to do: the command that bakes
    # it again, with the --set the forest was gathered with (this one leaves the scene as it is).
    os.remove(os.path.join(shards, trees[3]["outputs"][0]["files"][0]))
    done = run(treeanim, "farm", "gather", SCENE, "-o", shards, "--tasks", "3", "--set", "time.frames=24", check=False)
    rerun = "treeanim run '%s' --shard I/3 -o '%s' --set 'time.frames=24' --resume" % (SCENE, shards)
    if done.returncode != 4 or trees[3]["id"] not in done.stderr or rerun not in done.stderr:
        raise Failed("gather with a missing file: exit %d, %s" % (done.returncode, done.stderr))
    # The manifest the first gather wrote no longer describes the folder: removed, and said so.
    if os.path.exists(os.path.join(shards, "forest.json")) or "the earlier one" not in done.stderr:
        raise Failed("a gather that found a tree missing left the manifest before it: %s" % done.stderr)
    # A part copied from another tree is named as that tree's, not as another scene's.
    parts = os.path.join(shards, "forest.parts")
    shutil.copy(os.path.join(parts, trees[1]["id"] + ".json"), os.path.join(parts, trees[2]["id"] + ".json"))
    done = run(treeanim, "farm", "gather", SCENE, "-o", shards, check=False)
    copied = "%s.json is the part of tree %s, copied here" % (trees[2]["id"], trees[1]["id"])
    if done.returncode != 4 or copied not in done.stderr:
        raise Failed("gather with a copied part: exit %d, %s" % (done.returncode, done.stderr))
    # A part edited by hand to list another tree's file is not taken at its word.
    part_path = os.path.join(parts, trees[1]["id"] + ".json")
    part = json.load(open(part_path))
    part["outputs"][0]["files"][0] = trees[0]["outputs"][0]["files"][0]
    json.dump(part, open(part_path, "w"), indent=2)
    done = run(treeanim, "farm", "gather", SCENE, "-o", shards, check=False)
    edited = "%s.json was edited after its tree was baked" % trees[1]["id"]
    if done.returncode != 4 or edited not in done.stderr:
        raise Failed("gather with an edited part: exit %d, %s" % (done.returncode, done.stderr))


def listed(folder):
    """The names in folder; none if it is not there (a bake removes a finished tree's checkpoints)."""
    try:
        return os.listdir(folder)
    except (FileNotFoundError, NotADirectoryError):
        return []


def tree_in_progress(out, last=200, trees=None):
    """The id of a tree (of `trees`, default any) with checkpoints, none past frame `last`, and no
    part yet (baking), else None."""
    folder = os.path.join(out, "checkpoints")
    for tree in listed(folder):
        if (trees is not None and tree not in trees) or os.path.exists(os.path.join(out, "forest.parts", tree + ".json")):
            continue
        frames = [int(n[len("checkpoint-"):-len(".h5")]) for n in listed(os.path.join(folder, tree))
                  if n.startswith("checkpoint-") and n.endswith(".h5")]
        if frames and max(frames) <= last:
            return tree
    return None


def case_resume(treeanim, tmp):
    longer = ["--set", "time.frames=240", "--set", "time.substeps=8"]
    reference = os.path.join(tmp, "reference")
    run(treeanim, "run", SCENE, "-o", reference, "-q", *longer)
    out = os.path.join(tmp, "killed")
    shard = ["--shard", "0/2", "--checkpoint-every", "20"]
    process = subprocess.Popen([treeanim, "run", SCENE, "-o", out, "-q", *shard, *longer],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    parts = os.path.join(out, "forest.parts")
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        done_trees = len(os.listdir(parts)) if os.path.isdir(parts) else 0
        if done_trees >= 2 and tree_in_progress(out):
            process.send_signal(signal.SIGKILL)
            break
        if process.poll() is not None:
            raise Failed("the shard ended (exit %s) before it could be killed mid-tree" % process.returncode)
        time.sleep(0.0005)
    process.wait()
    if process.returncode != -signal.SIGKILL:
        raise Failed("expected the shard to die of SIGKILL, got exit %s" % process.returncode)
    finished = len(os.listdir(parts))
    # As a kill between a tree's part and the removal of its checkpoints leaves them: spent.
    spent = os.path.join(out, "checkpoints", sorted(os.listdir(parts))[0][:-len(".json")])
    os.makedirs(spent, exist_ok=True)
    open(os.path.join(spent, "checkpoint-20.h5"), "wb").close()
    done = run(treeanim, "run", SCENE, "-o", out, *shard, "--resume", *longer)
    if os.path.exists(spent):
        raise Failed("the resumed shard skipped a complete tree but left its spent checkpoints in %s" % spent)
    if done.stdout.count("complete, skipped") != finished:
        raise Failed("%d trees were complete, the resumed shard skipped %d:\n%s"
                     % (finished, done.stdout.count("complete, skipped"), done.stdout))
    if "resuming at frame" not in done.stderr:
        raise Failed("the tree in progress did not resume from its checkpoint:\n%s" % done.stderr[-3000:])
    run(treeanim, "run", SCENE, "-o", out, "-q", "--shard", "1/2", *longer)
    run(treeanim, "farm", "gather", SCENE, "-o", out, *longer)
    same_outputs(reference, out)
    if os.path.exists(os.path.join(out, "checkpoints")):
        raise Failed("the forest is whole, yet the folder of its spent checkpoints stayed: %s"
                     % sorted(os.listdir(os.path.join(out, "checkpoints"))))


def case_plan(treeanim, tmp):
    plan_file = os.path.join(tmp, "plan.json")
    run(treeanim, "farm", "plan", SCENE, "--tasks", "5", "--json", plan_file)
    plan = json.load(open(plan_file))
    ids = sorted(i for task in plan["tasks"] for i in task["trees"])
    manifest_ids = sorted(t["id"] for t in json.load(open(os.path.join(HERE, "..", "..", "configs",
                                                                         "forest-demo.json")))["forest"]["trees"])
    if len(ids) != 16 or len(set(ids)) != 16 or not set(manifest_ids) <= set(ids):
        raise Failed("the plan's tasks hold %s" % ids)
    costs = [task["vertex_steps"] for task in plan["tasks"]]
    if len(costs) != 5 or max(costs) > 1.35 * sum(costs) / 5:
        raise Failed("unbalanced tasks: %s" % costs)
    if not plan["total"]["core_hours"] > 0 or not plan["total"]["bytes"] > 0:
        raise Failed("no estimate: %s" % plan["total"])


FAKE_SBATCH = r'''#!/usr/bin/python3
# A stand-in for Slurm's sbatch: records its arguments and the script, prints a job id
# (--parsable), and runs the job at once: an array task by task, then (with --wait) returns
# the job's exit status.
import json, os, re, shutil, subprocess, sys
log = os.environ["FAKE_SBATCH_LOG"]
calls = open(log).read().splitlines() if os.path.exists(log) else []
job = 1000 + len(calls)
script = sys.argv[-1]
shutil.copy(script, "%s.%d" % (log, job))
with open(log, "a") as f:
    f.write(json.dumps(sys.argv[1:]) + "\n")
print(job, flush=True)
text = open(script).read()
array = re.search(r"^#SBATCH --array=0-(\d+)$", text, re.M)
status = 0
for task in range(int(array.group(1)) + 1 if array else 1):
    env = dict(os.environ, SLURM_ARRAY_TASK_ID=str(task)) if array else dict(os.environ)
    status = subprocess.run(["bash", script], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode or status
sys.exit(status if "--wait" in sys.argv else 0)
'''


def case_submit(treeanim, tmp):
    # A file where the tasks' logs go is refused before anything is written (each task failed on it).
    blocked = os.path.join(tmp, "blocked")
    os.makedirs(os.path.join(blocked, "farm"))
    open(os.path.join(blocked, "farm", "logs"), "w").close()
    done = run(treeanim, "farm", "submit", SCENE, "--engine", "script", "--tasks", "2", "-o", blocked, check=False)
    if done.returncode != 2 or "logs is not a folder, left untouched" not in done.stderr \
            or os.listdir(os.path.join(blocked, "farm")) != ["logs"]:
        raise Failed("a file where the logs go: exit %d, %s" % (done.returncode, done.stderr))
    reference = os.path.join(tmp, "reference")
    run(treeanim, "run", SCENE, "-o", reference, "-q")
    bin_dir = os.path.join(tmp, "bin")
    os.makedirs(bin_dir)
    with open(os.path.join(bin_dir, "sbatch"), "w") as f:
        f.write(FAKE_SBATCH)
    os.chmod(os.path.join(bin_dir, "sbatch"), 0o755)
    log = os.path.join(tmp, "sbatch.log")
    env = dict(os.environ, PATH=bin_dir + ":" + os.environ["PATH"], FAKE_SBATCH_LOG=log)
    out = os.path.join(tmp, "farm-out")
    # Relative paths, from another folder: the scripts must name everything absolutely.
    done = subprocess.run([treeanim, "farm", "submit", os.path.relpath(SCENE, tmp), "--engine", "slurm", "--tasks",
                           "4", "-o", "farm-out", "--wait"], cwd=tmp, capture_output=True, text=True, env=env)
    if done.returncode != 0:
        raise Failed("farm submit --wait: exit %d\n%s%s" % (done.returncode, done.stdout, done.stderr))
    calls = [json.loads(line) for line in open(log)]
    if len(calls) != 2 or calls[0][0] != "--parsable" or calls[1][:3] != ["--parsable", "--dependency=afterany:1000",
                                                                          "--wait"]:
        raise Failed("sbatch was called with %s" % calls)
    array, gather = open(log + ".1000").read(), open(log + ".1001").read()
    exe = os.path.realpath(treeanim)
    for needed in ["#SBATCH --array=0-3", "#SBATCH --requeue", "#SBATCH --output=%s/farm/logs/task-%%a.log" % out,
                   "'%s' run '%s' --shard \"$SLURM_ARRAY_TASK_ID/4\" -o '%s' --checkpoint-every 3 --resume"
                   % (exe, os.path.realpath(SCENE), out)]:
        if needed not in array:
            raise Failed("the array script lacks %r:\n%s" % (needed, array))
    if "'%s' farm gather '%s' -o '%s' --tasks 4" % (exe, os.path.realpath(SCENE), out) not in gather:
        raise Failed("the gather script:\n%s" % gather)
    for name in ["forest-demo.sbatch", "forest-demo-gather.sbatch"]:
        if not os.path.isfile(os.path.join(out, "farm", name)):
            raise Failed("%s was not kept in %s/farm" % (name, out))
    if [n for n in os.listdir(os.path.join(out, "farm")) if ".tmp-" in n]:
        raise Failed("temporaries left in %s/farm: %s" % (out, os.listdir(os.path.join(out, "farm"))))
    same_outputs(reference, out)

    # --engine script: the same work as a plain shell script, same relative outputs.
    plain = os.path.join(tmp, "plain")
    run(treeanim, "farm", "submit", SCENE, "--engine", "script", "--tasks", "3", "-o", plain)
    done = subprocess.run(["bash", os.path.join(plain, "farm", "forest-demo.sh")], capture_output=True, text=True)
    if done.returncode != 0:
        raise Failed("the plain script exited %d: %s" % (done.returncode, done.stderr))
    same_outputs(reference, plain)


def folder_state(folder):
    """folder => {relative path: None for a folder, else the file's bytes} of everything below it."""
    found = {}
    for root, dirs, names in os.walk(folder):
        for name in dirs:
            found[os.path.relpath(os.path.join(root, name), folder)] = None
        for name in names:
            with open(os.path.join(root, name), "rb") as f:
                found[os.path.relpath(os.path.join(root, name), folder)] = f.read()
    return found


def case_locked(treeanim, tmp):
    """A second whole forest into the folder a first one is baking: refused at once (exit 4,
    naming the first's process) before it makes or writes anything; the first goes on."""
    out = os.path.join(tmp, "out")
    first = subprocess.Popen([treeanim, "run", SCENE, "-o", out, "-q", "--set", "time.frames=5000"],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        while not os.path.exists(os.path.join(out, ".forest.json.lock")):
            if first.poll() is not None or time.monotonic() > deadline:
                raise Failed("the first forest did not start baking (exit %s)" % first.returncode)
            time.sleep(0.01)
        second = run(treeanim, "run", SCENE, "-o", out, "--set", "time.frames=20", "--set",
                     'outputs=[{"format": "pc2", "path": "other/{tree}.pc2"}]', check=False)
        message = "forest.json: another bake is writing this output (process %d, lock " % first.pid
        if second.returncode != 4 or message not in second.stderr:
            raise Failed("the second forest: exit %d: %s" % (second.returncode, second.stderr[-2000:]))
        if os.path.exists(os.path.join(out, "other")):
            raise Failed("the refused forest made its folder 'other'")
        if first.poll() is not None:
            raise Failed("the first forest stopped (exit %s)" % first.returncode)
    finally:
        first.kill()
        first.wait()


def case_targets(treeanim, tmp):
    # validate and info have no -o: a scene named forest.json, checked in its own folder, is not
    # taken for the manifest a bake writes (where -o puts it).
    named = os.path.join(tmp, "named")
    os.makedirs(named)
    with open(SCENE) as f:
        text = f.read().replace('"../grammars/', '"%s/' % os.path.realpath(os.path.join(HERE, "..", "..", "grammars")))
    with open(os.path.join(named, "forest.json"), "w") as f:
        f.write(text)
    for command in [["validate", "forest.json"], ["info", "forest.json"]]:
        done = subprocess.run([treeanim, *command], cwd=named, capture_output=True, text=True)
        if done.returncode != 0:
            raise Failed("%s of a scene named forest.json in its folder: exit %d, %s"
                         % (command[0], done.returncode, done.stderr))
    out = os.path.join(tmp, "out")
    # The first tree's files from an earlier bake, which a refused forest must not replace.
    for name in ["trees/hero.h5", "trees/hero.html", "caches/hero.pc2", "caches/hero.rest.obj"]:
        os.makedirs(os.path.dirname(os.path.join(out, name)), exist_ok=True)
        with open(os.path.join(out, name), "wb") as f:
            f.write(b"earlier bake of " + name.encode())
    in_the_way = [("trees/hero-bush.h5", "forest-demo.json: /outputs/0/path of tree hero-bush: "),
                  ("forest.parts/hero-bush.json", ""), ("forest.json", ""), ("forest.html", "")]
    for name, pointer in in_the_way:
        folder = os.path.join(out, name)
        os.makedirs(folder)
        before = folder_state(out)
        done = run(treeanim, "run", SCENE, "-o", out, "-q", check=False)
        message = "%s%s is a directory, left untouched" % (pointer, folder)
        if done.returncode != 2 or message not in done.stderr:
            raise Failed("a folder at %s: exit %d, expected 2 and %r: %s"
                         % (name, done.returncode, message, done.stderr))
        if folder_state(out) != before:
            raise Failed("a folder at %s: the output folder changed" % name)
        os.rmdir(folder)
    # A shard writes no manifest: a folder where it goes does not stop one.
    os.makedirs(os.path.join(out, "forest.json"))
    run(treeanim, "run", SCENE, "-o", out, "-q", "--shard", "0/16")


def case_seeded(treeanim, tmp):
    """A stochastic variant whose third tree's seed grows past lsystem.max_modules: validate and
    run refuse it (exit 2, naming the tree) before the first tree is baked; it wrote the first
    two trees, replacing an earlier bake's, then failed."""
    grammar = os.path.join(HERE, "..", "..", "grammars", "abop-1.27-stochastic.lsys")
    scene = {"lsystem": {"axiom": "F", "iterations": 0}, "time": {"frames": 3},
             "wind": {"keys": [{"time": 0, "speed": 5, "direction": [1, 0, 0]}]},
             "forest": {"variants": [{"name": "a", "lsystem": {"grammar": grammar, "iterations": 4,
                                                               "max_modules": 400}}],
                        "trees": [{"id": "t%d" % k, "position": [3 * k, 0, 0], "seed": seed}
                                  for k, seed in enumerate([7, 3, 1])]},
             "outputs": [{"format": "hdf5", "path": "{tree}.h5"}]}
    path = os.path.join(tmp, "seeded.json")
    with open(path, "w") as f:
        json.dump(scene, f)
    out = os.path.join(tmp, "out")
    os.makedirs(out)
    with open(os.path.join(out, "t0.h5"), "wb") as f:
        f.write(b"earlier bake")
    before = folder_state(out)
    message = "tree t2 (L-system seed 1): %s: derivation step 4 of 4 reached" % grammar
    for command in (["validate", path], ["run", path, "-o", out, "-q"]):
        done = run(treeanim, *command, check=False)
        if done.returncode != 2 or message not in done.stderr:
            raise Failed("%s: exit %d, expected 2 and %r: %s" % (command[0], done.returncode, message, done.stderr))
    if folder_state(out) != before:
        raise Failed("the refused forest changed its output folder: %s" % sorted(folder_state(out)))


def case_checkpoint_folders(treeanim, tmp):
    """A complete tree's checkpoint folder, which --resume clears of spent checkpoints, where a
    tree's output stands (checkpoints/{tree}); and a tree whose id makes its output the parts'
    folder: refused (exit 2) before anything is written or removed. --resume removed the first
    bake's outputs as spent checkpoints, then failed (exit 4); validate passed the second. And a
    resumed forest's parts, read back, are still its own to write."""
    scene = {"lsystem": {"axiom": "F", "iterations": 1}, "time": {"frames": 3},
             "forest": {"trees": [{"id": "x"}, {"id": "b", "position": [5, 0, 0]}]},
             "outputs": [{"format": "hdf5", "path": "checkpoints/{tree}"}]}
    path = os.path.join(tmp, "collide.json")
    with open(path, "w") as f:
        json.dump(scene, f)
    out = os.path.join(tmp, "out")
    run(treeanim, "run", path, "-o", out, "-q")
    before = folder_state(out)
    done = run(treeanim, "run", path, "-o", out, "-q", "--checkpoint-every", "1", "--resume", check=False)
    message = "writes %s, the folder of the checkpoints of tree x" % os.path.join(out, "checkpoints", "x")
    if done.returncode != 2 or message not in done.stderr:
        raise Failed("--resume: exit %d, expected 2 and %r: %s" % (done.returncode, message, done.stderr))
    if folder_state(out) != before:
        raise Failed("the refused --resume changed the output folder: %s" % sorted(folder_state(out)))
    scene["forest"]["trees"][0]["id"] = "forest.parts"
    scene["outputs"][0]["path"] = "{tree}"
    with open(path, "w") as f:
        json.dump(scene, f)
    for command in (["validate", path], ["run", path, "-o", os.path.join(tmp, "parts"), "-q"]):
        done = run(treeanim, *command, check=False)
        if done.returncode != 2 or "forest.parts" not in done.stderr:
            raise Failed("%s of a tree named forest.parts: exit %d: %s" % (command[0], done.returncode, done.stderr))
    # The parts --resume reads back are the bake's own files, not inputs it must leave alone: a
    # changed scene rebakes every tree over them.
    scene["forest"]["trees"][0]["id"] = "x"
    scene["outputs"][0]["path"] = "t/{tree}.h5"
    with open(path, "w") as f:
        json.dump(scene, f)
    again = os.path.join(tmp, "again")
    run(treeanim, "run", path, "-o", again, "-q")
    run(treeanim, "run", path, "-o", again, "-q", "--set", "time.frames=4", "--checkpoint-every", "2", "--resume")


CASES = {"shards": case_shards, "resume": case_resume, "plan": case_plan, "submit": case_submit,
         "targets": case_targets, "locked": case_locked, "seeded": case_seeded,
         "checkpoint-folders": case_checkpoint_folders}


def main():
    treeanim, case = os.path.abspath(sys.argv[1]), sys.argv[2]
    tmp = tempfile.mkdtemp(prefix="treeanim-forest-%d-" % os.getpid())
    try:
        CASES[case](treeanim, tmp)
    except Failed as failure:
        print("FAIL %s: %s" % (case, failure))
        sys.exit(1)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print("ok %s" % case)


if __name__ == "__main__":
    main()
