#!/usr/bin/python3
"""A wind volume through the treeanim binary (docs/scene.md `wind.volume`), with volumes written
at test time by write_volumes.py (python3-openvdb):

  volume_cli.py TREEANIM bad      every bad input exits 2 naming the file (grid, voxel, time),
                                  nothing written
  volume_cli.py TREEANIM info     `info --json` and `validate` give the volume's frames, bounds,
                                  voxel size and largest speed
  volume_cli.py TREEANIM forest   a gust front through a three-tree forest: each tree moves when
                                  the front reaches it, along it; three shards give the same bytes
                                  as one process
"""
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile

import h5py
import numpy as np
import pyopenvdb as vdb

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
WRITE = os.path.join(HERE, "write_volumes.py")


def write_volume(flow, layout, out_dir, *arguments):
    subprocess.run([sys.executable, WRITE, flow, layout, out_dir, *arguments], check=True)


def scene(folder, name, wind, time=None, forest=None, outputs=None):
    document = {
        "lsystem": {"grammar": os.path.join(SOURCE, "grammars/abop-2.6b-monopodial.lsys"), "iterations": 4},
        "tree": {"scale": 0.6, "width_scale": 0.01, "ring_sides": 6},
        "wind": wind,
        "time": time or {"fps": 24, "frames": 24, "substeps": 2},
        "outputs": outputs if outputs is not None else [{"format": "hdf5", "path": "tree.h5"}],
    }
    if forest:
        document["forest"] = forest
    path = os.path.join(folder, name)
    with open(path, "w") as f:
        json.dump(document, f)
    return path


def run(treeanim, *arguments):
    return subprocess.run([treeanim, *arguments], capture_output=True, text=True)


