#!/usr/bin/python3
"""Failure injection for treeanim: hostile conditions around a real bake must give the
documented exit code and message and leave no file under a final name (and no temporaries).

usage: failure_injection.py TREEANIM SCENARIO     (exit 0 pass, 1 fail, 77 skipped)
Each scenario bakes tests/hardening/scenes/bake.json (a small tree written as hdf5, an obj
sequence, glb and pc2) from a fresh copy in a temporary folder. Works as root: an unwritable
output is a path below a regular file or in /proc, not a chmod that root ignores.
"""
import os
import re
import resource
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SKIP = 77


class Failed(Exception):
    pass


def files_under(folder):
    """folder => every file below it (relative paths); [] when the folder does not exist."""
    found = []
    for root, _, names in os.walk(folder):
        found += [os.path.relpath(os.path.join(root, n), folder) for n in names]
    return sorted(found)


def expect(done, code, message, out):
    """A finished run => Failed unless it exited `code`, said `message` and left no file in out."""
    stderr = done.stderr if isinstance(done.stderr, str) else done.stderr.decode(errors="replace")
    problems = []
    if done.returncode != code:
        problems.append("exit %d, expected %d" % (done.returncode, code))
    if message not in stderr:
        problems.append("stderr lacks %r" % message)
    left = files_under(out)
    if left:
        problems.append("files left behind: %s" % left[:10])
    if problems:
        raise Failed("; ".join(problems) + "\nstderr: " + stderr.strip()[-2000:])


class Bake:
    """A fresh copy of the bake scene in a temporary folder; outputs go to <tmp>/out."""

    def __init__(self, binary, tmp):
        self.binary, self.tmp = binary, tmp
        for name in ("bake.json", "wind.csv"):
            shutil.copy(os.path.join(HERE, "scenes", name), tmp)
        self.scene = os.path.join(tmp, "bake.json")
        self.wind = os.path.join(tmp, "wind.csv")
        self.out = os.path.join(tmp, "out")
        self.cleanups = []  # run when the scenario ends (a mounted filesystem: unmounted)

    def args(self, frames, extra=(), out=None):
        return [self.binary, "run", self.scene, "-o", out or self.out, "--quiet",
                "--set", "time.frames=%d" % frames] + list(extra)

    def run(self, frames, extra=(), out=None, preexec=None, timeout=120):
        return subprocess.run(self.args(frames, extra, out), capture_output=True, text=True,
                              errors="replace", preexec_fn=preexec, timeout=timeout)

    def start(self, frames, extra=()):
        return subprocess.Popen(self.args(frames, extra), stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True, errors="replace")

    def wait_until_writing(self, process):
        """Returns once the bake has staged its temporaries and written some frames."""
        deadline = time.monotonic() + 60
        while not any(".tmp-" in f for f in files_under(self.out)):
            if process.poll() is not None:
                raise Failed("the bake ended before writing: " + process.communicate()[1])
            if time.monotonic() > deadline:
                raise Failed("no temporary file appeared within 60 s")
            time.sleep(0.02)
        time.sleep(0.3)
        if process.poll() is not None:
            raise Failed("the bake finished before it could be interrupted (raise its frames)")


# ---- scenarios: each takes a Bake and raises Failed (or returns SKIP) ------------------------

def output_below_a_file(bake):
    """-o names a folder below a regular file: mkdir fails with ENOTDIR, even for root."""
    blocker = os.path.join(bake.tmp, "not-a-folder")
    open(blocker, "w").close()
    out = os.path.join(blocker, "out")
    expect(bake.run(24, out=out), 4, "output failed: " + out, bake.out)


def output_in_proc(bake):
    """An absolute output path in /proc, where no one (root included) can create a file."""
    done = bake.run(24, ["--set", "outputs.0.path=/proc/treeanim-hardening.h5"])
    expect(done, 4, "output failed: /proc/treeanim-hardening.h5: cannot create a file in /proc", bake.out)
    if os.path.exists("/proc/treeanim-hardening.h5"):
        raise Failed("a file appeared in /proc")


def output_directory_in_the_way(bake):
    """A directory stands where the hdf5 file should go: bad input, and it stays an empty directory."""
    os.makedirs(os.path.join(bake.out, "bake.h5"))
    done = bake.run(24)
    expect(done, 2, "bake.h5 is a directory, left untouched", os.path.join(bake.out, "bake.h5"))
    if sorted(os.listdir(bake.out)) != ["bake.h5"]:
        raise Failed("the output folder holds more than the directory: %s" % os.listdir(bake.out))


def output_at_a_lock_or_the_checkpoints(bake):
    """An output at another's lock file (.bake.h5.lock), or at the checkpoints' (.checkpoints.lock):
    bad input naming both (it was baked, reported written, then unlinked as the lock was
    released); and checkpoints in a folder at an output's path: bad input before the bake (the
    whole bake ran, then failed to place the output)."""
    lock = os.path.join(bake.out, ".bake.h5.lock")
    expect(bake.run(24, ["--set", "outputs.1={\"format\": \"hdf5\", \"path\": \".bake.h5.lock\"}"]), 2,
           "/outputs/1/path: writes %s, the lock file of /outputs/0" % lock, bake.out)
    checkpoints = os.path.join(bake.out, "checkpoints")
    expect(bake.run(24, ["--set", "outputs.1.path=.checkpoints.lock", "--set", "outputs.1.format=hdf5",
                         "--checkpoint-every", "4"]), 2,
           "/outputs/1/path: writes %s.lock, the lock file of the checkpoints" % os.path.join(bake.out, ".checkpoints"),
           bake.out)
    output = os.path.join(bake.out, "bake.h5")
    expect(bake.run(24, ["--checkpoint-every", "4", "--checkpoint-dir", output]), 2,
           "/outputs/0/path: writes %s, the folder of the checkpoints" % output, bake.out)


