#!/usr/bin/python3
"""Two bakes on the same two cores, each given two threads (bake/thread_governor.h).

usage: contention.py TREEANIM DEMO_SCENE     (exit 0 pass, 1 fail, 77 skipped)

Both are pinned to the same CPUs (two of this process's, or its only one), so their four
spinning threads share two cores: each bake must tell that its threads waited for a core
and step on one (the second's stderr is a terminal, whose progress bar is cleared for the
line), and its files must be byte for byte those of a bake on one thread alone. Without the governor each frame took 5-80 ms instead of 0.7 (docs/benchmarks.md,
"Threads"); the test asserts no time, only what the bakes say and write.
"""
import filecmp
import json
import os
import subprocess
import sys
import tempfile
import threading
import time

SKIP = 77
GUSTS = [{"time": 0, "speed": 9, "direction": [1, 0, 0.3], "gust": 3}]  # no calm: no island sleeps


def schedstat_counts():
    """Whether this thread's schedstat exists and counts its time on a CPU (a sandbox may show zeros)."""
    def cpu_ns():
        with open("/proc/thread-self/schedstat") as f:
            return int(f.read().split()[0])
    try:
        before = cpu_ns()
        end = time.monotonic() + 0.05
        while time.monotonic() < end:
            pass
        return cpu_ns() > before
    except (OSError, ValueError, IndexError):
        return False


def read_all(fd, chunks):
    """A terminal's output until its last writer closes it (EIO on Linux)."""
    while True:
        try:
            chunk = os.read(fd, 65536)
        except OSError:
            break
        if not chunk:
            break
        chunks.append(chunk)
    os.close(fd)


def main():
    treeanim, scene = sys.argv[1], sys.argv[2]
    if not schedstat_counts():
        print("skipped: the kernel keeps no schedstat, so a bake cannot see other work")
        return SKIP
    cpus = sorted(os.sched_getaffinity(0))[:2]
    sets = ["time.frames=600", 'hsm.particles="samples"', "wind.keys=" + json.dumps(GUSTS),
            'outputs=[{"format":"hdf5","path":"a.h5","velocities":true},{"format":"pc2","path":"a.pc2"}]']
    args = [a for s in sets for a in ("--set", s)]
    with tempfile.TemporaryDirectory() as work:
        def bake(name, threads, pinned, stderr=subprocess.PIPE):
            command = [treeanim, "run", scene, "-o", os.path.join(work, name), "--threads", str(threads)] + args
            return subprocess.Popen(command, stdout=subprocess.PIPE, stderr=stderr, text=True,
                                    preexec_fn=(lambda: os.sched_setaffinity(0, cpus)) if pinned else None)

        alone = bake("alone", 1, False)
        out, err = alone.communicate()
        if alone.returncode != 0:
            print(f"FAIL: the one-thread bake exited {alone.returncode}: {err}")
            return 1
        # The second bake's stderr is a terminal: its progress bar is cleared for the line.
        master, terminal = os.openpty()
        pair = [bake("first", 2, True), bake("second", 2, True, terminal)]
        os.close(terminal)
        screen = []
        reader = threading.Thread(target=read_all, args=(master, screen))
        reader.start()
        failed = False
        for name, process in zip(["first", "second"], pair):
            out, err = process.communicate()
            if name == "second":
                reader.join()
                err = b"".join(screen).decode(errors="replace")
            said = [line.split("\x1b[K")[-1] for line in err.replace("\r", "\n").splitlines()
                    if "waited for a core" in line]
            print(f"{name}: exit {process.returncode}; " + (said[0] if said else "said nothing of waiting for cores"))
            if process.returncode != 0 or not any("stepping on 1" in line for line in said):
                failed = True
            if name == "second":
                cleared = "\r\x1b[Ktreeanim: frame" in err
                print(f"  on a terminal: the progress bar {'cleared' if cleared else 'NOT cleared'} for that line")
                failed |= not cleared
            for file in ("a.h5", "a.pc2"):
                same = filecmp.cmp(os.path.join(work, "alone", file), os.path.join(work, name, file), shallow=False)
                print(f"  {file}: {'the same bytes as' if same else 'DIFFERS from'} the one-thread bake")
                failed |= not same
    print("FAIL" if failed else "PASS")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
