#!/usr/bin/python3
"""Stress runner (tests/stress/README.md).

  run_stress.py --treeanim BIN case NAME...        cases of tests/stress/cases.json
  run_stress.py --treeanim BIN ctest-cases          every case marked "ctest"
  run_stress.py --treeanim BIN all-cases            every case
  run_stress.py --treeanim BIN random N [--seed S]  N scenes of scripts/stress-scenes
  run_stress.py --treeanim BIN determinism          /frames/positions bytes, OMP_NUM_THREADS 1, 2, 4, TREEANIM_ISA (double and float; and on the samples)

A bake passes when treeanim exits 0 and its HDF5 holds only finite positions with every
attached vertex closer to its rest position than 2.5 times the tree's size (the larger of the
rest mesh's extent and the tree's reach along its branches, as the solver's guard takes it). Exit 3 (the runaway guard) is a failure: the guard is a
safety net that no scene may trip. A random scene with physical stiffness is baked again at
64 substeps, and at its own step its branch vertices may move no farther than 1.25 x their
largest displacement there plus 5 % of the tree's extent (a coarse bake is less accurate,
never wilder). A soak case (a long bake written at its last frame) passes when the tree ends
at rest and its resident memory stays flat. Prints one line per case; exit 1 on any failure.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
# An attached vertex may move from rest less than this many times the tree's size: the
# solver's runaway guard (kRunawaySizes in src/sim/solver_model.h).
RUNAWAY_SIZES = 2.5
ROOT = os.path.dirname(os.path.dirname(HERE))


def treeanim(binary, scene, out_dir, sets, extra=(), threads=None, timeout=300, isa=None, blocks=None):
    """One `treeanim run` (isa: TREEANIM_ISA, the solver loops' instruction set; blocks:
    TREEANIM_BLOCKS, memberships per cache block of the step) => (exit code, stderr, seconds)."""
    args = [binary, "run", scene, "-o", out_dir, *(() if "--verbose" in extra else ("--quiet",)), *extra]
    for key, value in sets.items():
        args += ["--set", f"{key}={json.dumps(value)}"]
    env = dict(os.environ)
    if threads:
        env["OMP_NUM_THREADS"] = str(threads)
    if isa:
        env["TREEANIM_ISA"] = isa
    if blocks is not None:
        env["TREEANIM_BLOCKS"] = str(blocks)
    start = time.perf_counter()
    done = subprocess.run(args, env=env, capture_output=True, text=True, timeout=timeout)
    return done.returncode, done.stderr.strip(), time.perf_counter() - start


def branch_vertices(f):
    """Open bake => boolean mask of the vertices in no leaf cluster."""
    offsets, members, kind = f["/model/cluster_offsets"][()], f["/model/cluster_members"][()], f["/model/cluster_kind"][()]
    branch = np.ones(f["/mesh/rest_positions"].shape[0], dtype=bool)
    for c in np.nonzero(kind == 1)[0]:
        branch[members[offsets[c]:offsets[c + 1]]] = False
    return branch


def largest_branch_displacement(path):
    """Bake => (per branch vertex, its largest displacement from rest over all frames (m); tree size (m))."""
    with h5py.File(path, "r") as f:
        rest = f["/mesh/rest_positions"][()].astype(np.float64)
        branch = branch_vertices(f)
        positions = f["/frames/positions"]
        worst = np.zeros(int(branch.sum()))
        for k in range(positions.shape[0]):
            worst = np.maximum(worst, np.linalg.norm(positions[k][branch].astype(np.float64) - rest[branch], axis=1))
        return worst, float((rest.max(axis=0) - rest.min(axis=0)).max())


def exaggeration(binary, scene, out_dir, sets=None):
    """Baked random scene (with `sets`, the --set overrides it was baked with) => (passed, text):
    its branch vertices against the same scene at 64 substeps (skipped with per-step
    stiffness, which has no converged motion)."""
    with open(scene) as f:
        config = json.load(f)
    if config.get("hsm", {}).get("stiffness", "physical") != "physical":
        return True, "per_step stiffness: no reference"
    reference_dir = os.path.join(out_dir, "reference")
    os.makedirs(reference_dir)
    code, err, _ = treeanim(binary, scene, reference_dir, dict(sets or {}, **{"time.substeps": 64}))
    if code != 0:
        return False, f"the 64-substep reference failed: exit {code}: {err.splitlines()[-1] if err else ''}"
    own, size = largest_branch_displacement(os.path.join(out_dir, "out.h5"))
    converged, _ = largest_branch_displacement(os.path.join(reference_dir, "out.h5"))
    if not len(own):
        return True, "no branch vertices"
    text = f"branches at most {own.max():.3g} m (64 substeps: {converged.max():.3g} m, extent {size:.3g} m)"
    if own.max() > 1.25 * converged.max() + 0.05 * size:
        return False, "exaggerated: " + text
    return True, text


def tree_size(f):
    """Open bake => the tree's size as the solver's runaway guard takes it (m): the larger of the
    rest mesh's extent and its reach, the longest path from the root's joint to a vertex along
    the chain of cluster joints (a branch cluster's joint: its first segment's start; a leaf's:
    its vertex shared with its branch)."""
    rest = f["/mesh/rest_positions"][()].astype(np.float64)
    offsets, members, kind = f["/model/cluster_offsets"][()], f["/model/cluster_members"][()], f["/model/cluster_kind"][()]
    seg_cluster, seg_parent = f["/skeleton/segment_cluster"][()], f["/skeleton/segment_parent"][()]
    seg_start = f["/skeleton/segment_start"][()].astype(np.float64)
    C = len(kind)
    joint, parent, first = np.zeros((C, 3)), np.full(C, -1), {}
    for s in range(len(seg_cluster) - 1, -1, -1):
        first[int(seg_cluster[s])] = s
    branch_of = {}
    for c in range(C):
        if kind[c] == 0:
            for v in members[offsets[c]:offsets[c + 1]]:
                branch_of.setdefault(int(v), c)
    for c in range(C):
        m = members[offsets[c]:offsets[c + 1]]
        if kind[c] == 0 and c in first:
            s = first[c]
            joint[c] = seg_start[s]
            parent[c] = seg_cluster[seg_parent[s]] if seg_parent[s] >= 0 else -1
        else:
            shared = [int(v) for v in m if int(v) in branch_of and branch_of[int(v)] != c]
            joint[c] = rest[shared[0]] if shared else rest[m].mean(axis=0)
            parent[c] = branch_of[shared[0]] if shared else -1
    path, reach = np.zeros(C), 0.0
    for c in range(C):  # parents before children
        if parent[c] >= 0:
            path[c] = path[parent[c]] + np.linalg.norm(joint[c] - joint[parent[c]])
        m = members[offsets[c]:offsets[c + 1]]
        if len(m):
            reach = max(reach, float((path[c] + np.linalg.norm(rest[m] - joint[c], axis=1)).max()))
    return max(float((rest.max(axis=0) - rest.min(axis=0)).max()), reach)


def check_bake(path):
    """HDF5 bake => (None, summary) when finite and bounded, else (reason, summary)."""
    with h5py.File(path, "r") as f:
        rest = f["/mesh/rest_positions"][()].astype(np.float64)
        positions = f["/frames/positions"]
        attached = f["/frames/leaf_attached"][()] if "/frames/leaf_attached" in f else None
        vertex_leaf = None
        if attached is not None:
            # Vertices of each leaf cluster: a detached leaf flies off, it is not bounded.
            offsets, members, kind = (f["/model/cluster_offsets"][()], f["/model/cluster_members"][()],
                                      f["/model/cluster_kind"][()])
            vertex_leaf = np.full(rest.shape[0], -1)
            leaf = 0
            for c in range(len(kind)):
                if kind[c] == 1:
                    vertex_leaf[members[offsets[c]:offsets[c + 1]]] = leaf
                    leaf += 1
        size = tree_size(f)
        worst, frames = 0.0, positions.shape[0]
        for k in range(frames):  # frame by frame: long bakes need not fit in memory
            x = positions[k].astype(np.float64)
            if not np.isfinite(x).all():
                return f"frame index {k}: non-finite position written", ""
            d = np.linalg.norm(x - rest, axis=1)
            if vertex_leaf is not None:
                flying = (vertex_leaf >= 0) & (attached[k][np.maximum(vertex_leaf, 0)] == 0)
                d[flying] = 0
            worst = max(worst, float(d.max()))
    summary = f"{frames} frames, max displacement {worst:.3g} m of size {size:.3g} m"
    if not worst < RUNAWAY_SIZES * size:
        return f"displacement {worst:.3g} m >= {RUNAWAY_SIZES} x tree size {size:.3g} m", summary
    return None, summary


def judge(code, stderr, out_dir, h5_name):
    """Exit code, stderr, output folder => (passed, text)."""
    path = os.path.join(out_dir, h5_name)
    if code == 0:
        reason, summary = check_bake(path)
        return (reason is None), (summary if reason is None else reason)
    last = stderr.splitlines()[-1] if stderr else ""
    return False, f"exit {code}: {last}"


def kinetic_energy(path):
    """Bake with velocities => per-frame kinetic energy (J) and max displacement (m)."""
    with h5py.File(path, "r") as f:
        mass = f["/model/mass"][()] * (1 - f["/model/anchored"][()])
        v = f["/frames/velocities"][()].astype(np.float64)
        x = f["/frames/positions"][()].astype(np.float64)
        rest = f["/mesh/rest_positions"][()].astype(np.float64)
    energy = 0.5 * np.einsum("fnk,fnk,n->f", v, v, mass)
    return energy, np.linalg.norm(x - rest[None], axis=2).max(axis=1)


def run_million(binary, case, tmp):
    """1,000,000 steps: the last `window` frames against the first `window` (same run's prefix):
    kinetic energy and displacement must stay within 2x of the first window's maxima."""
    m = case["million"]
    scene = os.path.join(HERE, case["scene"])
    sets = dict(case.get("set", {}), **{"time.fps": m["fps"], "time.substeps": m["substeps"],
                                        "outputs": [{"format": "hdf5", "path": "out.h5", "velocities": True}]})
    w = m["window"]
    code, err, _ = treeanim(binary, scene, tmp, dict(sets, **{"time.frames": w}), timeout=case.get("timeout", 300))
    if code != 0:
        return False, f"first window: exit {code}: {err}"
    e0, d0 = kinetic_energy(os.path.join(tmp, "out.h5"))
    last = m["frames"] - 1
    code, err, _ = treeanim(binary, scene, tmp, dict(sets, **{"time.frames": m["frames"]}),
                            extra=["--frames", f"{last - w + 1}:{last}"], timeout=case.get("timeout", 300))
    passed, text = judge(code, err, tmp, "out.h5")
    if not passed or code != 0:
        return passed, text
    e1, d1 = kinetic_energy(os.path.join(tmp, "out.h5"))
    steps = (m["frames"] - 1) * m["substeps"]
    text = (f"{steps} steps: kinetic energy max {e0.max():.3g} J (first {w} frames) vs {e1.max():.3g} J (last {w}), "
            f"displacement {d0.max():.3g} vs {d1.max():.3g} m")
    bounded = e1.max() <= 2 * e0.max() and d1.max() <= 2 * d0.max()
    return bounded, text if bounded else "energy grew: " + text


def resident_kib(pid):
    """Process id => its resident set (KiB), or None once it has ended."""
    try:
        with open(f"/proc/{pid}/status") as f:
            return next(int(line.split()[1]) for line in f if line.startswith("VmRSS:"))
    except (OSError, StopIteration):
        return None


def run_soak(binary, case, tmp):
    """A long bake written only at its last frame: the tree must end within `rest` m of its rest
    pose, and its resident memory, sampled every `interval` s once `settle` of the run's samples
    are past (loading, growing and the first steps allocate), may grow by at most `growth` KiB."""
    s = case["soak"]
    last = case["set"]["time.frames"] - 1
    sets = dict(case["set"], outputs=[{"format": "hdf5", "path": "out.h5"}])
    # One thread: the soak judges a long run's rest and memory, not its parallel loops (the
    # determinism case does), and beside other tests OpenMP's waiting threads spin: two threads
    # ran past the 900 s limit there, where one alone takes about 4 minutes.
    args = [binary, "run", os.path.join(HERE, case["scene"]), "-o", tmp, "--quiet", "--threads", "1",
            "--frames", f"{last}:{last}"]
    for key, value in sets.items():
        args += ["--set", f"{key}={json.dumps(value)}"]
    start = time.perf_counter()
    samples = []
    with subprocess.Popen(args, stderr=subprocess.PIPE, text=True) as process:
        while process.poll() is None:
            kib = resident_kib(process.pid)
            if kib:
                samples.append(kib)
            time.sleep(s["interval"])
        err = process.stderr.read().strip()
    seconds = time.perf_counter() - start
    if process.returncode != 0:
        return False, f"exit {process.returncode}: {err.splitlines()[-1] if err else ''}"
    with h5py.File(os.path.join(tmp, "out.h5"), "r") as f:
        rest = f["/mesh/rest_positions"][()].astype(np.float64)
        final = np.linalg.norm(f["/frames/positions"][-1].astype(np.float64) - rest, axis=1).max()
    steady = samples[int(len(samples) * s["settle"]):]
    if len(steady) < 2:
        return False, f"{len(samples)} memory samples in {seconds:.1f} s: too few to judge"
    growth = max(steady) - steady[0]
    text = (f"{last + 1} frames in {seconds:.0f} s: {final * 1000:.3g} mm from rest at the end; resident memory "
            f"{steady[0] / 1024:.1f} MiB after the first {s['settle']:.0%} of the run, at most {max(steady) / 1024:.1f} MiB "
            f"after, {steady[-1] / 1024:.1f} MiB at the end ({len(samples)} samples)")
    if not final <= s["rest"]:
        return False, "not at rest: " + text
    if growth > s["growth"]:
        return False, "memory grew: " + text
    return True, text


def run_case(binary, case):
    with tempfile.TemporaryDirectory(prefix="stress-") as tmp:
        if "million" in case:
            return run_million(binary, case, tmp)
        if "soak" in case:
            return run_soak(binary, case, tmp)
        sets = dict(case.get("set", {}), outputs=[{"format": "hdf5", "path": "out.h5"}])
        scene = os.path.join(HERE, case["scene"])
        code, err, _ = treeanim(binary, scene, tmp, sets, timeout=case.get("timeout", 300))
        passed, text = judge(code, err, tmp, "out.h5")
        if passed and case.get("converged"):
            passed, versus = exaggeration(binary, scene, tmp, sets)
            text += "; " + versus
        return passed, text


def run_random(binary, count, seed):
    """`count` generated scenes => list of failures."""
    failures = []
    with tempfile.TemporaryDirectory(prefix="stress-random-") as tmp:
        scenes = os.path.join(tmp, "scenes")
        subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "stress-scenes"), "--seed", str(seed),
                        "--count", str(count), "--out", scenes], check=True)
        for name in sorted(os.listdir(scenes)):
            out = os.path.join(tmp, "out", name)
            os.makedirs(out)
            code, err, seconds = treeanim(binary, os.path.join(scenes, name), out, {})
            passed, text = judge(code, err, out, "out.h5")
            if passed:
                passed, versus = exaggeration(binary, os.path.join(scenes, name), out)
                text += "; " + versus
            report(f"random/{name}", passed, f"{text} ({seconds:.1f} s)")
            if not passed:
                failures.append(name)
    return failures