def output_at_an_input(bake):
    """An output at the scene file, at its wind file through a link, or at a grammar it includes:
    bad input, each input left as it was (the scene was overwritten with the HDF5 and exit 0)."""
    with open(os.path.join(bake.tmp, "part.lsys"), "w") as f:
        f.write("B --> F\n")
    with open(os.path.join(bake.tmp, "tree.lsys"), "w") as f:
        f.write("derivation length: 2\naxiom: A\nA --> FA[+B]\n#include \"part.lsys\"\n")
    os.symlink(bake.wind, os.path.join(bake.tmp, "wind.h5"))
    inputs = {path: open(path, "rb").read() for path in (bake.scene, bake.wind, os.path.join(bake.tmp, "part.lsys"))}
    expect(bake.run(12, ["--set", "outputs.0.path=" + bake.scene]), 2,
           "/outputs/0/path: writes %s, which is an input of this bake, left untouched" % bake.scene, bake.out)
    expect(bake.run(12, ["--set", "outputs.0.path=../wind.h5"]), 2,
           "which is %s, an input of this bake, left untouched" % bake.wind, bake.out)
    grammar = ["--set", "lsystem={\"grammar\": \"tree.lsys\"}"]
    expect(bake.run(12, grammar + ["--set", "outputs.2.path=../part.lsys"]), 2,
           "an input of this bake, left untouched", bake.out)
    for path, content in inputs.items():
        if open(path, "rb").read() != content:
            raise Failed(path + " was changed")


def output_through_folder_links(bake):
    """Two outputs that reach the same files through a linked folder, and an output in the
    checkpoints' folder named "." or through a link: bad input before the bake, and the old
    files stay (the bake ran, replaced some of them, then failed with exit 4; or wrote its output
    among the checkpoints)."""
    real = os.path.join(bake.out, "real")
    os.makedirs(real)
    os.symlink("real", os.path.join(bake.out, "link"))
    old = {}
    for name in ("t.pc2", "t.rest.obj", "t.rest.mtl"):
        old[name] = os.path.join(real, name)
        with open(old[name], "w") as f:
            f.write("an old bake")
    twice = "outputs=[{\"format\": \"pc2\", \"path\": \"real/t\"}, {\"format\": \"pc2\", \"path\": \"link/t\"}]"
    done = bake.run(12, ["--set", twice])
    if done.returncode != 2 or "which /outputs/0 writes too" not in done.stderr:
        raise Failed("two outputs through a linked folder: exit %d: %s" % (done.returncode, done.stderr))
    for path in old.values():
        if open(path).read() != "an old bake":
            raise Failed(path + " was replaced")
    os.symlink("real", os.path.join(bake.out, "checkpoints"))
    # The checkpoints in real/ as "real/." and as the link checkpoints/, the output in real/.
    for checkpoints, out, path in ((os.path.join(real, "."), real, "x.h5"),
                                   (os.path.join(bake.out, "checkpoints"), bake.out, "real/x.h5")):
        done = bake.run(12, ["--set", "outputs=[{\"format\": \"hdf5\", \"path\": \"%s\"}]" % path,
                             "--checkpoint-every", "4", "--checkpoint-dir", checkpoints], out=out)
        if done.returncode != 2 or "in the folder of the checkpoints" not in done.stderr:
            raise Failed("checkpoints in %s: exit %d: %s" % (checkpoints, done.returncode, done.stderr))
    if sorted(os.listdir(real)) != sorted(old):
        raise Failed("the folder holds more than the old files: %s" % os.listdir(real))


def output_named_as_a_scratch(bake):
    """A USD layer's normals wait in a scratch file beside it; an output named after the layer
    plus ".normals" is another file (its temporary was the scratch: exit 4 after the bake, the
    layer already replaced)."""
    outputs = ("outputs=[{\"format\": \"usd\", \"path\": \"t.usda\", \"normals\": true}, "
               "{\"format\": \"hdf5\", \"path\": \"t.usda.normals\"}]")
    done = bake.run(12, ["--set", outputs])
    if done.returncode != 0:
        raise Failed("exit %d: %s" % (done.returncode, done.stderr))
    for name, start in (("t.usda", b"#usda 1.0"), ("t.usda.normals", b"\x89HDF\r\n\x1a\n")):
        with open(os.path.join(bake.out, name), "rb") as f:
            if not f.read(len(start)) == start:
                raise Failed(name + " does not hold its output")
    if sorted(files_under(bake.out)) != ["t.usda", "t.usda.normals"]:
        raise Failed("files left: %s" % files_under(bake.out))


