#!/usr/bin/python3
"""Checks a seamless loop (time.loop) with h5py and numpy: the HDF5 bake's frames are one period
at the loop's own times (frame k at k / fps), the step from the last frame back to the first
(the seam) is at most twice the median step between neighbouring frames (RMS over vertices),
and the animated GLB closes the loop: one key more, at the loop's end, that shows frame 0 again;
the VAT's JSON says "loop": true.

Usage: /usr/bin/python3 check_loop.py BAKE.h5 ANIM.glb VAT.json
Exit 0 when everything holds, 1 with one line per failure otherwise."""
import json
import struct
import sys

import h5py
import numpy as np

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)


def rms(a, b):
    return float(np.sqrt(np.mean(np.sum((a.astype(np.float64) - b) ** 2, axis=1))))


def main():
    if len(sys.argv) != 4:
        print(__doc__)
        return 2
    bake_path, glb_path, vat_path = sys.argv[1:]
    with h5py.File(bake_path, "r") as f:
        fps = f.attrs["fps"]
        time = f["frames/time"][()]
        positions = f["frames/positions"]
        frames = len(time)
        start = f.attrs["frame_start"]
        check(np.allclose(time, (start + np.arange(frames)) / fps, rtol=0, atol=1e-12),
              f"{bake_path}: frame times are not k / fps: {time[:3]} ...")
        steps = [rms(positions[k + 1], positions[k]) for k in range(frames - 1)]
        seam = rms(positions[0], positions[frames - 1])
        median = float(np.median(steps))
        check(seam <= 2 * median, f"{bake_path}: seam {seam:.4g} m, more than twice the median step {median:.4g} m")

    data = open(glb_path, "rb").read()
    length = struct.unpack("<I", data[12:16])[0]
    document = json.loads(data[20:20 + length])
    binary = data[20 + length + 8:]
    sampler = document["animations"][0]["samplers"][0]

    def values(index):
        a = document["accessors"][index]
        view = document["bufferViews"][a["bufferView"]]
        return np.frombuffer(binary, "<f4", a["count"], view.get("byteOffset", 0) + a.get("byteOffset", 0))

    keys = values(sampler["input"])
    weights = values(sampler["output"]).reshape(len(keys), -1)
    check(len(keys) == frames + 1, f"{glb_path}: {len(keys)} keys for a loop of {frames} frames")
    check(abs(keys[-1] - (start + frames) / fps) < 1e-6, f"{glb_path}: the closing key is at {keys[-1]} s")
    check(np.array_equal(weights[-1], weights[0]), f"{glb_path}: the closing key does not show frame 0")

    with open(vat_path) as f:
        check(json.load(f)["loop"] is True, f"{vat_path}: loop is not true")
    for failure in failures:
        print(f"check_loop: {failure}")
    print(f"check_loop: {'FAILED' if failures else 'ok'}: {frames} frames, seam {seam:.4g} m = "
          f"{seam / median:.2f} x the median frame step {median:.4g} m")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
