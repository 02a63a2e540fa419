#!/usr/bin/python3
"""An HDF5 bake's frames for the Node checks: BAKE.h5 OUT => OUT.json (frame indices, times,
vertex count, fps, the rest positions, the triangles' and leaf triangles' counts, the
scene's sRGB bark and leaf colours) and OUT.f32 (every frame's float32
positions, F x N x 3, little-endian), read with h5py so the reference is the HDF5 file itself."""
import json
import sys

import h5py
import numpy as np

bake, out = sys.argv[1], sys.argv[2]
with h5py.File(bake, "r") as f:
    positions = f["frames/positions"][()].astype("<f4")
    times = f["frames/time"][()]
    fps = float(f.attrs["fps"])
    start = int(f.attrs["frame_start"])
    rest = f["mesh/rest_positions"][()].astype("<f4")
    triangles = int(f["mesh/triangles"].shape[0])
    leaf_triangles = int((f["mesh/triangle_material"][()] == 1).sum())
    tree = json.loads(f["scene"][()])["tree"]
positions.tofile(out + ".f32")
rest.tofile(out + ".rest.f32")
frames = [int(round(t * fps)) for t in times]
assert frames[0] == start, (frames[0], start)
json.dump({"frames": frames, "times": times.tolist(), "vertices": int(rest.shape[0]), "fps": fps,
           "triangles": triangles, "leaf_triangles": leaf_triangles,
           "bark_color": tree["bark_color"], "leaf_color": tree["leaf_color"]}, open(out + ".json", "w"))
print(f"{bake}: {len(frames)} frames of {rest.shape[0]} vertices")
