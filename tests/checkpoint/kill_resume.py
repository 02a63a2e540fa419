#!/usr/bin/python3
"""Kill and resume (docs/checkpoint.md): a bake with --checkpoint-every is killed with SIGKILL
mid-way (twice), resumed with --resume, and its files are compared with an uninterrupted
bake: every file byte for byte, HDF5 included (HDF5 objects carry no times), with h5diff
naming what differs in an HDF5 file. Then the refusals: a checkpoint of another scene
and a damaged checkpoint exit 2 with the reason; --frames A:B starts from a checkpoint.

usage: kill_resume.py TREEANIM      (exit 0 pass, 1 fail)
"""
import filecmp
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "bake.json")
EVERY = 10


class Failed(Exception):
    pass


def run(treeanim, out, *args):
    """A finished bake of SCENE into `out` => CompletedProcess (text)."""
    return subprocess.run([treeanim, "run", SCENE, "-o", out, *args], capture_output=True, text=True)


def checkpoints(folder):
    """Frames of the checkpoints in folder, ascending."""
    if not os.path.isdir(folder):
        return []
    frames = []
    for name in os.listdir(folder):
        if name.startswith("checkpoint-") and name.endswith(".h5"):
            frames.append(int(name[len("checkpoint-"):-len(".h5")]))
    return sorted(frames)


def kill_after_checkpoint(treeanim, out, frame, *args):
    """Starts a checkpointing bake and SIGKILLs it once the checkpoint of `frame` or later
    exists => the newest checkpoint frame at the kill."""
    folder = os.path.join(out, "checkpoints")
    process = subprocess.Popen([treeanim, "run", SCENE, "-o", out, "-q", "--checkpoint-every", str(EVERY), *args],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        if checkpoints(folder) and checkpoints(folder)[-1] >= frame:
            process.send_signal(signal.SIGKILL)
            break
        if process.poll() is not None:
            raise Failed("the bake ended (exit %s) before checkpoint %d: make tests/checkpoint/bake.json longer"
                         % (process.returncode, frame))
        time.sleep(0.0005)
    process.wait()
    if process.returncode != -signal.SIGKILL:
        raise Failed("expected the bake to die of SIGKILL, got exit %s" % process.returncode)
    return checkpoints(folder)[-1]


def output_files(folder):
    """Every output file below folder (relative), without checkpoints and the temporaries
    (.NAME.tmp-PID) that a killed bake leaves behind."""
    found = []
    for root, dirs, names in os.walk(folder):
        dirs[:] = [d for d in dirs if os.path.relpath(os.path.join(root, d), folder) != "checkpoints"]
        found += [os.path.relpath(os.path.join(root, n), folder) for n in names if ".tmp-" not in n]
    return sorted(found)


def same_outputs(reference, resumed):
    """Raises Failed unless both folders hold the same files with the same bytes."""
    if output_files(reference) != output_files(resumed):
        raise Failed("different files: %s vs %s" % (output_files(reference), output_files(resumed)))
    for name in output_files(reference):
        a, b = os.path.join(reference, name), os.path.join(resumed, name)
        if name.endswith(".h5"):  # h5diff first, to name what differs
            for extra in (["/frames/positions"], []):
                diff = subprocess.run(["h5diff", a, b, *extra], capture_output=True, text=True)
                if diff.returncode != 0:
                    raise Failed("h5diff %s %s %s: %s" % (a, b, " ".join(extra), diff.stdout[-2000:]))
        if not filecmp.cmp(a, b, shallow=False):
            raise Failed("%s differs" % name)
    return len(output_files(reference))


def expect_refusal(done, words):
    if done.returncode != 2 or words not in done.stderr:
        raise Failed("expected exit 2 saying '%s', got exit %d: %s" % (words, done.returncode, done.stderr))


def main():
    treeanim = sys.argv[1]
    work = tempfile.mkdtemp(prefix="treeanim-kill-resume-")
    try:
        reference, out = os.path.join(work, "reference"), os.path.join(work, "resumed")
        done = run(treeanim, reference, "--threads", "1")
        if done.returncode != 0:
            raise Failed("reference bake: exit %d: %s" % (done.returncode, done.stderr))

        # The job's first launch passes --resume too: nothing to resume, it bakes from the start.
        fresh = os.path.join(work, "fresh")
        done = run(treeanim, fresh, "--resume", "--frames", "0:5")
        if done.returncode != 0 or "no usable checkpoint" not in done.stderr:
            raise Failed("--resume without checkpoints: exit %d: %s" % (done.returncode, done.stderr))

        first_kill = kill_after_checkpoint(treeanim, out, 100, "--threads", "2")
        second_kill = kill_after_checkpoint(treeanim, out, 200, "--threads", "1", "--resume")
        done = run(treeanim, out, "--checkpoint-every", str(EVERY), "--resume")
        if done.returncode != 0 or "resuming at frame %d" % second_kill not in done.stderr:
            raise Failed("resume: exit %d: %s" % (done.returncode, done.stderr))
        files = same_outputs(reference, out)
        print("killed with SIGKILL after checkpoints %d and %d; resumed: %d files identical to the "
              "uninterrupted bake (h5diff /frames/positions: no differences)" % (first_kill, second_kill, files))

        # --frames A:B starts from the newest checkpoint at or before A.
        part, part_reference = os.path.join(work, "part"), os.path.join(work, "part-reference")
        done = run(treeanim, part, "--frames", "155:170", "--checkpoint-dir", os.path.join(out, "checkpoints"))
        if done.returncode != 0 or "resuming at frame 150" not in done.stderr:
            raise Failed("--frames 155:170: exit %d: %s" % (done.returncode, done.stderr))
        done = run(treeanim, part_reference, "--frames", "155:170")
        if done.returncode != 0:
            raise Failed("--frames 155:170 without checkpoints: exit %d: %s" % (done.returncode, done.stderr))
        same_outputs(part_reference, part)

        # Refusals: another scene, then a damaged checkpoint.
        expect_refusal(run(treeanim, out, "--resume", "--set", "seed=12"), "written for another scene or treeanim version")
        newest = os.path.join(out, "checkpoints", "checkpoint-%d.h5" % checkpoints(os.path.join(out, "checkpoints"))[-1])
        with open(newest, "r+b") as f:
            f.write(b"\0" * 64)
        expect_refusal(run(treeanim, out, "--resume"), "not a readable checkpoint")
        print("refused with exit 2: a checkpoint of another scene, a damaged checkpoint")
    except Failed as error:
        print("FAIL: %s" % error)
        return 1
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
