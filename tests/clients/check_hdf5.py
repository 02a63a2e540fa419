#!/usr/bin/python3
"""Checks a treeanim HDF5 bake against the format_version 1 layout of docs/design.md with h5py:
every root attribute, every dataset's shape, dtype and chunking, the index ranges, and,
with --obj, that frame k of the bake equals the OBJ of frame k (bit for bit, float32);
with --pc2, that the PC2 samples equal the bake's frames.

Usage: /usr/bin/python3 check_hdf5.py BAKE.h5 [--obj PREFIX] [--pc2 FILE.pc2]
       [--velocities yes|no] [--compression N]
PREFIX names the OBJ sequence as the output path did ("obj/tree" => obj/tree.%04d.obj).
Exit 0 when everything holds, 1 with one line per failure otherwise."""
import argparse
import json
import struct
import sys

import h5py
import numpy as np

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)
    return condition


def expect_dataset(f, name, dtype, shape):
    if not check(name in f, f"{name}: missing"):
        return None
    d = f[name]
    check(d.dtype == np.dtype(dtype), f"{name}: dtype {d.dtype}, expected {np.dtype(dtype)}")
    check(d.shape == tuple(shape), f"{name}: shape {d.shape}, expected {tuple(shape)}")
    return d[()]


def read_obj(path, materials=None):
    """positions, UVs, faces; and the usemtl name of each face appended to `materials` when given."""
    positions, uvs, faces = [], [], []
    material = None
    with open(path) as lines:
        for line in lines:
            fields = line.split()
            if not fields:
                continue
            if fields[0] == "usemtl":
                material = fields[1]
            elif fields[0] == "v":
                positions.append([np.float32(x) for x in fields[1:4]])
            elif fields[0] == "vt":
                uvs.append([float(x) for x in fields[1:3]])
            elif fields[0] == "f":
                faces.append([int(c.split("/")[0]) - 1 for c in fields[1:4]])
                if materials is not None:
                    materials.append(material)
    return np.array(positions, np.float32), np.array(uvs), np.array(faces, np.uint32)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("bake")
    parser.add_argument("--obj")
    parser.add_argument("--pc2")
    parser.add_argument("--velocities", choices=["yes", "no"])
    parser.add_argument("--compression", type=int)
    args = parser.parse_args()

    f = h5py.File(args.bake, "r")
    # Root attributes: name => (numpy kind, exact value or None).
    attributes = {"format": (str, "treeanim"), "format_version": (np.int32, 1), "generator": (str, None),
                  "fps": (np.float64, None), "frame_start": (np.int64, None), "substeps": (np.int32, None),
                  "units": (str, "m"), "up_axis": (str, "Y"), "seed": (np.uint64, None)}
    check(set(f.attrs.keys()) == set(attributes), f"root attributes {sorted(f.attrs.keys())}")
    for name, (kind, value) in attributes.items():
        if not check(name in f.attrs, f"attribute {name}: missing"):
            continue
        a = f.attrs[name]
        if kind is str:
            check(isinstance(a, str), f"attribute {name}: {type(a)}, expected a variable-length string")
        else:
            check(a.dtype == np.dtype(kind), f"attribute {name}: dtype {a.dtype}, expected {np.dtype(kind)}")
        if value is not None:
            check(a == value, f"attribute {name}: {a!r}, expected {value!r}")
    check(f.attrs["generator"].startswith("treeanim"), "attribute generator: does not name treeanim")
    check(f.attrs["fps"] > 0 and f.attrs["substeps"] >= 1, "attributes fps/substeps out of range")

    scene = f["scene"]
    check(scene.shape == () and h5py.check_string_dtype(scene.dtype) is not None, "/scene: not a scalar string")
    json.loads(scene[()].decode("utf-8"))  # the resolved scene must parse

    rest = f["mesh/rest_positions"]
    n = rest.shape[0]
    rest = expect_dataset(f, "mesh/rest_positions", np.float32, (n, 3))
    t = f["mesh/triangles"].shape[0]
    triangles = expect_dataset(f, "mesh/triangles", np.uint32, (t, 3))
    check(t == 0 or triangles.max() < n, "/mesh/triangles: vertex id out of range")
    material = expect_dataset(f, "mesh/triangle_material", np.uint8, (t,))
    mass = expect_dataset(f, "model/mass", np.float64, (n,))
    check(np.all(mass > 0), "/model/mass: a vertex without mass")
    anchored = expect_dataset(f, "model/anchored", np.uint8, (n,))
    check(set(np.unique(anchored)) <= {0, 1}, "/model/anchored: values other than 0/1")
    c = f["model/cluster_kind"].shape[0]
    offsets = expect_dataset(f, "model/cluster_offsets", np.uint32, (c + 1,))
    members = expect_dataset(f, "model/cluster_members", np.uint32, (int(offsets[-1]),))
    kind = expect_dataset(f, "model/cluster_kind", np.uint8, (c,))
    check(offsets[0] == 0 and np.all(np.diff(offsets.astype(np.int64)) > 0), "/model/cluster_offsets: not increasing")
    check(members.size == 0 or members.max() < n, "/model/cluster_members: vertex id out of range")
    check(set(np.unique(kind)) <= {0, 1}, "/model/cluster_kind: values other than 0/1")
    # A leaf's triangles are the ones whose three vertices all belong to leaf clusters (bark
    # vertices never do), and they are leaf material: the model's count of each.
    on_leaf = np.zeros(n, bool)
    for k in np.flatnonzero(kind == 1):
        on_leaf[members[offsets[k]:offsets[k + 1]]] = True
    leaf_triangles = on_leaf[triangles].all(axis=1)
    check(np.array_equal(material, leaf_triangles.astype(np.uint8)),
          f"/mesh/triangle_material: {np.count_nonzero(material == 0)} bark and {np.count_nonzero(material == 1)} leaf "
          f"triangles, the model has {np.count_nonzero(~leaf_triangles)} and {np.count_nonzero(leaf_triangles)}")
    check(np.count_nonzero(material == 0) > 0 and np.count_nonzero(material == 1) > 0,
          "/mesh/triangle_material: the tree lacks bark or leaf triangles")
    s = f["skeleton/segment_parent"].shape[0]
    expect_dataset(f, "skeleton/segment_start", np.float32, (s, 3))
    expect_dataset(f, "skeleton/segment_end", np.float32, (s, 3))
    radius = expect_dataset(f, "skeleton/segment_radius", np.float32, (s, 2))
    check(np.all(radius >= 0), "/skeleton/segment_radius: negative")
    parent = expect_dataset(f, "skeleton/segment_parent", np.int32, (s,))
    check(np.all(parent < np.arange(s)) and np.all(parent >= -1), "/skeleton/segment_parent: not parents-first")
    cluster = expect_dataset(f, "skeleton/segment_cluster", np.uint32, (s,))
    check(s == 0 or cluster.max() < c, "/skeleton/segment_cluster: cluster id out of range")

    frames = f["frames/time"].shape[0]
    time = expect_dataset(f, "frames/time", np.float64, (frames,))
    check(frames == 0 or np.all(np.diff(time) > 0), "/frames/time: not increasing")
    positions = f["frames/positions"]
    check(positions.dtype == np.float32 and positions.shape == (frames, n, 3), f"/frames/positions: {positions.dtype} {positions.shape}")
    check(positions.chunks == (1, n, 3), f"/frames/positions: chunks {positions.chunks}, expected one frame")
    check(positions.maxshape == (None, n, 3), f"/frames/positions: maxshape {positions.maxshape}, expected extendible")
    check(np.all(np.isfinite(positions[()])), "/frames/positions: non-finite values")
    if args.compression is not None:
        expected = ("gzip", args.compression) if args.compression > 0 else (None, None)
        check((positions.compression, positions.compression_opts) == expected,
              f"/frames/positions: compression {positions.compression} {positions.compression_opts}")
        check(positions.shuffle == (args.compression > 0), "/frames/positions: shuffle filter")
    expected_groups = {"frames": {"time", "positions"}, "mesh": {"rest_positions", "triangles", "triangle_material"},
                       "model": {"mass", "anchored", "cluster_offsets", "cluster_members", "cluster_kind"},
                       "skeleton": {"segment_start", "segment_end", "segment_radius", "segment_parent", "segment_cluster"}}
    if args.velocities == "yes" or (args.velocities is None and "velocities" in f["frames"]):
        velocities = f["frames/velocities"]
        check(velocities.dtype == np.float32 and velocities.shape == (frames, n, 3) and velocities.chunks == (1, n, 3),
              f"/frames/velocities: {velocities.dtype} {velocities.shape} {velocities.chunks}")
        expected_groups["frames"].add("velocities")
    leaves = int(np.count_nonzero(kind == 1))
    if leaves > 0:
        expect_dataset(f, "frames/leaf_attached", np.uint8, (frames, leaves))
        expected_groups["frames"].add("leaf_attached")
    check(set(f.keys()) == set(expected_groups) | {"scene"}, f"root members {sorted(f.keys())}")
    for group, names in expected_groups.items():
        check(set(f[group].keys()) == names, f"/{group} members {sorted(f[group].keys())}, expected {sorted(names)}")

    frame_index = np.rint(time * f.attrs["fps"]).astype(np.int64)
    # Each frame at its own time, frame x (1 / fps) (a sum of steps drifted 1.5e-11 s by frame 8191).
    check(np.array_equal(time, frame_index * (1.0 / f.attrs["fps"])), "/frames/time is not frame x (1 / fps)")
    check(frames == 0 or frame_index[0] == f.attrs["frame_start"], "/frames/time does not start at frame_start")
    compared = 0
    if args.obj:
        obj_materials = []
        obj_rest, obj_uv, obj_faces = read_obj(f"{args.obj}.rest.obj", obj_materials)
        check(np.array_equal(obj_rest, rest), "rest OBJ != /mesh/rest_positions")
        check(np.array_equal(obj_faces, triangles), "rest OBJ faces != /mesh/triangles")
        check(obj_materials == [("bark", "leaf")[m] for m in material], "rest OBJ usemtl != /mesh/triangle_material")
        for k, index in enumerate(frame_index):
            try:
                obj_positions, _, obj_faces = read_obj(f"{args.obj}.{index:04d}.obj")
            except FileNotFoundError:
                continue  # the OBJ output may write every k-th frame only
            compared += 1
            check(np.array_equal(obj_positions, positions[k]), f"frame {index}: OBJ != /frames/positions[{k}]")
            check(np.array_equal(obj_faces, triangles), f"frame {index}: OBJ faces differ")
        check(compared > 0, f"no OBJ frame {args.obj}.NNNN.obj matches a bake frame")
    if args.pc2:
        data = open(args.pc2, "rb").read()
        signature, version, points, start, rate, samples = struct.unpack("<12siiffi", data[:32])
        check(signature == b"POINTCACHE2\0" and version == 1 and points == n, f"{args.pc2}: header {signature} {version} {points}")
        cache = np.frombuffer(data[32:], "<f4").reshape(samples, points, 3)
        for k, index in enumerate(frame_index):
            sample = (index - start) / rate
            if sample == int(sample) and 0 <= sample < samples:
                compared += 1
                check(np.array_equal(cache[int(sample)], positions[k]), f"frame {index}: PC2 != /frames/positions[{k}]")
    for failure in failures:
        print(f"{args.bake}: {failure}")
    print(f"{args.bake}: {'FAILED' if failures else 'ok'}: {n} vertices, {t} triangles, {c} clusters, "
          f"{s} segments, {frames} frames; {compared} frames compared with OBJ/PC2")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
