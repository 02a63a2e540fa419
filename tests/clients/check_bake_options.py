#!/usr/bin/python3
"""Checks the optional outputs of one bake with h5py and numpy, against the plain HDF5 bake of
the same scene:

- normals (/frames/normals of PLAIN.h5): float32 [F, N, 3], unit length, and equal to the
  normals recomputed here from the frame's float32 positions and triangles (area-weighted sums
  of triangle cross products) within NORMAL_TOLERANCE; the OBJ sequence's "vn" lines and the
  animated GLB's rest NORMAL + morph-target NORMAL equal them too;
- quantized (QUANTIZED.h5): format_version 2, no /frames/positions, /frames/displacement_quantized
  int16 or int32 [F, N, 3] with shuffle + deflate, one frame per chunk and the attribute `step`;
  rest + step * q within half a step of the plain bake's positions;
- MDD: big-endian frame count, vertex count, float32 times (= /frames/time), then the frames,
  equal to /frames/positions bit for bit.

Usage: /usr/bin/python3 check_bake_options.py PLAIN.h5 --quantized Q.h5 --mdd M.mdd
       --obj PREFIX --glb ANIM.glb
Exit 0 when everything holds, 1 with one line per failure otherwise."""
import argparse
import json
import struct
import sys

import h5py
import numpy as np

# float32 normals of float32 positions, recomputed in float64: they differ by rounding only.
NORMAL_TOLERANCE = 1e-6

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)
    return condition


def recomputed_normals(positions, triangles, fallback):
    """(N, 3) float32 positions => (N, 3) unit normals, area-weighted, fallback where none."""
    p = positions.astype(np.float64)
    a, b, c = p[triangles[:, 0]], p[triangles[:, 1]], p[triangles[:, 2]]
    cross = np.cross(b - a, c - a)
    sums = np.zeros_like(p)
    for corner in range(3):
        np.add.at(sums, triangles[:, corner], cross)
    length = np.linalg.norm(sums, axis=1)
    normals = np.array(fallback, np.float64)
    has = length > 1e-30
    normals[has] = sums[has] / length[has, None]
    return normals


def check_normals(f, args):
    frames, n = f["frames/positions"].shape[:2]
    normals = f["frames/normals"]
    check(normals.dtype == np.float32 and normals.shape == (frames, n, 3) and normals.chunks == (1, n, 3),
          f"/frames/normals: {normals.dtype} {normals.shape} {normals.chunks}")
    triangles = f["mesh/triangles"][()].astype(np.int64)
    rest_normals = recomputed_normals(f["mesh/rest_positions"][()], triangles, np.tile([0.0, 1.0, 0.0], (n, 1)))
    worst = 0.0
    for k in range(frames):
        ours = normals[k].astype(np.float64)
        check(np.all(np.isfinite(ours)), f"/frames/normals[{k}]: non-finite values")
        check(np.abs(np.linalg.norm(ours, axis=1) - 1).max() < 1e-6, f"/frames/normals[{k}]: not of unit length")
        error = np.abs(ours - recomputed_normals(f["frames/positions"][k], triangles, rest_normals)).max()
        worst = max(worst, error)
        check(error <= NORMAL_TOLERANCE, f"/frames/normals[{k}]: {error:.3g} from the recomputed normals")
    return worst


def read_vn(path):
    values = []
    with open(path) as lines:
        for line in lines:
            if line.startswith("vn "):
                values.append([np.float32(x) for x in line.split()[1:4]])
    return np.array(values, np.float32)


def check_obj_normals(f, prefix):
    time = f["frames/time"][()]
    compared = 0
    for k, index in enumerate(np.rint(time * f.attrs["fps"]).astype(np.int64)):
        try:
            vn = read_vn(f"{prefix}.{index:04d}.obj")
        except FileNotFoundError:
            continue
        compared += 1
        check(np.array_equal(vn, f["frames/normals"][k]), f"{prefix}.{index:04d}.obj: vn != /frames/normals[{k}]")
    check(compared > 0, f"{prefix}: no OBJ frame with normals compared")
    return compared


