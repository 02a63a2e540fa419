#!/usr/bin/python3
"""The local Slurm (scripts/slurm-local) runs what a farm bake needs: a job array of 4 tasks, one
of them requeued while it runs (scontrol requeue) and run again from the start, and a job that
depends on the array (--dependency=afterany) running after every task. Then the daemons are
stopped by their process ids and must be gone.

usage: slurm_smoke.py      (exit 0 pass, 1 fail, 77 skipped: no Slurm and TREEANIM_FARM_SKIP_OK=1)
"""
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import slurm_cluster  # noqa: E402

TASKS = 4
REQUEUED = 1
# Each task: one line in its log at every start, then WORK seconds of work, then its output file.
WORK = 4
TASK_SCRIPT = """#!/bin/sh
echo "start $(date +%%s.%%N)" >> log.$SLURM_ARRAY_TASK_ID
end=$(( $(date +%%s) + %d ))
while [ "$(date +%%s)" -lt "$end" ]; do :; done
echo "task $SLURM_ARRAY_TASK_ID done" > out.$SLURM_ARRAY_TASK_ID
""" % WORK
# The dependent job lists the outputs it finds: all of them if it ran after every task.
GATHER_SCRIPT = """#!/bin/sh
ls out.* > gathered
"""


class Failed(Exception):
    pass


def lines(path):
    with open(path) as f:
        return f.read().splitlines()


def write_script(folder, name, text):
    path = os.path.join(folder, name)
    with open(path, "w") as f:
        f.write(text)
    os.chmod(path, 0o755)
    return path


def check(cluster, work):
    task = write_script(work, "task.sh", TASK_SCRIPT)
    gather = write_script(work, "gather.sh", GATHER_SCRIPT)
    began = time.monotonic()
    array = cluster.submit(["--array=0-%d" % (TASKS - 1), "--chdir", work, "--output", "slurm-%A_%a.out", task])
    dependent = cluster.submit(["--dependency=afterany:%s" % array, "--chdir", work, "--output", "slurm-%j.out",
                                gather])
    requeued = "%s_%d" % (array, REQUEUED)
    log = os.path.join(work, "log.%d" % REQUEUED)
    cluster.requeue_when_running(requeued, ready=lambda: os.path.exists(log))
    tasks = cluster.wait(array)
    gathered = cluster.wait(dependent)[dependent]
    elapsed = time.monotonic() - began

    names = ["%s_%d" % (array, i) for i in range(TASKS)]
    if sorted(tasks) != sorted(names):
        raise Failed("array records %s, expected %s" % (sorted(tasks), names))
    for i, name in enumerate(names):
        record = tasks[name]
        if record["JobState"] != "COMPLETED":
            raise Failed("%s ended %s (exit %s)" % (name, record["JobState"], record.get("ExitCode")))
        starts = len(lines(os.path.join(work, "log.%d" % i)))
        expected = 2 if i == REQUEUED else 1
        if starts != expected or int(record["Restarts"]) != expected - 1:
            raise Failed("%s started %d times (Restarts=%s), expected %d"
                         % (name, starts, record["Restarts"], expected))
        if lines(os.path.join(work, "out.%d" % i)) != ["task %d done" % i]:
            raise Failed("%s: out.%d is not its output" % (name, i))
    if gathered["JobState"] != "COMPLETED":
        raise Failed("the dependent job %s ended %s" % (dependent, gathered["JobState"]))
    last_end = max(tasks[name]["EndTime"] for name in names)  # ISO times sort as text
    if gathered["StartTime"] < last_end:
        raise Failed("the dependent job started at %s, before the last task ended (%s)"
                     % (gathered["StartTime"], last_end))
    if lines(os.path.join(work, "gathered")) != ["out.%d" % i for i in range(TASKS)]:
        raise Failed("the dependent job saw %s" % lines(os.path.join(work, "gathered")))
    return elapsed


def smoke(work):
    """The test in folder `work` => its summary line."""
    with slurm_cluster.SlurmCluster(limit=240) as cluster:  # ctest's TIMEOUT is 300 s
        elapsed = check(cluster, work)
        pids = dict(cluster.pids)
    left = [name for name, pid in pids.items() if slurm_cluster.alive(pid)]
    if left:
        raise Failed("still running after stop: %s" % left)
    return ("cluster started in %.1f s; %d tasks, one requeued, and the dependent job ran in %.1f s; daemons %s "
            "stopped in %.1f s" % (cluster.start_seconds, TASKS, elapsed, pids, cluster.stop_seconds))


if __name__ == "__main__":
    sys.exit(slurm_cluster.run_test("slurm_smoke", smoke, (Failed,)))