def omp_threads_past_the_limit(bake):
    """OMP_NUM_THREADS past --threads' range (1 ... 1024): bad input naming it (libgomp crashed
    making 99999 threads: SIGSEGV); with --threads given, the variable is not read."""
    env = dict(os.environ, OMP_NUM_THREADS="99999")
    done = subprocess.run(bake.args(4), capture_output=True, text=True, env=env, timeout=120)
    expect(done, 2, "OMP_NUM_THREADS asks for 99999 threads: expected 1 ... 1024 threads, or a comma-separated list of them (or give run --threads N)", bake.out)
    done = subprocess.run(bake.args(4, ["--threads", "2"]), capture_output=True, text=True, env=env, timeout=120)
    if done.returncode != 0:
        raise Failed("with --threads 2: exit %d: %s" % (done.returncode, done.stderr[-2000:]))


def node_state(path):
    """What stands at path, without opening anything but a regular file: type, device, size, bytes."""
    info = os.lstat(path)
    content = None
    if stat.S_ISREG(info.st_mode):
        with open(path, "rb") as f:
            content = f.read()
    return (info.st_mode, info.st_rdev, info.st_size, content)


def tree_state(folder):
    """folder => {relative path: node_state} of everything below it."""
    found = {}
    for root, dirs, names in os.walk(folder):
        for name in dirs + names:
            path = os.path.join(root, name)
            found[os.path.relpath(path, folder)] = node_state(path)
    return found


# Every file the bake scene's outputs write (one frame of each sequence), plus the formats it
# does not list: a glTF sequence, an MDD cache, vertex animation textures and a skinned GLB.
WITH_GLTF = ["--set", "outputs.4={\"format\": \"gltf\", \"path\": \"gltf/tree\"}",
             "--set", "outputs.5={\"format\": \"mdd\", \"path\": \"cache/tree.mdd\"}",
             "--set", "outputs.6={\"format\": \"vat\", \"path\": \"vat/tree\"}",
             "--set", "outputs.7={\"format\": \"skinned_glb\", \"path\": \"skinned.glb\"}"]
TARGETS = ["bake.h5", "seq/tree.0005.obj", "seq/tree.rest.obj", "tree.glb", "tree.pc2", "tree.rest.obj",
           "gltf/tree.0003.glb", "cache/tree.mdd", "vat/tree.positions.exr", "vat/tree.glb", "skinned.glb"]


def output_not_a_regular_file(bake):
    """A character device (root only: mknod), a FIFO or a directory at any output's target: exit 2
    before simulating, naming the output and what stands there; the node is left as it was and
    nothing else is written. The FIFO must not be opened (that would block the bake)."""
    kinds = [("FIFO", lambda p: os.mkfifo(p)), ("directory", os.mkdir)]
    if os.geteuid() == 0:
        kinds.insert(0, ("character device", lambda p: os.mknod(p, 0o600 | stat.S_IFCHR, os.makedev(1, 3))))
    else:
        print("not root: no device node (mknod needs root); FIFOs and directories only")
    for target in TARGETS:
        for kind, make in kinds:
            shutil.rmtree(bake.out, ignore_errors=True)
            node = os.path.join(bake.out, target)
            os.makedirs(os.path.dirname(node))
            make(node)
            before = tree_state(bake.out)
            done = bake.run(12, WITH_GLTF, timeout=30)
            stderr = done.stderr
            problems = []
            if done.returncode != 2:
                problems.append("exit %d, expected 2" % done.returncode)
            message = "%s is a %s, left untouched" % (node, kind)
            if message not in stderr:
                problems.append("stderr lacks %r" % message)
            if tree_state(bake.out) != before:
                problems.append("the output folder changed")
            if problems:
                raise Failed("%s at %s: %s\nstderr: %s" % (kind, target, "; ".join(problems), stderr.strip()[-1000:]))
    return 0


def output_symbolic_links_followed(bake):
    """A symbolic link at a target is followed, as cp does: the file it names gets the bake (a
    dangling link creates it) and the link stays a link; no temporary is left on either side."""
    store = os.path.join(bake.tmp, "store")
    os.makedirs(store)
    os.makedirs(bake.out)
    with open(os.path.join(store, "old.h5"), "w") as f:
        f.write("an old bake")
    os.symlink(os.path.join(store, "old.h5"), os.path.join(bake.out, "bake.h5"))
    os.symlink("../store/new.glb", os.path.join(bake.out, "tree.glb"))  # dangling, relative
    done = bake.run(12)
    if done.returncode != 0:
        raise Failed("exit %d: %s" % (done.returncode, done.stderr))
    for link in ("bake.h5", "tree.glb"):
        if not os.path.islink(os.path.join(bake.out, link)):
            raise Failed(link + " is no longer a symbolic link")
    with open(os.path.join(store, "old.h5"), "rb") as f:
        if f.read(8) != b"\x89HDF\r\n\x1a\n":
            raise Failed("the linked file does not hold the HDF5 bake")
    with open(os.path.join(store, "new.glb"), "rb") as f:
        if f.read(4) != b"glTF":
            raise Failed("the dangling link's file was not created with the GLB")
    left = [f for f in files_under(bake.tmp) if ".tmp-" in f]
    if left:
        raise Failed("temporaries left: %s" % left)


def bad_scene_keeps_previous_bake(edit, message):
    """edit(bake) makes the scene bad input => a scenario: over a finished bake, the bad scene
    exits 2 with `message` and every file of the previous bake stays byte for byte."""
    def scenario(bake):
        first = bake.run(12)
        if first.returncode != 0:
            raise Failed("the first bake failed: " + first.stderr)
        before = tree_state(bake.out)
        extra = edit(bake)
        done = bake.run(12, extra)
        problems = []
        if done.returncode != 2:
            problems.append("exit %d, expected 2" % done.returncode)
        if message not in done.stderr:
            problems.append("stderr lacks %r" % message)
        if tree_state(bake.out) != before:
            problems.append("the previous bake changed")
        if problems:
            raise Failed("; ".join(problems) + "\nstderr: " + done.stderr.strip()[-1000:])
    return scenario