def check_glb_normals(f, path):
    data = open(path, "rb").read()
    json_length = struct.unpack("<I", data[12:16])[0]
    document = json.loads(data[20:20 + json_length])
    binary = data[20 + json_length + 8:]

    def accessor(index):
        a = document["accessors"][index]
        view = document["bufferViews"][a["bufferView"]]
        start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        return np.frombuffer(binary, "<f4", a["count"] * 3, start).reshape(-1, 3)

    primitive = document["meshes"][0]["primitives"][0]
    if not check("NORMAL" in primitive["attributes"], f"{path}: no NORMAL on the mesh"):
        return 0
    rest = accessor(primitive["attributes"]["NORMAL"])
    targets = primitive["targets"]
    normals = f["frames/normals"]
    check(len(targets) == normals.shape[0], f"{path}: {len(targets)} targets for {normals.shape[0]} frames")
    worst = 0.0
    for k, target in enumerate(targets[:normals.shape[0]]):
        if not check("NORMAL" in target, f"{path}: target {k} has no NORMAL"):
            continue
        error = np.abs(rest + accessor(target["NORMAL"]) - normals[k]).max()
        worst = max(worst, error)
        check(error <= NORMAL_TOLERANCE, f"{path}: rest + target {k} NORMAL is {error:.3g} from /frames/normals[{k}]")
    return len(targets)


def check_quantized(plain, path):
    with h5py.File(path, "r") as q:
        check(q.attrs["format_version"] == 2, f"{path}: format_version {q.attrs['format_version']}, expected 2")
        check("positions" not in q["frames"], f"{path}: /frames/positions present beside the quantized data")
        d = q["frames/displacement_quantized"]
        frames, n = plain["frames/positions"].shape[:2]
        check(d.dtype in (np.int16, np.int32) and d.shape == (frames, n, 3) and d.chunks == (1, n, 3),
              f"{path}: /frames/displacement_quantized {d.dtype} {d.shape} {d.chunks}")
        check(d.shuffle and d.compression == "gzip", f"{path}: filters shuffle={d.shuffle} {d.compression}")
        step = float(d.attrs["step"])
        rest = q["mesh/rest_positions"][()]
        worst = 0.0
        for k in range(frames):
            positions = rest + step * d[k]  # the one line a reader needs
            error = np.abs(positions - plain["frames/positions"][k]).max()
            worst = max(worst, error)
        check(worst <= 0.5 * step * (1 + 1e-6), f"{path}: {worst:.3g} m from the plain bake, more than step/2 = {step / 2:.3g}")
        return step, worst, d.dtype


def check_mdd(f, path):
    data = open(path, "rb").read()
    frames, points = struct.unpack(">ii", data[:8])
    positions = f["frames/positions"]
    check((frames, points) == positions.shape[:2], f"{path}: header {frames} frames {points} points")
    times = np.frombuffer(data, ">f4", frames, 8)
    check(np.array_equal(times, f["frames/time"][()].astype(np.float32)), f"{path}: times != /frames/time")
    cache = np.frombuffer(data, ">f4", frames * points * 3, 8 + 4 * frames).reshape(frames, points, 3)
    check(np.array_equal(cache, positions[()]), f"{path}: frames != /frames/positions")
    check(len(data) == 8 + 4 * frames + 12 * frames * points, f"{path}: {len(data)} bytes")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("plain")
    parser.add_argument("--quantized", required=True)
    parser.add_argument("--mdd", required=True)
    parser.add_argument("--obj", required=True)
    parser.add_argument("--glb", required=True)
    args = parser.parse_args()
    with h5py.File(args.plain, "r") as f:
        normal_error = check_normals(f, args)
        obj_frames = check_obj_normals(f, args.obj)
        glb_frames = check_glb_normals(f, args.glb)
        step, quantized_error, dtype = check_quantized(f, args.quantized)
        check_mdd(f, args.mdd)
    for failure in failures:
        print(f"check_bake_options: {failure}")
    print(f"check_bake_options: {'FAILED' if failures else 'ok'}: normals within {normal_error:.3g} of the "
          f"recomputed ones ({obj_frames} OBJ and {glb_frames} GLB frames equal); quantized {dtype} at step "
          f"{step} m within {quantized_error:.3g} m; MDD equal to the bake")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
