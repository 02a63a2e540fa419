#!/usr/bin/python3
"""The species library in the test suite (docs/species.md "Checks"):

  check_species.py --treeanim BIN SPECIES     one species: its shape, its bakes, its sway
  check_species.py --treeanim BIN --list      `treeanim species` and a bad name

A species passes when, as its table entry (grammars/species/species.json, "checks") documents:
- shape, from the rest mesh at its default height, seeds 1 and 2: the crown's width over the
  tree's height in its range; the widest crown low (conifers), twig tips hanging below their
  attachment (weeping and birch twigs), the stem unbranched below the crown (palms), several
  stems from the ground (shrubs), every blade from one point (grasses); two seeds differ;
- bakes: 240 frames of configs/demo.json's gusting wind at its smallest and largest height,
  seeds 1 and 2, exit 0, finite and bounded; the smallest with seed 1 and the largest with
  seed 2 also converged against 64 substeps as the stress rule asks (tests/stress/README.md);
- sway: plucked at the two heights, its first frequency (at the top of its leader) lies in
  the field band: between Jackson et al.'s broadleaves - 0.2 Hz and Moore & Maguire's conifers
  + 0.07 Hz at its DBH and height (scripts/bench-accuracy), or the entry's own band where a
  plant has no stem at breast height; and at its default height the frequency the table gives
  (`treeanim species` prints it) within 10 %.
Prints a line per check; exit 1 on any failure.
"""
import argparse
import importlib.machinery
import json
import math
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tests", "stress"))
import run_stress  # noqa: E402  (bake, bounds and the 64-substep rule)

accuracy = importlib.machinery.SourceFileLoader("bench_accuracy", os.path.join(ROOT, "scripts", "bench-accuracy")).load_module()

with open(os.path.join(ROOT, "configs", "demo.json")) as f:
    GUSTS = json.load(f)["wind"]
with open(os.path.join(ROOT, "configs", "accuracy-pluck.json")) as f:
    PLUCK = json.load(f)
PLUCK_SPEED = 5  # m/s, the gust that plucks a species


def table():
    with open(os.path.join(ROOT, "grammars", "species", "species.json")) as f:
        return {s["name"]: s for s in json.load(f)["species"]}


def write_scene(folder, name, scene):
    path = os.path.join(folder, name)
    with open(path, "w") as f:
        json.dump(scene, f)
    return path


def bake(binary, scene, folder, sets=None):
    """Scene dict => (exit code, stderr, the bake's path): one thread, the solver's own."""
    os.makedirs(folder, exist_ok=True)
    code, err, _ = run_stress.treeanim(binary, write_scene(folder, "scene.json", scene), folder, sets or {}, threads=1)
    return code, err, os.path.join(folder, "out.h5")


def species_scene(name, height, seed, **more):
    return dict({"species": {"name": name, "height": height}, "seed": seed,
                 "outputs": [{"format": "hdf5", "path": "out.h5"}]}, **more)


def rest_mesh(path):
    with h5py.File(path, "r") as f:
        return (f["/mesh/rest_positions"][()].astype(np.float64), f["/skeleton/segment_start"][()].astype(np.float64),
                f["/skeleton/segment_end"][()].astype(np.float64), f["/skeleton/segment_parent"][()])


def crown_shape(rest):
    """Rest mesh => (height, width over height, height of its widest tenth over the height)."""
    y0, height = rest[:, 1].min(), np.ptp(rest[:, 1])
    width = max(np.ptp(rest[:, 0]), np.ptp(rest[:, 2]))
    base = rest[np.argmin(rest[:, 1])]
    radius = np.hypot(rest[:, 0] - base[0], rest[:, 2] - base[2])
    band = np.minimum(((rest[:, 1] - y0) / height * 10).astype(int), 9)
    widest = max(range(10), key=lambda b: radius[band == b].max() if (band == b).any() else 0)
    return height, width / height, (widest + 0.5) / 10


def hanging_share(start, end, parent):
    """Skeleton => the share of twigs (the segments from a branching point to a tip) whose tip
    hangs below the point where the twig attaches."""
    children = np.bincount(parent[parent >= 0], minlength=len(parent))
    tips = np.nonzero(children == 0)[0]
    hanging = 0
    for s in tips:
        a = s
        while parent[a] >= 0 and children[parent[a]] == 1:
            a = parent[a]
        hanging += end[s, 1] < start[a, 1]
    return hanging / max(len(tips), 1)


