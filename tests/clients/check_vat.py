"""Blender 3.4 (headless) reads treeanim's vertex animation textures as a game artist's tools
would, and gets the bake back:

1. loads STEM.positions.exr with bpy.data.images.load and, for every frame, rebuilds rest +
   texel (vertex v of frame f at column v % width, row f * rows_per_frame + v / width, row 0 the
   top of the image) and compares with the HDF5 bake's positions: within float32 rounding for
   float textures, within half-float rounding of the offsets for half textures;
2. loads STEM.normals.exr the same way: the normals of the bake (/frames/normals), to the
   texture's precision;
3. imports STEM.glb: its second UV map puts every vertex at the centre of its frame-0 texel.

Usage: blender -b --factory-startup --python check_vat.py -- BAKE.h5 STEM [STEM ...]
BAKE.h5 must hold /frames/normals. Exit 0 when everything holds, 1 otherwise."""
import json
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_bake_check  # noqa: E402
from blender_bake_check import check  # noqa: E402

def texture(path):
    """EXR => (height, width, 3) float array, row 0 the top of the image."""
    image = bpy.data.images.load(path, check_existing=False)
    image.colorspace_settings.name = 'Non-Color'  # raw values, no view transform
    width, height = image.size
    pixels = np.empty(width * height * 4, np.float32)
    image.pixels.foreach_get(pixels)
    return pixels.reshape(height, width, 4)[::-1, :, :3]  # Blender stores the bottom row first


def texels(image, layout, frame, count):
    """The (count, 3) texels of frame `frame`'s vertices."""
    v = np.arange(count)
    return image[frame * layout["rows_per_frame"] + v // layout["texture_width"], v % layout["texture_width"]]


def check_stem(stem, bake):
    with open(stem + ".json") as f:
        layout = json.load(f)
    positions = bake["frames/positions"]
    normals = bake["frames/normals"]
    frames, n = positions.shape[:2]
    check(layout["vertex_count"] == n and layout["frame_count"] == frames, f"{stem}.json: counts {layout}")
    rest = bake["mesh/rest_positions"][()]
    offsets = texture(stem + ".positions.exr")
    normal_texture = texture(stem + ".normals.exr")
    check(offsets.shape == (layout["texture_height"], layout["texture_width"], 3),
          f"{stem}.positions.exr: {offsets.shape[1]} x {offsets.shape[0]} texels, the JSON says "
          f"{layout['texture_width']} x {layout['texture_height']}")
    half = layout["precision"] == "half"
    worst_position = worst_normal = 0.0
    for k in range(frames):
        offset = texels(offsets, layout, k, n).astype(np.float64)
        truth = positions[k].astype(np.float64) - rest
        # half keeps 11 significant bits: 2^-11 of the offset, plus float32 rounding of rest + offset
        tolerance = (np.abs(truth) * 2.0 ** -11 if half else 0) + 1e-6
        error = np.abs(rest + offset - positions[k])
        worst_position = max(worst_position, float(error.max()))
        check(np.all(error <= tolerance), f"{stem}: frame {k} rebuilt from the texture is {error.max():.3g} m off")
        normal_error = np.abs(texels(normal_texture, layout, k, n) - normals[k]).max()
        worst_normal = max(worst_normal, float(normal_error))
        check(normal_error <= (1e-3 if half else 1e-7), f"{stem}: frame {k} normals are {normal_error:.3g} off")

    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    bpy.ops.import_scene.gltf(filepath=stem + ".glb", import_shading='SMOOTH')
    mesh = [o for o in bpy.data.objects if o.type == 'MESH'][0].data
    check(len(mesh.uv_layers) == 2, f"{stem}.glb: {len(mesh.uv_layers)} UV maps, expected 2")
    if len(mesh.uv_layers) == 2 and len(mesh.vertices) == n:
        uv = np.empty(2 * len(mesh.loops))
        mesh.uv_layers[1].data.foreach_get("uv", uv)
        vertex = np.empty(len(mesh.loops), np.int64)
        mesh.loops.foreach_get("vertex_index", vertex)
        uv = uv.reshape(-1, 2)
        column = uv[:, 0] * layout["texture_width"] - 0.5
        row = (1 - uv[:, 1]) * layout["texture_height"] - 0.5  # Blender flips glTF's v
        check(np.abs(column - vertex % layout["texture_width"]).max() < 1e-3 and
              np.abs(row - vertex // layout["texture_width"]).max() < 1e-3,
              f"{stem}.glb: the second UV map does not address each vertex's texel")
    else:
        check(False, f"{stem}.glb: {len(mesh.vertices)} vertices in Blender, {n} in the bake")
    return f"{os.path.basename(os.path.dirname(stem))}: {layout['precision']} {layout['texture_width']}x" \
           f"{layout['texture_height']}, positions within {worst_position:.3g} m, normals within {worst_normal:.3g}"


if __name__ == "__main__":
    blender_bake_check.run("check_vat", __doc__, check_stem)
