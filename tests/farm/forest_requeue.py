#!/usr/bin/python3
"""configs/forest-demo.json baked through a real one-node Slurm (scripts/slurm-local): `treeanim farm
submit --engine slurm --tasks 4 --wait`, with one array task requeued (scontrol requeue) in the
middle of a tree once it has finished another. Then: farm submit and the gather job succeeded,
forest.json lists every tree, the requeued task ran twice (Restarts=1, two starts in its log), its
second run skipped the trees it had finished and resumed the tree in progress from its checkpoint,
and every tree's files and forest.json equal `treeanim run` of the forest in one process, byte for
byte. The daemons are stopped by their process ids afterwards.

usage: forest_requeue.py TREEANIM      (exit 0 pass, 1 fail, 77 skipped: no Slurm and TREEANIM_FARM_SKIP_OK=1)
"""
import json
import os
import re
import signal
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "forest"))
import forest_bake  # noqa: E402
import slurm_cluster  # noqa: E402
from forest_bake import Failed  # noqa: E402

TASKS = 4
REQUEUED = 1
# The demo forest with the demo broadleaf (iterations 8, 9,293 vertices): a broadleaf takes about
# 3 s here, long enough to requeue a task in the middle of one.
FRAMES = 120
LONGER = ["--set", "lsystem.iterations=8", "--set", "time.frames=%d" % FRAMES, "--set", "time.substeps=16"]
CHECKPOINT_EVERY = 5
# The requeue lands while the tree in progress has no checkpoint past this frame: half a tree of
# slack before it could finish.
REQUEUE_BEFORE = FRAMES // 2
LIMIT = 420  # s, the harness stops the cluster then; below ctest's TIMEOUT (tests/farm.cmake)


def task_trees(treeanim, tmp):
    """farm plan --json => [[tree id, ...] per task]."""
    plan = os.path.join(tmp, "plan.json")
    forest_bake.run(treeanim, "farm", "plan", forest_bake.SCENE, "--tasks", str(TASKS), "--json", plan, *LONGER)
    with open(plan) as f:
        return [task["trees"] for task in json.load(f)["tasks"]]


def parts(out, trees):
    """The trees (of `trees`) whose manifest part is written: complete."""
    return {t for t in trees if os.path.exists(os.path.join(out, "forest.parts", t + ".json"))}


def bake_on_slurm(treeanim, cluster, out, trees):
    """farm submit --wait with task REQUEUED requeued mid-tree => (the cluster's job records, the
    trees complete and the tree in progress at the requeue, farm submit's wall time)."""
    began = time.monotonic()
    # Its own process group: a failure stops farm submit and the sbatch --wait it runs.
    submit = subprocess.Popen([treeanim, "farm", "submit", forest_bake.SCENE, "--engine", "slurm", "--tasks",
                               str(TASKS), "-o", out, "--wait", "--checkpoint-every", str(CHECKPOINT_EVERY), *LONGER],
                              env=cluster.env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                              start_new_session=True)
    try:
        first = submit.stdout.readline()  # printed once the array is in, before sbatch --wait
        array = re.match(r"submitted job array (\d+) ", first)
        if not array:
            rest, errors = submit.communicate()
            raise Failed("farm submit (exit %s) said: %s%s%s" % (submit.returncode, first, rest, errors))
        mine = set(trees[REQUEUED])
        seen = {}

        def mid_tree():  # a tree of the task finished, another in progress with an early checkpoint
            seen["complete"] = parts(out, mine)
            seen["baking"] = forest_bake.tree_in_progress(out, REQUEUE_BEFORE, mine)
            return bool(seen["complete"]) and seen["baking"] is not None

        cluster.requeue_when_running("%s_%d" % (array.group(1), REQUEUED), ready=mid_tree)
        rest, errors = submit.communicate(timeout=LIMIT)
    finally:
        if submit.poll() is None:
            os.killpg(submit.pid, signal.SIGKILL)
            submit.wait()
    seconds = time.monotonic() - began
    if submit.returncode != 0:
        raise Failed("farm submit --wait exited %d:\n%s%s%s" % (submit.returncode, first, rest, errors))
    return cluster.jobs(), seen["complete"], seen["baking"], seconds