def nest_scene_deeply(bake):
    """50,000 levels in the scene file (a stack overflow before the depth limit) => no --set."""
    with open(bake.scene) as f:
        text = f.read()
    with open(bake.scene, "w") as f:
        f.write(text.replace('"wind":', '"tree": %s%s,\n  "wind":' % ("[" * 50000, "]" * 50000), 1))
    return []


def nest_set_deeply(bake):
    """50,000 levels in a --set value."""
    return ["--set", "tree=" + "[" * 50000 + "]" * 50000]


def repeat_a_key(bake):
    """The scene's "time" given twice, as a hand edit or a merge leaves it."""
    with open(bake.scene) as f:
        text = f.read()
    with open(bake.scene, "w") as f:
        f.write(text.replace('"outputs":', '"time": {"fps": 30},\n  "outputs":', 1))
    return []


def output_read_only_folder(bake):
    """A folder without write permission (only meaningful when not root)."""
    if os.geteuid() == 0:
        print("skipped: root ignores folder permissions (output_below_a_file covers this as root)")
        return SKIP
    os.makedirs(bake.out)
    os.chmod(bake.out, 0o555)
    expect(bake.run(24), 4, "output failed: ", bake.out)


def resume_from_a_read_only_folder(bake):
    """--resume where the checkpoints' folder may not be written (a read-only bind mount as
    root, its permissions otherwise): exit 4 naming the journal, before any output, rather than
    bake every frame again from the start."""
    checkpoints = os.path.join(bake.tmp, "checkpoints")
    first = bake.run(60, ["--checkpoint-every", "10", "--checkpoint-dir", checkpoints, "--frames", "0:30"])
    if first.returncode != 0:
        raise Failed("the first part: exit %d: %s" % (first.returncode, first.stderr))
    shutil.rmtree(bake.out)
    if os.geteuid() == 0:
        if subprocess.run(["mount", "--bind", checkpoints, checkpoints], capture_output=True).returncode:
            print("skipped: bind mounts are not permitted here, and root ignores folder permissions")
            return SKIP
        bake.cleanups.append(lambda: subprocess.run(["umount", "-l", checkpoints]))
        if subprocess.run(["mount", "-o", "remount,ro,bind", checkpoints], capture_output=True).returncode:
            print("skipped: a bind mount cannot be made read-only here")
            return SKIP
    else:
        os.chmod(checkpoints, 0o555)
    for extra in ([], ["--checkpoint-every", "10"]):
        expect(bake.run(60, extra + ["--checkpoint-dir", checkpoints, "--resume"]), 4,
               "frames-from-0.journal: cannot open the frame journal to continue it", bake.out)


def limit_file_size(ignore_sigxfsz, kib=100):
    """=> preexec function: a file-size limit (KiB), as a full disk or a quota gives."""
    def preexec():
        if ignore_sigxfsz:
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (kib * 1024, kib * 1024))
    return preexec


def disk_full(bake):
    """`ulimit -f` as a shell sets it (SIGXFSZ at its default, which kills): writes past the
    limit must fail with exit 4, not kill the bake and strand its temporaries."""
    done = bake.run(2000, preexec=limit_file_size(False))
    expect(done, 4, "output failed: ", bake.out)
    if "File too large" not in done.stderr:
        raise Failed("the message does not name the cause: " + done.stderr)


def disk_full_efbig(bake):
    """A write that fails with an error (SIGXFSZ ignored, as with ENOSPC): exit 4 naming the file."""
    done = bake.run(2000, preexec=limit_file_size(True))
    expect(done, 4, "write failed: File too large", bake.out)


def disk_full_gltf(bake):
    """The glTF writers (a sequence, the skinned GLB, the VAT's mesh), each alone past a 4 KiB
    limit: exit 4 naming the cause, no file cut short (tinygltf's own file writer reports no
    failed write)."""
    for output in ('{"format": "gltf", "path": "seq/tree"}', '{"format": "skinned_glb", "path": "skin.glb"}',
                   '{"format": "vat", "path": "vat/tree"}'):
        done = bake.run(24, ["--set", "outputs=[%s]" % output], preexec=limit_file_size(True, 4))
        try:
            expect(done, 4, "write failed: File too large", bake.out)
        except Failed as failure:
            raise Failed("%s: %s" % (output, failure))


def interrupted(signal_number, code, name):
    def scenario(bake):
        """A signal in the middle of a bake: the documented code, and no output at all."""
        process = bake.start(30000)  # under the GLB limit of 31898 frames
        bake.wait_until_writing(process)
        process.send_signal(signal_number)
        try:
            _, stderr = process.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            process.kill()
            raise Failed("the bake did not stop within 60 s of " + name)
        done = subprocess.CompletedProcess(process.args, process.returncode, "", stderr)
        expect(done, code, "interrupted by " + name, bake.out)
    return scenario


