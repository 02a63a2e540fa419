"""A one-node Slurm on localhost for tests (scripts/slurm-local in a per-process folder).

    with SlurmCluster() as cluster:           # starts munged, slurmctld, slurmd
        job = cluster.submit(["--array=0-3", script])
        cluster.requeue_when_running("%s_1" % job)
        cluster.wait(job)                      # {"JOBID_TASK": record, ...}
    # the daemons are stopped by their process ids, also when the block raised

Clients (sbatch, squeue, scontrol and treeanim farm submit) need `cluster.env` (SLURM_CONF).
There is no slurmdbd, so no sacct: job states come from `scontrol show job`, which keeps
finished jobs for MinJobAge (10 minutes), and Restarts counts requeues.
"""
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

REPOSITORY = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(REPOSITORY, "scripts", "slurm-local")
PROGRAMS = ("munged", "slurmctld", "slurmd", "sbatch", "squeue", "scontrol", "sinfo")
# The states a job leaves no more (a requeued job goes back to PENDING).
FINAL = {"COMPLETED", "FAILED", "CANCELLED", "TIMEOUT", "NODE_FAIL", "PREEMPTED", "OUT_OF_MEMORY",
         "BOOT_FAIL", "DEADLINE"}
# ctest's exit code for a skipped test (SKIP_RETURN_CODE in tests/farm.cmake).
SKIP = 77
# Set to 1 where the farm tests may be skipped when Slurm is not installed (never in CI).
SKIP_VARIABLE = "TREEANIM_FARM_SKIP_OK"


class SlurmError(Exception):
    pass


def missing_programs():
    """The Slurm and munge programs not on PATH or in the sbin folders (where scripts/slurm-local
    looks too), and a reason when not root => list of str."""
    path = os.pathsep.join([os.environ.get("PATH", ""), "/usr/sbin", "/sbin"])
    missing = [p for p in PROGRAMS if shutil.which(p, path=path) is None]
    if os.geteuid() != 0:
        missing.append("root (the daemons switch users)")
    return missing


def skip_or_fail_without_slurm(test):
    """Exits SKIP when Slurm is missing and SKIP_VARIABLE=1, exits 1 with what to do when it is
    missing otherwise; returns when everything is there."""
    missing = missing_programs()
    if not missing:
        return
    if os.environ.get(SKIP_VARIABLE) == "1":
        print("%s: skipped, missing: %s" % (test, ", ".join(missing)))
        sys.exit(SKIP)
    print("%s: FAIL: missing %s (run scripts/setup test as root, or set %s=1 to skip)"
          % (test, ", ".join(missing), SKIP_VARIABLE))
    sys.exit(1)


def run_test(name, check, failures=()):
    """A farm test's main: skips or fails without Slurm, then check(work) in a per-process
    temporary folder (removed at the end) => 0 after printing check's summary line, or 1 after
    printing what failed (a SlurmError or one of `failures`)."""
    skip_or_fail_without_slurm(name)
    work = tempfile.mkdtemp(prefix="treeanim-%s-%d-" % (name, os.getpid()))
    try:
        print("%s: %s" % (name, check(work)))
    except (SlurmError, *failures) as error:
        print("%s: FAIL: %s" % (name, error))
        return 1
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print("%s: ok" % name)
    return 0


def _raise_exit(signum, frame):
    print("slurm_cluster: %s: stopping the cluster" % signal.Signals(signum).name, file=sys.stderr)
    raise SystemExit(128 + signum)


def alive(pid):
    """Whether pid runs (a zombie has exited)."""
    try:
        with open("/proc/%d/stat" % pid) as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return False


def _record(line):
    """One line of `scontrol show -o job` => {key: value}. Values may hold spaces (Command=,
    WorkDir=), so a field ends where the next `Key=` starts."""
    fields = re.split(r" (?=[A-Za-z][A-Za-z:/]*=)", line.strip())
    return dict(field.split("=", 1) for field in fields if "=" in field)


def _job_name(record):
    """JOBID_TASK for an array task, JOBID otherwise."""
    if record.get("ArrayJobId") and record.get("ArrayTaskId"):
        return "%s_%s" % (record["ArrayJobId"], record["ArrayTaskId"])
    return record["JobId"]