def shape_checks(name, entry, rests, failures):
    checks = entry["checks"]
    rest, start, end, parent = rests[0]
    height, ratio, widest = crown_shape(rest)
    lo, hi = checks["width_over_height"]
    print(f"  shape: height {height:.2f} m (default {entry['height']['default']} m), crown width / height {ratio:.2f} "
          f"(documented {lo}-{hi}), widest at {widest:.2f} of the height")
    if abs(height / entry["height"]["default"] - 1) > 0.1:
        failures.append(f"grown to {height:.2f} m, not its default height {entry['height']['default']} m (10 %)")
    if not lo <= ratio <= hi:
        failures.append(f"crown width / height {ratio:.2f} outside {lo}-{hi}")
    if "widest_below" in checks and widest > checks["widest_below"]:
        failures.append(f"widest at {widest:.2f} of its height, not below {checks['widest_below']} (a cone)")
    if "hanging_twigs" in checks:
        share = hanging_share(start, end, parent)
        print(f"  twigs hanging below their attachment: {100 * share:.0f} % (at least {100 * checks['hanging_twigs']:.0f} %)")
        if share < checks["hanging_twigs"]:
            failures.append(f"{100 * share:.0f} % of twig tips hang below their attachment")
    if "unbranched_below" in checks:
        children = np.bincount(parent[parent >= 0], minlength=len(parent))
        y0 = rest[:, 1].min()
        forks = [s for s in range(len(parent)) if children[s] > 1 and end[s, 1] - y0 < checks["unbranched_below"] * height]
        print(f"  branching points below {checks['unbranched_below']} of the height: {len(forks)}")
        if forks:
            failures.append(f"the stem branches below {checks['unbranched_below']} of the height ({len(forks)} forks)")
    ground = np.nonzero((parent < 0) | (start[:, 1] - rest[:, 1].min() < 0.02 * height))[0]
    stems = [s for s in ground if np.linalg.norm(end[s] - start[s]) > 0 and start[s, 1] - rest[:, 1].min() < 0.02 * height]
    if "stems_from_ground" in checks:
        print(f"  stems from the ground: {len(stems)} (at least {checks['stems_from_ground']})")
        if len(stems) < checks["stems_from_ground"]:
            failures.append(f"{len(stems)} stems from the ground, expected at least {checks['stems_from_ground']}")
    if "one_base" in checks:
        spread = max((np.hypot(*(start[s, [0, 2]] - start[stems[0], [0, 2]])) for s in stems), default=0)
        print(f"  blades from one point: {len(stems)} blades, their bases within {spread * 1000:.1f} mm")
        if len(stems) < checks["one_base"] or spread > 0.02 * height:
            failures.append(f"{len(stems)} blades with bases {spread * 1000:.1f} mm apart: not a tuft from one point")
    if rests[0][0].shape == rests[1][0].shape and np.array_equal(rests[0][0], rests[1][0]):
        failures.append("seeds 1 and 2 grow the same tree")


def sway_band(entry, dbh, height):
    """The field band at a DBH (m) and height (m): between the two regressions, each widened by
    its scatter on its outer side (scripts/bench-accuracy), or the entry's own band."""
    if "sway_band" in entry["checks"]:
        return tuple(entry["checks"]["sway_band"])
    (low, low_scatter), (high, high_scatter) = sorted([(0.064 + 3.25 * dbh * 100 / height ** 2, 0.07),
                                                       (-0.665 + 4.66 / math.sqrt(height), 0.2)])
    return low - low_scatter, high + high_scatter


def leader_top(path):
    """Bake => the branch vertex nearest the top of the leader: the path toward the tree's highest
    point, from the root segment that reaches it, while the next segment is at least half as thick
    (the stem that a tree's first sway mode moves, not a drooping limb's or a frond's tip)."""
    with h5py.File(path, "r") as f:
        parent, radius = f["/skeleton/segment_parent"][()], f["/skeleton/segment_radius"][()]
        end, rest = f["/skeleton/segment_end"][()], f["/mesh/rest_positions"][()]
        branch = run_stress.branch_vertices(f)
    children = {}
    for s, p in enumerate(parent):
        children.setdefault(int(p), []).append(s)
    top = end[:, 1].copy()  # the highest point of each segment's subtree (a parent comes first)
    for s in range(len(parent) - 1, -1, -1):
        if parent[s] >= 0:
            top[parent[s]] = max(top[parent[s]], top[s])
    s = max(children[-1], key=lambda k: top[k])
    while s in children:
        up = max(children[s], key=lambda k: top[k])
        if radius[up, 0] < 0.5 * radius[s, 1]:
            break
        s = up
    candidates = np.nonzero(branch)[0]
    return int(candidates[np.argmin(np.linalg.norm(rest[candidates] - end[s], axis=1))])


def pluck(binary, name, height, folder, own_band):
    """The species at `height` plucked as configs/accuracy-pluck.json plucks the demo tree =>
    (first sway frequency Hz, DBH m, height m)."""
    # A gentler gust than the demo tree's: a species' crown of leaf cards catches more wind, and
    # the first frequency is the small motion's (a limb bent past yield_strain rings about a new
    # rest, and large swings mix the modes).
    wind = dict(PLUCK["wind"], keys=[dict(k, speed=min(k["speed"], PLUCK_SPEED)) for k in PLUCK["wind"]["keys"]])
    scene = species_scene(name, height, PLUCK["seed"], wind=wind, hsm=PLUCK["hsm"], time=dict(PLUCK["time"], frames=720))
    code, err, path = bake(binary, scene, folder)
    if code != 0:
        raise RuntimeError(f"pluck at {height} m: exit {code}: {err}")
    with h5py.File(path, "r") as f:
        grown = float(np.ptp(f["/mesh/rest_positions"][:, 1]))
    # A plant with no stem at breast height has no DBH: its entry gives its own band.
    dbh = math.nan if own_band else accuracy.breast_height_diameter(path)[0]
    return accuracy.tip_frequency(path, leader_top(path), 0.6), dbh, grown