def interrupted_while_growing(bake):
    """SIGTERM while an L-system derives for minutes (a binary tree of 40 steps, stopped only by
    max_modules): the bake stops at once, 143, before it opened anything (no out/ at all)."""
    grow = ["--set", "lsystem={\"axiom\": \"A\", \"productions\": [\"A --> [+A][-A]FA\"], \"iterations\": 40, "
            "\"max_modules\": 500000000}"]
    process = bake.start(3, grow)
    time.sleep(1.0)
    if process.poll() is not None:
        raise Failed("the derivation ended within a second: %s" % process.communicate()[1][-2000:])
    process.send_signal(signal.SIGTERM)
    try:
        _, stderr = process.communicate(timeout=5)
    except subprocess.TimeoutExpired:
        process.kill()
        raise Failed("the growing bake did not stop within 5 s of SIGTERM")
    expect(subprocess.CompletedProcess(process.args, process.returncode, "", stderr), 143,
           "interrupted by SIGTERM while no output was open; none was left half-written", bake.out)
    if os.path.exists(bake.out):
        raise Failed("the output folder was made: %s" % folders_under(bake.out))


def growth_reports_progress(bake):
    """A derivation that runs for seconds says how far it is ("growing: step S of N, M modules")
    while no frame has begun, in a bake and in validate; both were silent until the tree was grown."""
    grow = "{\"axiom\": \"A(0)\", \"productions\": [\"A(n) : n < 20 --> A(n+1)A(n+1)\", " \
           "\"A(n) : n >= 20 --> A(n)\"], \"iterations\": 120, \"max_modules\": 2000000}"
    for command in (["run", bake.scene, "-o", bake.out, "--set", "time.frames=2"], ["validate", bake.scene]):
        done = subprocess.run([bake.binary, *command, "--set", "lsystem=" + grow], capture_output=True, text=True,
                              errors="replace", timeout=600)
        if not re.search(r"growing: step \d+ of 120, 1048576 modules", done.stderr):
            raise Failed("%s: no growth progress in: %s" % (command[0], done.stderr[-2000:]))


def folders_under(folder):
    """folder => every folder below it, itself included (relative paths); [] when absent."""
    return sorted(os.path.relpath(root, folder) for root, _, _ in os.walk(folder))


def interrupted_removes_made_folders(bake):
    """SIGTERM during a bake into folders it made (-o out, the OBJ sequence's seq/): exit 143 and
    those folders gone; folders that stood before (out/kept, empty) stay."""
    process = bake.start(30000)
    bake.wait_until_writing(process)
    process.send_signal(signal.SIGTERM)
    _, stderr = process.communicate(timeout=60)
    expect(subprocess.CompletedProcess(process.args, process.returncode, "", stderr), 143, "interrupted by SIGTERM",
           bake.out)
    if os.path.exists(bake.out):
        raise Failed("folders the bake made are left: %s" % folders_under(bake.out))
    os.makedirs(os.path.join(bake.out, "kept"))
    os.makedirs(os.path.join(bake.out, "seq"))
    process = bake.start(30000, ["--set", "outputs.1.path=seq/new/tree.%04d.obj"])
    bake.wait_until_writing(process)
    process.send_signal(signal.SIGTERM)
    _, stderr = process.communicate(timeout=60)
    if process.returncode != 143 or folders_under(bake.out) != [".", "kept", "seq"]:
        raise Failed("exit %d, folders %s; expected 143 and the folders that stood before: %s"
                     % (process.returncode, folders_under(bake.out), stderr))


def wind_file_deleted(bake):
    """The wind file is gone when the bake starts: bad input (2) naming /wind/file."""
    os.remove(bake.wind)
    expect(bake.run(24), 2, "/wind/file: cannot open wind file '%s'" % bake.wind, bake.out)


def wind_file_truncated(bake):
    """The wind file was cut in the middle of a line (a copy that did not finish): file:line."""
    with open(bake.wind, "rb") as f:
        text = f.read()
    with open(bake.wind, "wb") as f:
        f.write(text[: text.rindex(b",")])
    expect(bake.run(24), 2, "%s:4: expected 6 comma-separated values, got 5" % bake.wind, bake.out)


def wind_file_deleted_mid_bake(bake):
    """The wind is read once when the scene loads: deleting the file during the bake changes
    nothing, and the bake completes (every output under its final name, no temporaries)."""
    process = bake.start(3000)
    bake.wait_until_writing(process)
    os.remove(bake.wind)
    _, stderr = process.communicate(timeout=300)
    if process.returncode != 0:
        raise Failed("exit %d: %s" % (process.returncode, stderr))
    left = files_under(bake.out)
    if any(".tmp-" in f for f in left) or "bake.h5" not in left:
        raise Failed("unexpected outputs: %s" % left[:10])


def module_cap_under_ulimit_v(bake):
    """A grammar that doubles every step stops at the default module cap (20 million) with a
    clear message, within a 4 GB address-space limit (ulimit -v 4000000), not an OOM kill."""
    if asan_binary(bake.binary):
        print("skipped: AddressSanitizer reserves terabytes of address space; ulimit -v cannot apply")
        return SKIP
    done = bake.run(24, ["--set", "lsystem.productions=[\"A(x) --> A(x)A(x)\"]",
                         "--set", "lsystem.iterations=40"], preexec=limit_address_space, timeout=300)
    expect(done, 2, "reached 20000002 modules, more than lsystem.max_modules = 20000000", bake.out)


def glb_too_large(bake):
    """A GLB cannot exceed 4 GiB: a bake whose animated GLB would (100000 frames of 563
    vertices, about 31900 fit) is refused before simulating, naming the limit and what fits."""
    done = bake.run(100000, timeout=120)
    expect(done, 2, "over glTF's 4 GiB GLB limit; at most ", bake.out)