class SlurmCluster:
    """Starts scripts/slurm-local in `folder` (default a per-process folder in /tmp, removed at
    the end) and stops it on exit; SIGTERM and SIGINT stop it too, and so does the end of
    `limit` seconds (SIGALRM): keep it below ctest's TIMEOUT, whose SIGKILL would leave the
    daemons running."""

    def __init__(self, folder=None, timeout=60, limit=None):
        self.folder = folder or "/tmp/treeanim-slurm-test-%d" % os.getpid()
        self.timeout = timeout
        self.limit = limit
        self.remove = folder is None
        self.env = dict(os.environ, SLURM_CONF=os.path.join(self.folder, "slurm.conf"))
        self.script_env = dict(self.env, SLURM_LOCAL_DIR=self.folder, SLURM_LOCAL_TIMEOUT=str(timeout))
        self.pids = {}  # daemon name -> process id, read once the cluster runs
        self.start_seconds = None  # wall time of `scripts/slurm-local start`, s
        self.stop_seconds = None  # wall time of stopping the daemons, s

    def pid_files(self):
        """Daemon name -> its pid file (as scripts/slurm-local writes them)."""
        return {"munged": os.path.join(self.folder, "munge", "munged.pid"),
                "slurmctld": os.path.join(self.folder, "run", "slurmctld.pid"),
                "slurmd": os.path.join(self.folder, "run", "slurmd.pid")}

    def __enter__(self):
        self.previous_handlers = {s: signal.signal(s, _raise_exit)
                                  for s in (signal.SIGTERM, signal.SIGINT, signal.SIGALRM)}
        if self.limit:
            signal.alarm(self.limit)
        start = time.monotonic()
        try:
            self.script("start")
            self.start_seconds = time.monotonic() - start
            for name, path in self.pid_files().items():
                with open(path) as f:
                    self.pids[name] = int(f.read())
        except BaseException:
            self.stop(failed=True)
            raise
        return self

    def __exit__(self, kind, value, trace):
        self.stop(failed=kind is not None)
        return False

    def script(self, command):
        """Runs scripts/slurm-local COMMAND for this folder => its output; SlurmError if it fails."""
        done = subprocess.run([SCRIPT, command], env=self.script_env, capture_output=True, text=True)
        if done.returncode != 0:
            raise SlurmError("scripts/slurm-local %s failed (exit %d):\n%s%s"
                             % (command, done.returncode, done.stdout, done.stderr))
        return done.stdout

    def stop(self, failed=False):
        """Stops the daemons (the script, then SIGKILL by process id for any left) and checks that
        they are gone; prints the logs' ends when `failed`; removes the folder if it is ours.
        A signal now would cut the stop short: they are ignored until it ends."""
        signal.alarm(0)
        for s in getattr(self, "previous_handlers", {}):
            signal.signal(s, signal.SIG_IGN)
        try:
            if failed:
                self.print_logs()
            start = time.monotonic()
            try:
                self.script("stop")
            except SlurmError as error:
                print(error, file=sys.stderr)
            pids = dict(self.pids)
            for name, path in self.pid_files().items():  # also daemons of a start that failed
                try:
                    with open(path) as f:
                        pids.setdefault(name, int(f.read()))
                except (OSError, ValueError):
                    pass
            left = {name: pid for name, pid in pids.items() if alive(pid) and self._is_daemon(pid, name)}
            for pid in left.values():
                os.kill(pid, signal.SIGKILL)
            self.stop_seconds = time.monotonic() - start
            if left:
                raise SlurmError("scripts/slurm-local stop left %s running (killed)" % left)
        finally:
            for s, handler in getattr(self, "previous_handlers", {}).items():
                signal.signal(s, handler)
            if self.remove:
                shutil.rmtree(self.folder, ignore_errors=True)

    @staticmethod
    def _is_daemon(pid, name):
        try:
            with open("/proc/%d/comm" % pid) as f:
                return f.read().strip() == name
        except OSError:
            return False

    def print_logs(self, lines=30):
        """The end of each daemon's log, to stderr."""
        for log in (os.path.join(self.folder, "munge", "munged.log"),
                    os.path.join(self.folder, "log", "slurmctld.log"),
                    os.path.join(self.folder, "log", "slurmd.log")):
            if os.path.exists(log):
                with open(log, errors="replace") as f:
                    tail = f.readlines()[-lines:]
                print("--- %s\n%s" % (log, "".join(tail)), file=sys.stderr)

    def run(self, *command):
        """A Slurm client command with this cluster's SLURM_CONF => stdout; SlurmError if it fails."""
        done = subprocess.run(list(command), env=self.env, capture_output=True, text=True)
        if done.returncode != 0:
            raise SlurmError("%s failed (exit %d): %s" % (" ".join(command), done.returncode, done.stderr.strip()))
        return done.stdout

    def submit(self, arguments):
        """sbatch --parsable ARGUMENTS => the job id (str)."""
        return self.run("sbatch", "--parsable", *arguments).strip().split(";")[0]

    def jobs(self, job=None):
        """The records of a job or array (`scontrol show -o job JOB`), pending tasks not yet split
        off included; every job of the cluster when job is None (what `treeanim farm submit`
        submitted) => {JOBID_TASK or JOBID: {key: value}}."""
        out = self.run("scontrol", "show", "-o", "job", *([] if job is None else [str(job)]))
        return {_job_name(r): r for r in map(_record, out.splitlines()) if "JobId" in r}

    def states(self, job=None):
        """{JOBID_TASK or JOBID: JobState}."""
        return {name: r["JobState"] for name, r in self.jobs(job).items()}

    def wait(self, job=None, timeout=300):
        """Waits until every record of the job (every task of an array; every job when job is
        None) is in a final state => jobs(job); SlurmError with the states on timeout."""
        deadline = time.monotonic() + timeout
        while True:
            records = self.jobs(job)
            if records and all(r["JobState"] in FINAL for r in records.values()):
                return records
            if time.monotonic() > deadline:
                raise SlurmError("job %s not finished after %d s: %s" % (job, timeout, self.states(job)))
            time.sleep(0.5)

    def wait_running(self, task, timeout=120, ready=None):
        """Waits until TASK (JOBID_TASK or JOBID) runs and `ready()` (if given) is true."""
        deadline = time.monotonic() + timeout
        while True:
            state = self.states(task).get(task)
            if state == "RUNNING" and (ready is None or ready()):
                return
            if state in FINAL or time.monotonic() > deadline:
                raise SlurmError("%s did not run (state %s)" % (task, state))
            time.sleep(0.2)

    def requeue_when_running(self, task, timeout=120, ready=None):
        """Requeues TASK once it runs and `ready()` is true (scontrol requeue): Slurm kills it and
        runs it again from the start, at the earliest cred_expire (10 s) later."""
        self.wait_running(task, timeout, ready)
        self.run("scontrol", "requeue", task)