def check_species(binary, name, tmp):
    entry = table()[name]
    failures = []
    heights = (entry["height"]["min"], entry["height"]["max"])
    rests = []
    for seed in (1, 2):
        code, err, path = bake(binary, species_scene(name, entry["height"]["default"], seed, time={"frames": 1}),
                               os.path.join(tmp, f"rest-{seed}"))
        if code != 0:
            return [f"seed {seed} at its default height: exit {code}: {err}"]
        rests.append(rest_mesh(path))
    shape_checks(name, entry, rests, failures)
    for height in heights:
        for seed in (1, 2):
            folder = os.path.join(tmp, f"gusts-{height}-{seed}")
            scene = species_scene(name, height, seed, wind=GUSTS, time={"fps": 24, "frames": 240})
            code, err, _ = bake(binary, scene, folder)
            passed, text = run_stress.judge(code, err, folder, "out.h5")
            # A 64-substep reference costs some 30 bakes at the default step: one per height and
            # per seed, on the diagonal, holds both heights and both trees to the rule.
            if passed and (height, seed) in ((heights[0], 1), (heights[1], 2)):
                passed, more = run_stress.exaggeration(binary, os.path.join(folder, "scene.json"), folder)
                text += "; " + more
            print(f"  240 frames of gusts at {height} m, seed {seed}: {'ok' if passed else 'FAIL'}: {text}")
            if not passed:
                failures.append(f"gusts at {height} m, seed {seed}: {text}")
    listed = json.loads(subprocess.run([binary, "species", "--json"], capture_output=True, text=True, check=True).stdout)
    listed = next(s for s in listed if s["name"] == name)
    for height in (heights[0], entry["height"]["default"], heights[1]):
        f, dbh, grown = pluck(binary, name, height, os.path.join(tmp, f"pluck-{height}"), "sway_band" in entry["checks"])
        lo, hi = sway_band(entry, dbh, grown)
        print(f"  plucked at {grown:.2f} m (DBH {100 * dbh:.1f} cm): {f:.3f} Hz, band {lo:.3f}-{hi:.3f} Hz")
        if height in heights and not lo <= f <= hi:
            failures.append(f"sways at {f:.3f} Hz at {grown:.2f} m, outside the band {lo:.3f}-{hi:.3f} Hz")
        if height == entry["height"]["default"]:
            print(f"  treeanim species: {listed['sway_frequency_hz']:.3f} Hz at its default height (the table's, plucked)")
            if abs(listed["sway_frequency_hz"] / f - 1) > 0.1:
                failures.append(f"treeanim species prints {listed['sway_frequency_hz']:.3f} Hz, the pluck {f:.3f} Hz")
    return failures


def check_list(binary, tmp):
    failures = []
    listed = json.loads(subprocess.run([binary, "species", "--json"], capture_output=True, text=True, check=True).stdout)
    names = [s["name"] for s in listed]
    print(f"  treeanim species --json: {len(listed)} species: {', '.join(names)}")
    if names != list(table()):
        failures.append("the listing's names are not the table's")
    for s in listed:
        if list(s)[0] != "name" or not all(k in s for k in ("height", "vertices", "clusters", "sway_frequency_hz")):
            failures.append(f"{s.get('name')}: expected name first, height, vertices, clusters, sway_frequency_hz")
    text = subprocess.run([binary, "species"], capture_output=True, text=True, check=True).stdout
    if not all(n in text for n in names):
        failures.append("treeanim species leaves a species out")
    scene = write_scene(tmp, "bad.json", {"species": "english_okk"})
    done = subprocess.run([binary, "run", scene, "-o", os.path.join(tmp, "bad")], capture_output=True, text=True)
    print(f"  a bad name: exit {done.returncode}: {done.stderr.strip()}")
    if done.returncode != 2 or "did you mean english_oak?" not in done.stderr or not all(n in done.stderr for n in names):
        failures.append("a bad species name is not refused with exit 2, the names and the closest")
    if os.path.exists(os.path.join(tmp, "bad")):
        failures.append("a refused scene wrote its output folder")
    return failures


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--treeanim", required=True)
    parser.add_argument("--list", action="store_true")
    parser.add_argument("species", nargs="?")
    args = parser.parse_args()
    # One thread per bake, the 64-substep references too: ctest runs tests side by side, and
    # OpenMP threads that wait on a busy core spin.
    os.environ["OMP_NUM_THREADS"] = "1"
    with tempfile.TemporaryDirectory() as tmp:
        failures = check_list(args.treeanim, tmp) if args.list else check_species(args.treeanim, args.species, tmp)
    for failure in failures:
        print(f"FAIL: {failure}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