def glb_far_too_large_under_ulimit_v(bake):
    """The largest bake a scene may ask for (time.frames = 10 million) is refused the same way
    within 4 GB of address space: the size check itself must not need memory per frame."""
    if asan_binary(bake.binary):
        print("skipped: AddressSanitizer reserves terabytes of address space; ulimit -v cannot apply")
        return SKIP
    done = bake.run(10000000, ["--set", "outputs=[{\"format\": \"glb\", \"path\": \"tree.glb\"}]"],
                    preexec=limit_address_space, timeout=120)
    expect(done, 2, "over glTF's 4 GiB GLB limit", bake.out)


def second_writer_refused(bake):
    """A second bake of the same outputs while the first writes: exit 4 at once naming the
    first's process, nothing of the first touched; the first completes, and leaves no lock file."""
    first = bake.start(3000)
    bake.wait_until_writing(first)
    began = time.monotonic()
    second = bake.run(3000)
    seconds = time.monotonic() - began
    if second.returncode != 4 or "another bake is writing this output (process %d, lock " % first.pid not in second.stderr:
        first.kill()
        raise Failed("the second bake: exit %d: %s" % (second.returncode, second.stderr))
    if seconds > 5:
        first.kill()
        raise Failed("the refusal took %.1f s: it must come before simulating" % seconds)
    _, stderr = first.communicate(timeout=300)
    if first.returncode != 0:
        raise Failed("the first bake: exit %d: %s" % (first.returncode, stderr))
    left = files_under(bake.out)
    if "bake.h5" not in left or any(".lock" in f or ".tmp-" in f for f in left):
        raise Failed("unexpected files after the first bake: %s" % [f for f in left if "seq/" not in f])


def directory_appears_mid_bake(bake):
    """A folder made at the last output's path while the bake writes: exit 4 naming it, and no
    output renamed into place, those before it included."""
    process = bake.start(3000)
    bake.wait_until_writing(process)
    os.makedirs(os.path.join(bake.out, "tree.pc2"))
    _, stderr = process.communicate(timeout=300)
    done = subprocess.CompletedProcess(process.args, process.returncode, "", stderr)
    expect(done, 4, "tree.pc2: a directory appeared at the output path during the bake", bake.out)


def fifo_in_the_checkpoints(bake):
    """A FIFO in place of the newest checkpoint, then of the frame journal: --resume refuses
    it (exit 2, then 4) instead of blocking in its open for a writer that never comes."""
    extra = ["--checkpoint-every", "10", "--resume"]
    done = bake.run(40, extra)
    if done.returncode != 0:
        raise Failed("the first bake: exit %d: %s" % (done.returncode, done.stderr))
    folder = os.path.join(bake.out, "checkpoints")
    for name, code, message in (("checkpoint-30.h5", 2, "checkpoint-30.h5: not a readable checkpoint: not a regular file"),
                                ("frames-from-0.journal", 4, "a FIFO stands where the bake writes its frame journal")):
        os.remove(os.path.join(folder, name))
        os.mkfifo(os.path.join(folder, name))
        try:
            done = bake.run(40, extra, timeout=60)
        except subprocess.TimeoutExpired:
            raise Failed("--resume blocked on a FIFO at %s" % name)
        if done.returncode != code or message not in done.stderr:
            raise Failed("%s: exit %d: %s" % (name, done.returncode, done.stderr))
        if name.endswith(".h5"):
            os.remove(os.path.join(folder, name))


def journal_bit_flipped(bake):
    """A bit flipped in a record of the frame journal: --resume refuses it (exit 2 naming the
    record) rather than replay it into the outputs, which stay as they were."""
    extra = ["--checkpoint-every", "10", "--resume"]
    done = bake.run(40, extra)
    if done.returncode != 0:
        raise Failed("the first bake: exit %d: %s" % (done.returncode, done.stderr))
    before = open(os.path.join(bake.out, "bake.h5"), "rb").read()
    journal = os.path.join(bake.out, "checkpoints", "frames-from-0.journal")
    with open(journal, "r+b") as f:
        record = int.from_bytes(f.read(16)[8:], "little")
        f.seek(96 + 5 * record + 16 + 7)  # a position's top byte
        byte = f.read(1)[0]
        f.seek(-1, os.SEEK_CUR)
        f.write(bytes([byte ^ 0x40]))
    done = bake.run(40, extra)
    if done.returncode != 2 or "record 5 of the frame journal is damaged" not in done.stderr:
        raise Failed("exit %d: %s" % (done.returncode, done.stderr))
    if open(os.path.join(bake.out, "bake.h5"), "rb").read() != before:
        raise Failed("the refused resume changed bake.h5")


def second_writer_of_an_alias_refused(bake):
    """A second bake whose outputs name the first's files another way (a link to its HDF5, its
    OBJ sequence without the frame field): refused, exit 4, as a second bake of the same paths."""
    first = bake.start(3000)
    bake.wait_until_writing(first)
    os.symlink("bake.h5", os.path.join(bake.out, "alias.h5"))
    try:
        for output in ('{"format": "hdf5", "path": "alias.h5"}', '{"format": "obj", "path": "seq/tree"}'):
            second = bake.run(20, ["--set", "outputs=[%s]" % output])
            if second.returncode != 4 or "another bake is writing this output (process %d, lock " % first.pid not in second.stderr:
                raise Failed("%s: exit %d: %s" % (output, second.returncode, second.stderr))
    finally:
        first.kill()
        first.communicate()