def check_bad(treeanim, tmp):
    vol = os.path.join(tmp, "vol")
    write_volume("uniform", "houdini", vol, "--frames", "1", "10", "--voxel", "1")
    # Damaged copies of frame 3 in sequences of their own.
    def copy_with(name, frame3):
        folder = os.path.join(tmp, name)
        shutil.copytree(vol, folder)
        with open(os.path.join(folder, "vel.0003.vdb"), "wb") as f:
            f.write(frame3)
        return folder
    whole = open(os.path.join(vol, "vel.0003.vdb"), "rb").read()
    not_vdb = copy_with("not-vdb", b"time,speed\n0,1\n")
    truncated = copy_with("truncated", whole[: len(whole) // 2])
    # Cut inside the grid's descriptor (its length-prefixed name): OpenVDB read a length past the
    # cut as garbage and allocated gigabytes before it failed.
    descriptor_cut = whole.index(b"\x03\x00\x00\x00vel") + 5
    truncated_descriptor = copy_with("truncated-descriptor", whole[:descriptor_cut])
    truncated_header = copy_with("truncated-header", whole[:6])  # OpenVDB found no grids in it

    def flipped(name, position, bit):
        damaged = bytearray(whole)
        damaged[position] ^= 1 << bit
        return copy_with(name, bytes(damaged))
    # A length inside the grid's own metadata 32 KB too long: OpenVDB read on past the file's end
    # and took 16 GB. The value of its string item "file_compression" follows its name and type.
    compression_value = whole.index(b"file_compression\x06\x00\x00\x00string") + 16 + 4 + 6
    metadata_length = flipped("metadata-length", compression_value + 1, 7)
    # The count of leaves in its delayed-load table 4,096 too large: OpenVDB sized its arrays by it.
    delayed_count = flipped("delayed-load-count", whole.index(b"__delayedload") + 13 + 4 + 1, 4)
    # The first leaf's values as a raw chunk of 64 KB, with that much more file after it: OpenVDB
    # reads it into the leaf's 6 KB buffer before it checks the length, over the heap beyond.
    grid, block, end = struct.unpack_from("<3q", whole, whole.index(b"Tree_vec3s_5_4_3") + 16 + 4)
    leaf_values = block + 64 + 1  # the leaf's value mask, its byte of what is stored, then its values
    assert whole[block + 64] in (0, 1, 6), "the first leaf stores no inactive values: its chunk's length follows"
    raw_chunk = bytearray(whole)
    struct.pack_into("<q", raw_chunk, leaf_values, -65536)
    raw_chunk = copy_with("raw-chunk", bytes(raw_chunk) + bytes(65536))
    nan = os.path.join(tmp, "nan")
    write_volume("uniform", "houdini", nan, "--frames", "1", "10", "--voxel", "1", "--nan-at", "3")
    fast = os.path.join(tmp, "fast")
    write_volume("uniform", "houdini", fast, "--frames", "1", "10", "--voxel", "1", "--velocity", "150", "0", "0")
    scalar = os.path.join(tmp, "scalar")  # 'vel' as a float grid
    write_volume("uniform", "split", scalar, "--frames", "1", "10", "--voxel", "1", "--grid", "vel")
    for frame in range(1, 11):
        path = os.path.join(scalar, f"vel.{frame:04d}.vdb")
        grids = vdb.readAll(path)[0]
        grids[0].name = "vel"
        vdb.write(path, grids=[grids[0]])

    def rewritten(name, change):
        """A copy of `vol` whose every frame's grids went through change(grids) => its folder."""
        folder = os.path.join(tmp, name)
        shutil.copytree(vol, folder)
        for frame in range(1, 11):
            path = os.path.join(folder, f"vel.{frame:04d}.vdb")
            grids = vdb.readAll(path)[0]
            vdb.write(path, grids=change(grids))
        return folder
    twice = rewritten("twice", lambda grids: [grids[0], grids[0].deepCopy()])

    def nan_background(grids):
        grids[0].background = (float("nan"), 0.0, 0.0)
        return grids
    background = rewritten("background", nan_background)
    split_background = os.path.join(tmp, "split-background")  # vel.y's background NaN
    write_volume("uniform", "split", split_background, "--frames", "1", "10", "--voxel", "1")
    for frame in range(1, 11):
        path = os.path.join(split_background, f"vel.{frame:04d}.vdb")
        grids = vdb.readAll(path)[0]
        for g in grids:
            if g.name == "vel.y":
                g.background = float("nan")
        vdb.write(path, grids=grids)

    def volume(folder, **extra):
        return {"volume": {"path": os.path.join(folder, "vel.####.vdb"), **extra}}
    nine = {"fps": 24, "frames": 9, "substeps": 2}  # times 0 .. 8/24 s: frames 1 .. 9
    cases = [
        ("missing-frame", volume(vol), {"fps": 24, "frames": 24, "substeps": 2},
         "vel.0011.vdb: the volume frame is missing, and the bake's times 0 s to 0.958333 s need frames 1 to 24"),
        ("before-the-first-frame", volume(vol), {"fps": 24, "frames": 4, "start": -2, "substeps": 2},
         "vel.-001.vdb: the volume frame is missing"),
        ("not-a-vdb", volume(not_vdb), nine, "not-vdb/vel.0003.vdb: not a readable VDB file"),
        ("truncated", volume(truncated), nine,
         f"truncated/vel.0003.vdb: not a readable VDB file (the file is cut short: it ends at byte {len(whole) // 2}, "
         f"inside grid 1, which ends at byte {len(whole)})"),
        ("truncated-descriptor", volume(truncated_descriptor), nine,
         f"vel.0003.vdb: not a readable VDB file (the file is cut short: it ends at byte {descriptor_cut}, inside "
         "grid 1's descriptor)"),
        ("truncated-header", volume(truncated_header), nine,
         "vel.0003.vdb: not a readable VDB file (the file is cut short: it ends at byte 6, inside the header)"),
        ("metadata-length", volume(metadata_length), nine,
         f"metadata-length/vel.0003.vdb: not a readable VDB file (grid 1's metadata runs past the grid's data, "
         f"which begins at byte {block})"),
        ("delayed-load-count", volume(delayed_count), nine,
         "delayed-load-count/vel.0003.vdb: not a readable VDB file (grid 1's metadata's delayed-load table counts "
         "4"),
        ("raw-chunk", volume(raw_chunk), nine, "raw-chunk/vel.0003.vdb: not a readable VDB file ("),
        ("missing-grid", volume(vol, grid="velocity"), nine,
         "vel.0001.vdb: no grid 'velocity' (nor 'velocity.x', 'velocity.y', 'velocity.z'); its grids: 'vel' (vec3s)"),
        ("grid-of-another-type", volume(scalar), nine,
         "vel.0001.vdb: grid 'vel' holds float values; a velocity is a vec3s grid"),
        ("not-finite", volume(nan), nine, "nan/vel.0003.vdb: grid 'vel', voxel (4, 4, 4): the velocity is not finite"),
        ("too-fast", volume(fast), nine,
         "fast/vel.0001.vdb: grid 'vel', voxel (0, 0, 0): a speed of 150 m/s, beyond the wind's 113 m/s"),
        ("units-too-fast", volume(vol, units=20), nine, "a speed of 160 m/s, beyond the wind's 113 m/s"),
        ("bad-pattern", volume(vol) | {"volume": {"path": os.path.join(vol, "vel.%s.vdb")}}, nine,
         "/wind/volume/path: expected at most one frame number in the file name, as #### or %04d (at most 18 "
         "digits), got 'vel.%s.vdb'"),
        ("no-path", {"volume": {"grid": "vel"}}, nine, "/wind/volume/path: expected the volume's frame files"),
        ("loop", volume(vol), {"fps": 24, "frames": 9, "loop": True},
         "/wind/volume: a loop needs a wind that repeats"),
        ("up", volume(vol, up="x"), nine, "/wind/volume/up"),
        ("two-grids-one-name", volume(twice), nine,
         "twice/vel.0001.vdb: 2 grids are named 'vel': which one is the velocity is not clear"),
        ("background-not-finite", volume(background), nine,
         "background/vel.0001.vdb: the background of vec3s grid 'vel' (the inactive voxels' value): the velocity is "
         "not finite"),
        ("split-background-not-finite", volume(split_background), nine,
         "split-background/vel.0001.vdb: the background of float grid 'vel.y' (the inactive voxels' value): the "
         "velocity is not finite"),
    ]
    failures = []
    for name, wind, time, message in cases:
        path = scene(tmp, f"{name}.json", wind, time)
        out = os.path.join(tmp, "out-" + name)
        os.makedirs(out)
        for arguments in (["run", path, "-o", out], ["validate", path]):
            result = run(treeanim, *arguments)
            problems = []
            if result.returncode != 2:
                problems.append(f"exit {result.returncode}, expected 2")
            if message not in result.stderr:
                problems.append(f"stderr {result.stderr.strip()!r} lacks {message!r}")
            if os.listdir(out):
                problems.append(f"wrote {os.listdir(out)}")
            if problems:
                failures.append(f"{name} ({arguments[0]}): " + "; ".join(problems))
            else:
                print(f"{name} ({arguments[0]}): exit 2: {result.stderr.strip()}")
    # An inactive voxel reads the grid's background whatever value the cache stored there: half
    # the box switched off holding 1e30 (or NaN) bakes as the same half switched off at 0.
    def switched_off(value):
        def change(grids):
            access = grids[0].getAccessor()
            for i in range(4):
                for j in range(9):
                    for k in range(9):
                        access.setValueOff((i, j, k), value)
            return grids
        return change
    baked = []
    for name, value in (("off-at-background", (0.0, 0.0, 0.0)), ("off-at-1e30", (1e30, 0.0, 0.0)),
                        ("off-at-nan", (float("nan"), 0.0, 0.0))):
        path = scene(tmp, f"{name}.json", volume(rewritten(name, switched_off(value))), nine)
        out = os.path.join(tmp, "out-" + name)
        result = run(treeanim, "run", path, "-o", out)
        if result.returncode != 0:
            failures.append(f"{name}: exit {result.returncode}: {result.stderr.strip()}")
            continue
        with h5py.File(os.path.join(out, "tree.h5")) as f:
            baked.append(f["frames/positions"][()])
    if len(baked) == 3 and not (np.array_equal(baked[0], baked[1]) and np.array_equal(baked[0], baked[2])):
        failures.append("a value stored in an inactive voxel changed the bake: it must read the background")
    # A binary copied without the OpenVDB module beside it bakes a scene without a volume, and
    # refuses one with a volume, before writing anything, saying why.
    copied = os.path.join(tmp, "copied", "treeanim")
    os.makedirs(os.path.dirname(copied))
    shutil.copy2(treeanim, copied)
    path = scene(tmp, "no-module.json", volume(vol), nine)
    for arguments in (["run", path, "-o", os.path.join(tmp, "out-no-module")], ["validate", path]):
        result = run(copied, *arguments)
        message = "treeanim's OpenVDB reader could not be loaded"
        if result.returncode != 2 or message not in result.stderr:
            failures.append(f"no module ({arguments[0]}): exit {result.returncode}, stderr {result.stderr.strip()!r}")
        elif os.path.exists(os.path.join(tmp, "out-no-module")) and os.listdir(os.path.join(tmp, "out-no-module")):
            failures.append(f"no module ({arguments[0]}): wrote {os.listdir(os.path.join(tmp, 'out-no-module'))}")
        else:
            print(f"no module ({arguments[0]}): exit 2: {result.stderr.strip()}")
    calm = scene(tmp, "no-volume.json", {"keys": [{"time": 0, "speed": 2, "direction": [1, 0, 0]}]}, nine)
    result = run(copied, "run", calm, "-o", os.path.join(tmp, "out-no-volume"))
    if result.returncode != 0:
        failures.append(f"no module, no volume: exit {result.returncode}, stderr {result.stderr.strip()!r}")
    if failures:
        raise SystemExit("\n".join(failures))


def check_info(treeanim, tmp):
    for layout, stem, grid, up in (("houdini", "vel.####.vdb", "vel", "y"), ("split", "vel.####.vdb", "vel", "y"),
                                   ("blender", "fluid_data_####.vdb", "velocity", "z")):
        folder = os.path.join(tmp, layout)
        write_volume("shear", layout, folder, "--frames", "1", "24")
        wind = {"volume": {"path": os.path.join(folder, stem), "grid": grid, "up": up}}
        path = scene(tmp, f"{layout}.json", wind)
        result = run(treeanim, "info", path, "--json")
        assert result.returncode == 0, result.stderr
        volume = json.loads(result.stdout)["wind_volume"]
        print(layout, volume)
        assert volume["frames"] == [1, 24], volume
        assert np.allclose(volume["bounds_min"], [-4, 0, -4]) and np.allclose(volume["bounds_max"], [4, 8, 4]), volume
        assert abs(volume["voxel_size"] - 0.5) < 1e-12, volume
        assert abs(volume["largest_speed"] - 14) < 1e-5, volume  # 2 + 1.5 * 8 at the top
        text = run(treeanim, "validate", path)
        assert text.returncode == 0 and "wind volume: frames 1 to 24" in text.stdout, text.stdout + text.stderr


def tip_motion(h5_path):
    with h5py.File(h5_path, "r") as f:
        positions = f["/frames/positions"][...]
    rest = positions[0]
    tip = int(np.argmax(rest[:, 1]))
    return positions[:, tip, :] - rest[tip]


def check_forest(treeanim, tmp):
    # A front of 12 m/s moving along +x at 6 m/s from x = -12 m through trees at x = -6, 0, 6:
    # it reaches them at 1, 2 and 3 s. The cache at 12 fps, in Blender's layout (Z-up).
    folder = os.path.join(tmp, "gust")
    write_volume("gust", "blender", folder, "--frames", "1", "49", "--fps", "12", "--voxel", "0.5",
                 "--lower", "-10", "0", "-4", "--upper", "10", "6", "4", "--speed", "12",
                 "--front-start", "-12", "--front-speed", "6", "--width", "0.5")
    wind = {"volume": {"path": os.path.join(folder, "fluid_data_####.vdb"), "grid": "velocity", "up": "z",
                       "fps": 12, "outside": "calm"}}
    forest = {"trees": [{"id": f"t{i}", "position": [x, 0, 0], "seed": 1} for i, x in enumerate((-6, 0, 6))]}
    outputs = [{"format": "hdf5", "path": "{tree}.h5"}, {"format": "html", "path": "{tree}.html"}]
    path = scene(tmp, "forest.json", wind, {"fps": 24, "frames": 96, "substeps": 2}, forest, outputs)
    whole = os.path.join(tmp, "whole")
    result = run(treeanim, "run", path, "-o", whole, "--quiet")
    assert result.returncode == 0, result.stderr
    moved = []
    for i, x in enumerate((-6, 0, 6)):
        motion = tip_motion(os.path.join(whole, f"t{i}.h5"))
        size = np.linalg.norm(motion, axis=1)
        first = int(np.argmax(size > 0.005))
        assert size[first] > 0.005, f"tree at x = {x} never moved"
        assert motion[first, 0] > 0.9 * size[first], f"tree at x = {x} not pushed along the flow: {motion[first]}"
        moved.append(first / 24)
        print(f"tree at x = {x} m: moves at {first / 24:.3f} s (front arrives at {(x + 12) / 6:.3f} s), "
              f"largest sway {size.max():.3f} m")
    assert moved[0] < moved[1] < moved[2], moved
    for x, t in zip((-6, 0, 6), moved):
        assert abs(t - (x + 12) / 6) < 0.5, (x, t)
    assert os.path.exists(os.path.join(whole, "forest.html"))
    # The middle tree's page plots the volume's wind at the tree: still before the front, 12 m/s after.
    page = open(os.path.join(whole, "t1.html"), encoding="utf-8").read()
    plot = json.loads(re.search(r'<script id="treeanim-bake" type="application/json">(.*?)</script>', page,
                                re.S).group(1))["plot"]
    wind = np.array(plot["wind"]).reshape(-1, 3)
    times = np.array(plot["time"])
    before, after = wind[np.argmin(abs(times - 1.0))], wind[np.argmin(abs(times - 3.5))]
    assert np.linalg.norm(before) < 0.01 and abs(after[0] - 12) < 0.01, (before, after)
    print(f"the middle tree's page plots the wind {before} m/s at 1 s, {after} m/s at 3.5 s")
    # Three shards give the same bytes as one process.
    shards = os.path.join(tmp, "shards")
    for shard in range(3):
        result = run(treeanim, "run", path, "-o", shards, "--quiet", "--shard", f"{shard}/3")
        assert result.returncode == 0, result.stderr
    for i in range(3):
        with h5py.File(os.path.join(whole, f"t{i}.h5"), "r") as a, h5py.File(os.path.join(shards, f"t{i}.h5"), "r") as b:
            assert np.array_equal(a["/frames/positions"][...], b["/frames/positions"][...]), f"tree t{i} differs"
    print("three shards: the same positions as one process")
    if os.environ.get("TREEANIM_KEEP_FOREST"):
        shutil.copytree(whole, os.environ["TREEANIM_KEEP_FOREST"], dirs_exist_ok=True)


def main():
    treeanim, case = sys.argv[1], sys.argv[2]
    tmp = tempfile.mkdtemp(prefix=f"treeanim_volume_{case}_")
    try:
        {"bad": check_bad, "info": check_info, "forest": check_forest}[case](os.path.abspath(treeanim), tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
