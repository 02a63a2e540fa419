#!/usr/bin/python3
"""Writes velocity volume sequences as the tools that make them lay them out, with the OpenVDB
library itself (python3-openvdb), from an analytic flow, for the tests and configs/ examples.

  write_volumes.py FLOW LAYOUT OUT_DIR [--frames A B] [--fps F] [options]

FLOW (velocity in m/s at a Y-up scene point x, y, z and time t):
  uniform   (u, v, w) everywhere                       --velocity U V W
  shear     (a + b y, 0, 0): speed growing with height  --base A --rate B
  gust      a gust front moving along +x at --front-speed C from x = --front-start:
            U (1 + tanh((x_f(t) - x) / W)) / 2 along x, x_f(t) = start + C t, W = --width
  steps     (U + k, 0, 0) in frame k: linear in time between frames  --velocity U 0 0
LAYOUT:
  houdini   vel.####.vdb, a vec3s grid 'vel', Y-up
  split     vel.####.vdb, float grids 'vel.x', 'vel.y', 'vel.z', Y-up (Houdini's split vel)
  blender   fluid_data_####.vdb, a vec3s grid 'velocity' among others, Z-up, the domain's
            voxel transform (a scale and an offset)
Frame F blows at time (F - first) / fps; the box of voxels covers --lower .. --upper (scene
metres, Y-up) at --voxel metres.
"""
import argparse
import math
import os

import numpy as np
import pyopenvdb as vdb


def flow(args, x, y, z, t, frame_index):
    """Scene-space (Y-up) velocity arrays at points x, y, z (arrays) and time t."""
    zero = np.zeros_like(x)
    if args.flow == "uniform":
        return zero + args.velocity[0], zero + args.velocity[1], zero + args.velocity[2]
    if args.flow == "shear":
        return args.base + args.rate * y, zero, zero
    if args.flow == "gust":
        front = args.front_start + args.front_speed * t
        return args.speed * 0.5 * (1 + np.tanh((front - x) / args.width)), zero, zero
    if args.flow == "steps":
        return zero + args.velocity[0] + frame_index, zero + args.velocity[1], zero + args.velocity[2]
    raise SystemExit(f"unknown flow {args.flow}")


def write_frame(args, frame, path):
    t = (frame - args.first) / args.fps
    voxel = args.voxel
    lower = np.array(args.lower, dtype=float)
    counts = [int(round((args.upper[k] - lower[k]) / voxel)) + 1 for k in range(3)]
    blender = args.layout == "blender"
    # Voxel (i, j, k) of the file's index space sits at origin + voxel * (i, j, k) in the file's
    # own space: Y-up for Houdini, Z-up for Blender, whose point (x, y, z) is the scene's (x, z, -y).
    if blender:
        # File axes: X = scene x, Y = -scene z, Z = scene y.
        origin = np.array([lower[0], -(lower[2] + voxel * (counts[2] - 1)), lower[1]])
        shape = (counts[0], counts[2], counts[1])
    else:
        origin = lower
        shape = tuple(counts)
    i, j, k = np.meshgrid(*[np.arange(n, dtype=float) for n in shape], indexing="ij")
    fx, fy, fz = origin[0] + voxel * i, origin[1] + voxel * j, origin[2] + voxel * k
    if blender:
        sx, sy, sz = fx, fz, -fy
    else:
        sx, sy, sz = fx, fy, fz
    u, v, w = flow(args, sx, sy, sz, t, frame - args.first)
    if args.nan_at is not None and frame == args.nan_at:
        u[shape[0] // 2, shape[1] // 2, shape[2] // 2] = float("nan")
    # Back into the file's axes: a Z-up file stores the scene's (u, v, w) as (u, -w, v).
    fu, fv, fw = (u, -w, v) if blender else (u, v, w)
    transform = vdb.createLinearTransform(voxelSize=voxel)
    transform.translate(tuple(origin))
    grids = []
    # A negative tolerance keeps every voxel active, calm ones too: the box is the volume.
    if args.layout == "split":
        for name, values in (("x", fu), ("y", fv), ("z", fw)):
            grid = vdb.FloatGrid()
            grid.copyFromArray(values.astype(np.float32), ijk=(0, 0, 0), tolerance=-1)
            grid.transform = transform
            grid.name = f"{args.grid}.{name}"
            grids.append(grid)
    else:
        grid = vdb.Vec3SGrid()
        grid.copyFromArray(np.stack([fu, fv, fw], axis=-1).astype(np.float32), ijk=(0, 0, 0), tolerance=(-1, -1, -1))
        grid.transform = transform
        grid.name = args.grid
        grids.append(grid)
        if blender:  # Blender's cache holds the smoke's other grids beside the velocity
            density = vdb.FloatGrid()
            density.copyFromArray(np.ones(shape, dtype=np.float32), ijk=(0, 0, 0))
            density.transform = transform
            density.name = "density"
            grids.insert(0, density)
    vdb.write(path, grids=grids)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("flow", choices=["uniform", "shear", "gust", "steps"])
    parser.add_argument("layout", choices=["houdini", "split", "blender"])
    parser.add_argument("out_dir")
    parser.add_argument("--frames", type=int, nargs=2, default=[1, 2])
    parser.add_argument("--first", type=int, default=1, help="the frame at time 0")
    parser.add_argument("--fps", type=float, default=24)
    parser.add_argument("--lower", type=float, nargs=3, default=[-4, 0, -4])
    parser.add_argument("--upper", type=float, nargs=3, default=[4, 8, 4])
    parser.add_argument("--voxel", type=float, default=0.5)
    parser.add_argument("--velocity", type=float, nargs=3, default=[8, 0, 0])
    parser.add_argument("--base", type=float, default=2)
    parser.add_argument("--rate", type=float, default=1.5)
    parser.add_argument("--speed", type=float, default=12)
    parser.add_argument("--front-start", type=float, default=-10)
    parser.add_argument("--front-speed", type=float, default=10)
    parser.add_argument("--width", type=float, default=1)
    parser.add_argument("--grid", default=None, help="default: vel, or velocity for blender")
    parser.add_argument("--nan-at", type=int, default=None, help="a NaN in the middle of this frame")
    args = parser.parse_args()
    if args.grid is None:
        args.grid = "velocity" if args.layout == "blender" else "vel"
    os.makedirs(args.out_dir, exist_ok=True)
    stem = "fluid_data_" if args.layout == "blender" else "vel."
    for frame in range(args.frames[0], args.frames[1] + 1):
        write_frame(args, frame, os.path.join(args.out_dir, f"{stem}{frame:04d}.vdb"))


if __name__ == "__main__":
    main()