def second_bake_of_the_checkpoints_refused(bake):
    """A second bake, of other outputs, given the first's checkpoint folder: refused (exit 4)
    before it reads or clears anything there; the first's checkpoints stay."""
    first = bake.start(3000, ["--checkpoint-every", "100"])
    bake.wait_until_writing(first)
    try:
        folder = os.path.join(bake.out, "checkpoints")
        before = sorted(n for n in os.listdir(folder) if not n.startswith("."))  # not the temporaries
        second = bake.run(20, ["--checkpoint-every", "5", "--checkpoint-dir", folder], out=os.path.join(bake.tmp, "other"))
        if second.returncode != 4 or "another bake is writing this output (process %d, lock " % first.pid not in second.stderr:
            raise Failed("exit %d: %s" % (second.returncode, second.stderr))
        if any(name not in os.listdir(folder) for name in before):
            raise Failed("the refused bake removed %s" % [n for n in before if n not in os.listdir(folder)])
    finally:
        first.kill()
        first.communicate()


def reader_gone(bake):
    """Progress and messages to a pipe whose reader has gone (`| head`): the bake goes on to
    exit 0 with every output whole, not killed by SIGPIPE with its temporaries and locks left."""
    read, write = os.pipe()
    os.close(read)
    try:
        args = [a for a in bake.args(200) if a != "--quiet"] + ["--verbose"]
        done = subprocess.run(args, stdout=write, stderr=write, timeout=120)
    finally:
        os.close(write)
    left = files_under(bake.out)
    if done.returncode != 0 or "bake.h5" not in left or any(".lock" in f or ".tmp-" in f for f in left):
        raise Failed("exit %d; files: %s" % (done.returncode, [f for f in left if "seq/" not in f]))


def stdout_full(bake):
    """What info, species and farm plan make is their standard output: written to a full device
    (`info --json > meta.json` on a full disk), exit 4 saying so, never 0 with an empty file."""
    commands = [["info", bake.scene, "--json"], ["info", bake.scene, "--resolved-scene"], ["species", "--json"],
                ["farm", "plan", os.path.join(HERE, "..", "..", "configs", "forest-demo.json"), "--tasks", "2"]]
    for command in commands:
        with open("/dev/full", "w") as full:
            done = subprocess.run([bake.binary, *command], stdout=full, stderr=subprocess.PIPE, text=True, timeout=120)
        if done.returncode != 4 or "standard output: the command's output could not be written whole" not in done.stderr:
            raise Failed("%s > /dev/full: exit %d, %s" % (" ".join(command), done.returncode, done.stderr[-500:]))


def resume_after_kill_not_blocked(bake):
    """A bake killed with SIGKILL holds no lock any more: its --resume bakes to the end, reusing
    and then removing the lock files it left."""
    extra = ["--checkpoint-every", "100", "--resume"]
    first = bake.start(3000, extra)
    bake.wait_until_writing(first)
    first.kill()
    first.communicate()
    if not any(f.endswith(".lock") for f in files_under(bake.out)):
        raise Failed("no lock file was left by the killed bake: the scenario tests nothing")
    done = bake.run(3000, extra, timeout=300)
    if done.returncode != 0:
        raise Failed("the resumed bake: exit %d: %s" % (done.returncode, done.stderr))
    left = files_under(bake.out)  # the killed bake's temporaries stay (docs/outputs.md)
    if "bake.h5" not in left or any(f.endswith(".lock") for f in left):
        raise Failed("unexpected files after the resumed bake: %s" % [f for f in left if "seq/" not in f])


def small_filesystem(bake):
    """=> a 4 MiB tmpfs mounted at <tmp>/small (unmounted when the scenario's folder goes), or
    None where mounting is not permitted."""
    folder = os.path.join(bake.tmp, "small")
    os.makedirs(folder)
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=4m", "tmpfs", folder], capture_output=True).returncode:
        return None
    bake.cleanups.append(lambda: subprocess.run(["umount", "-l", folder]))
    return folder


def no_room_for_the_outputs(bake):
    """Outputs estimated past the free space of their filesystem (~200 MB for 3000 frames on a
    4 MiB tmpfs): exit 4 before simulating, naming the path, what is needed and what is free."""
    out = small_filesystem(bake)
    if out is None:
        print("skipped: mounting a tmpfs is not permitted here")
        return SKIP
    began = time.monotonic()
    done = bake.run(3000, out=os.path.join(out, "out"))
    seconds = time.monotonic() - began
    expect(done, 4, "output failed: %s/out/bake.h5: not enough free space: the bake needs " % out, out)
    if not re.search(r"needs [0-9.]+ MB on its filesystem, [0-9.]+ MB free", done.stderr):
        raise Failed("the message lacks what is needed and what is free: " + done.stderr)
    if seconds > 5:
        raise Failed("the refusal took %.1f s: it must come before simulating" % seconds)
    # Without the estimate the bake starts and meets the full disk while writing.
    expect(bake.run(3000, ["--no-space-check"], out=os.path.join(out, "out")), 4,
           "write failed: No space left on device", out)