def run_determinism(binary):
    """The demo tree (parallel path: > 4096 memberships), 8 frames in wind, the solver in
    double and float, and on its samples (hsm.particles, the mesh placed in parallel), and 4 frames of configs/table1-13548.json (float, clusters of ~50
    members: the chain's eight-lane sums), each at 1, 2 and 4 threads with the portable solver
    loops and at 1 and 2 with each wider instruction set this CPU runs (TREEANIM_ISA,
    docs/solver.md "Instruction sets"); table1-13548 also stepped in cache blocks of 1,024
    memberships (TREEANIM_BLOCKS, docs/solver.md "Cache blocks") and without blocks."""
    demo_wind = {"wind.keys": [{"time": 0, "speed": 12, "direction": [1, 0, 0.3], "gust": 4}],
                 "hsm.leaf_detach_force": 0.3}
    texts = []
    sampled_wind = {**demo_wind, "hsm.particles": "samples"}  # the mesh placed from the samples
    for scene, precision, frames, extra_sets in (("demo-sparse.json", "double", 8, demo_wind),
                                                  ("demo-sparse.json", "float", 8, demo_wind),
                                                  ("demo-sparse.json", "double", 8, sampled_wind),
                                                  ("table1-13548.json", "float", 4, {})):
        digests = {}
        with tempfile.TemporaryDirectory(prefix="stress-det-") as tmp:
            sets = {"time.frames": frames, "outputs": [{"format": "hdf5", "path": "out.h5"}],
                    "hsm.precision": precision, **extra_sets}
            runs = [("portable", 1, None), ("portable", 2, None), ("portable", 4, None), ("avx2", 1, None),
                    ("avx2", 2, None), ("avx512", 1, None), ("avx512", 2, None)]
            if scene.startswith("table1"):
                runs += [("avx2", 1, 1024), ("avx2", 2, 1024), ("portable", 2, 1024), ("avx2", 2, 0)]
            for isa, threads, blocks in runs:
                code, err, _ = treeanim(binary, os.path.join(ROOT, "configs", scene), tmp, sets,
                                        extra=("--verbose",), threads=threads, isa=isa, blocks=blocks)
                if code != 0:
                    return False, f"{scene} {precision}, {isa}, OMP_NUM_THREADS={threads}, blocks {blocks}: exit {code}: {err}"
                ran = re.search(r"solver loops: (\w+)", err)
                if not ran:
                    return False, f"no 'solver loops:' in the verbose log: {err}"
                with h5py.File(os.path.join(tmp, "out.h5"), "r") as f:
                    digests[(ran.group(1), threads, blocks)] = f["/frames/positions"][()].tobytes()
        if len(set(digests.values())) != 1:
            return False, f"DIFFERENT /frames/positions across {sorted(map(str, digests))} ({scene}, {precision})"
        texts.append(f"{scene} {precision}{' samples' if 'hsm.particles' in extra_sets else ''} "
                     f"({len(next(iter(digests.values())))} bytes)")
    sets_run = sorted({isa for isa, _, _ in digests})
    return True, f"identical /frames/positions for 1, 2, 4 threads, the loops in {', '.join(sets_run)} and " + \
        "cache blocks of 1,024 memberships or none: " + ", ".join(texts)