def check_jobs(records):
    """The array's tasks completed, REQUEUED restarted once and the others never; the gather completed."""
    tasks = {int(r["ArrayTaskId"]): r for r in records.values() if r.get("ArrayTaskId")}
    gathers = [r for r in records.values() if r["JobName"].endswith("-gather")]
    if sorted(tasks) != list(range(TASKS)) or len(gathers) != 1:
        raise Failed("the cluster ran %s" % {name: r["JobName"] for name, r in records.items()})
    for task, record in sorted(tasks.items()):
        restarts = 1 if task == REQUEUED else 0
        if record["JobState"] != "COMPLETED" or int(record["Restarts"]) != restarts:
            raise Failed("task %d ended %s (exit %s) after %s restarts, expected COMPLETED after %d"
                         % (task, record["JobState"], record["ExitCode"], record["Restarts"], restarts))
    if gathers[0]["JobState"] != "COMPLETED" or gathers[0]["ExitCode"] != "0:0":
        raise Failed("the gather job ended %s (exit %s)" % (gathers[0]["JobState"], gathers[0]["ExitCode"]))


def check_resumed(out, complete, baking):
    """The requeued task's log (appended by both runs): two starts, the first stopped by Slurm's
    SIGTERM, the second skipping every tree complete at the requeue and resuming `baking`."""
    with open(os.path.join(out, "farm", "logs", "task-%d.log" % REQUEUED)) as f:
        log = f.read()
    runs = re.split(r"^shard %d/%d: \d+ of the forest" % (REQUEUED, TASKS), log, flags=re.M)[1:]
    if len(runs) != 2:
        raise Failed("task %d started %d times, expected 2:\n%s" % (REQUEUED, len(runs), log[-3000:]))
    if "interrupted by SIGTERM" not in runs[0]:
        raise Failed("task %d's first run was not stopped by SIGTERM:\n%s" % (REQUEUED, runs[0][-2000:]))
    skipped = set(re.findall(r"^tree \d+/\d+ (\S+): complete, skipped$", runs[1], re.M))
    if not complete <= skipped:
        raise Failed("complete at the requeue: %s; the second run skipped %s" % (sorted(complete), sorted(skipped)))
    resumed = re.search(r"^treeanim: resuming at frame (\d+) from \S*/checkpoints/%s/" % re.escape(baking),
                        runs[1], re.M)
    if not resumed or not 0 < int(resumed.group(1)) <= FRAMES:
        raise Failed("tree %s did not resume from its checkpoint:\n%s" % (baking, runs[1][-3000:]))
    return sorted(skipped), int(resumed.group(1))


def bake_and_compare(treeanim, tmp):
    """The test in folder `tmp` => its summary line."""
    trees = task_trees(treeanim, tmp)
    farm = os.path.join(tmp, "farm-out")
    with slurm_cluster.SlurmCluster(limit=LIMIT) as cluster:
        records, complete, baking, farm_seconds = bake_on_slurm(treeanim, cluster, farm, trees)
        check_jobs(records)
    skipped, frame = check_resumed(farm, complete, baking)
    with open(os.path.join(farm, "forest.json")) as f:
        listed = sorted(t["id"] for t in json.load(f)["trees"])
    if listed != sorted(t for task in trees for t in task):
        raise Failed("forest.json lists %s, the plan %s" % (listed, trees))
    one = os.path.join(tmp, "one")
    began = time.monotonic()
    # One thread, as each task: a thread count changes no byte, and the cores are the cluster's.
    forest_bake.run(treeanim, "run", forest_bake.SCENE, "-o", one, "-q", "--threads", "1", *LONGER)
    one_seconds = time.monotonic() - began
    forest_bake.same_outputs(one, farm)
    return ("%d trees in %d tasks on Slurm in %.1f s (one process: %.1f s); task %d requeued with %s complete and "
            "%s in progress, ran again: skipped %s, resumed %s at frame %d; every file and forest.json bit-identical"
            % (len(listed), TASKS, farm_seconds, one_seconds, REQUEUED, sorted(complete), baking, skipped, baking,
               frame))


if __name__ == "__main__":
    treeanim = os.path.abspath(sys.argv[1])
    sys.exit(slurm_cluster.run_test("forest_requeue", lambda work: bake_and_compare(treeanim, work), (Failed,)))