def no_room_for_the_forest(bake):
    """farm submit estimates the whole forest against its output folder's free space; with
    --no-space-check it writes the script, whose tasks skip their own estimate too."""
    out = small_filesystem(bake)
    if out is None:
        print("skipped: mounting a tmpfs is not permitted here")
        return SKIP
    scene = os.path.join(HERE, "..", "..", "configs", "forest-demo.json")
    done = subprocess.run([bake.binary, "farm", "submit", scene, "--tasks", "2", "--engine", "script", "-o", out],
                          capture_output=True, text=True)
    expect(done, 4, "%s/forest.json: not enough free space: the bake needs " % out, out)
    done = subprocess.run([bake.binary, "farm", "submit", scene, "--tasks", "2", "--engine", "script", "-o", out,
                           "--no-space-check"], capture_output=True, text=True)
    with open(os.path.join(out, "farm", "forest-demo.sh")) as f:
        script = f.read()
    if done.returncode != 0 or script.count(" --no-space-check") != 1:
        raise Failed("--no-space-check: exit %d, the tasks %s the flag: %s"
                     % (done.returncode, "lack" if " --no-space-check" not in script else "repeat", done.stderr))


def limit_address_space():
    """preexec: ulimit -v 4000000 (KiB), a render-farm node's share of memory."""
    limit = 4000000 * 1024
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))


def asan_binary(path):
    """True when the binary was built with AddressSanitizer."""
    with open(path, "rb") as f:
        return b"__asan_init" in f.read()


SCENARIOS = {
    "output-below-a-file": output_below_a_file,
    "output-in-proc": output_in_proc,
    "output-directory-in-the-way": output_directory_in_the_way,
    "output-at-a-lock-or-the-checkpoints": output_at_a_lock_or_the_checkpoints,
    "omp-threads-past-the-limit": omp_threads_past_the_limit,
    "output-at-an-input": output_at_an_input,
    "output-through-folder-links": output_through_folder_links,
    "output-named-as-a-scratch": output_named_as_a_scratch,
    "output-read-only-folder": output_read_only_folder,
    "resume-from-a-read-only-folder": resume_from_a_read_only_folder,
    "output-not-a-regular-file": output_not_a_regular_file,
    "output-symbolic-links-followed": output_symbolic_links_followed,
    "deep-scene-keeps-previous-bake": bad_scene_keeps_previous_bake(
        nest_scene_deeply, "bake.json:4:266: JSON nested deeper than 256 levels of arrays and objects"),
    "deep-set-keeps-previous-bake": bad_scene_keeps_previous_bake(
        nest_set_deeply, ":1:256: JSON nested deeper than 256 levels of arrays and objects"),
    "repeated-key-keeps-previous-bake": bad_scene_keeps_previous_bake(
        repeat_a_key, "bake.json:6:3: /time: duplicate key (first at line 5, again at line 6)"),
    "disk-full": disk_full,
    "disk-full-efbig": disk_full_efbig,
    "disk-full-gltf": disk_full_gltf,
    "sigint": interrupted(signal.SIGINT, 130, "SIGINT"),
    "sigterm": interrupted(signal.SIGTERM, 143, "SIGTERM"),
    "sighup": interrupted(signal.SIGHUP, 129, "SIGHUP"),  # a terminal closed under the bake
    "interrupted-removes-made-folders": interrupted_removes_made_folders,
    "interrupted-while-growing": interrupted_while_growing,
    "growth-reports-progress": growth_reports_progress,
    "wind-file-deleted": wind_file_deleted,
    "wind-file-truncated": wind_file_truncated,
    "wind-file-deleted-mid-bake": wind_file_deleted_mid_bake,
    "module-cap-under-ulimit-v": module_cap_under_ulimit_v,
    "glb-too-large": glb_too_large,
    "glb-far-too-large-under-ulimit-v": glb_far_too_large_under_ulimit_v,
    "no-room-for-the-outputs": no_room_for_the_outputs,
    "second-writer-refused": second_writer_refused,
    "reader-gone": reader_gone,
    "stdout-full": stdout_full,
    "second-bake-of-the-checkpoints-refused": second_bake_of_the_checkpoints_refused,
    "second-writer-of-an-alias-refused": second_writer_of_an_alias_refused,
    "journal-bit-flipped": journal_bit_flipped,
    "fifo-in-the-checkpoints": fifo_in_the_checkpoints,
    "directory-appears-mid-bake": directory_appears_mid_bake,
    "resume-after-kill-not-blocked": resume_after_kill_not_blocked,
    "no-room-for-the-forest": no_room_for_the_forest,
}


# Scenarios that reproduce an open defect (reported to the stage owner): tests/hardening.cmake
# registers them DISABLED, so ctest lists them as "Not Run (Disabled)" until the fix lands.
OPEN_DEFECTS = {}


def main():
    binary, name = os.path.abspath(sys.argv[1]), sys.argv[2]
    if name == "--list":  # "name" or "name defect", one scenario a line
        print("\n".join(n + (" defect" if n in OPEN_DEFECTS else "") for n in SCENARIOS))
        return 0
    with tempfile.TemporaryDirectory(prefix="treeanim-fi-") as tmp:
        bake = Bake(binary, tmp)
        try:
            result = SCENARIOS[name](bake)
        except Failed as failure:
            print("FAIL %s: %s" % (name, failure))
            return 1
        finally:
            for cleanup in bake.cleanups:
                cleanup()
    print("ok %s" % name)
    return result or 0


if __name__ == "__main__":
    sys.exit(main())