def report(name, passed, text):
    print(f"{'PASS' if passed else 'FAIL'} {name}: {text}", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--treeanim", required=True)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("what", choices=["case", "ctest-cases", "all-cases", "random", "determinism"])
    parser.add_argument("args", nargs="*")
    a = parser.parse_args()
    with open(os.path.join(HERE, "cases.json")) as f:
        cases = json.load(f)["cases"]
    failures = []
    if a.what == "random":
        failures = run_random(a.treeanim, int(a.args[0]) if a.args else 20, a.seed)
    elif a.what == "determinism":
        passed, text = run_determinism(a.treeanim)
        report("determinism", passed, text)
        failures = [] if passed else ["determinism"]
    else:
        if a.what == "case":
            unknown = set(a.args) - {c["name"] for c in cases}
            if unknown:
                sys.exit(f"unknown case(s): {sorted(unknown)}")
        chosen = [c for c in cases if (a.what == "all-cases") or (a.what == "ctest-cases" and c.get("ctest"))
                  or (a.what == "case" and c["name"] in a.args)]
        for case in chosen:
            start = time.perf_counter()
            passed, text = run_case(a.treeanim, case)
            if not passed and "defect" in case:
                text += f" [known defect: {case['defect']}]"
            report(case["name"], passed, f"{text} ({time.perf_counter() - start:.1f} s)")
            if not passed:
                failures.append(case["name"] + (" (known defect)" if "defect" in case else ""))
    if failures:
        print(f"{len(failures)} failed: {', '.join(failures)}")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
