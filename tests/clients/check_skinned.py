"""Blender 3.4 (headless) imports treeanim's skinned GLB as an engine artist would and checks that
its evaluated vertices (the armature deforming the mesh) at several frames are as far from the
HDF5 bake as the file claims: the RMS error over the vertices at each checked frame equals the
asset's extras ("skinning") `frame_rms_error_m` within TOLERANCE, and no vertex is farther than `largest_error_m`
(+ TOLERANCE).

With --exact (a bake on samples, whose keys are the solver's own cluster motions), every vertex
but the anchored ones must also be within TOLERANCE of the bake in Blender at every checked frame:
float rounding, not a fit. (An anchored vertex stays at rest in the bake while its cluster turns
about it; a skin moves it with its joint.)

Usage: blender -b --factory-startup --python check_skinned.py -- [--exact] BAKE.h5 SKINNED.glb [SKINNED.glb ...]
Exit 0 when everything holds, 1 otherwise."""
import json
import os
import struct
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_bake_check  # noqa: E402
from blender_bake_check import check  # noqa: E402

TOLERANCE = 2e-5  # m: float32 keys, Blender's bone-space conversions and its float evaluation
exact = "--exact" in sys.argv
if exact:
    sys.argv.remove("--exact")

def skin_extras(path):
    data = open(path, "rb").read()
    length = struct.unpack("<I", data[12:16])[0]
    return json.loads(data[20:20 + length])["asset"]["extras"]["skinning"]


def evaluated_y_up(obj):
    mesh = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
    co = np.empty(3 * len(mesh.vertices))
    mesh.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3) @ np.array(obj.matrix_world)[:3, :3].T + np.array(obj.matrix_world)[:3, 3]
    return np.stack([co[:, 0], co[:, 2], -co[:, 1]], axis=1)  # Blender's Z-up back to glTF's Y-up


def check_file(path, bake):
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    fps = bake.attrs["fps"]
    bpy.context.scene.render.fps = int(round(fps))
    bpy.context.scene.render.fps_base = round(fps) / fps
    bpy.ops.import_scene.gltf(filepath=path, import_shading='SMOOTH')
    extras = skin_extras(path)
    meshes = [o for o in bpy.data.objects if o.type == 'MESH']
    armatures = [o for o in bpy.data.objects if o.type == 'ARMATURE']
    check(len(meshes) == 1 and len(armatures) == 1, f"{path}: {len(meshes)} meshes, {len(armatures)} armatures")
    obj = meshes[0]
    n = bake["mesh/rest_positions"].shape[0]
    check(len(obj.data.vertices) == n, f"{path}: {len(obj.data.vertices)} vertices in Blender, {n} in the bake")
    time = bake["frames/time"][()]
    claimed = extras["frame_rms_error_m"]
    check(len(claimed) == len(time), f"{path}: {len(claimed)} frame errors for {len(time)} frames")
    worst_difference = 0.0
    checked = sorted({1, len(time) // 3, len(time) // 2, len(time) - 1})
    for k in checked:
        bpy.context.scene.frame_set(int(round(time[k] * fps)))
        error = np.linalg.norm(evaluated_y_up(obj) - bake["frames/positions"][k], axis=1)
        rms = float(np.sqrt(np.mean(error ** 2)))
        difference = abs(rms - claimed[k])
        worst_difference = max(worst_difference, difference)
        check(difference <= TOLERANCE, f"{path}: frame {k}: RMS error {rms:.6g} m in Blender, the file claims "
              f"{claimed[k]:.6g} m")
        if exact:
            free = bake["model/anchored"][()] == 0
            check(error[free].max() <= TOLERANCE, f"{path}: frame {k}: a vertex not anchored {error[free].max():.3g} m "
                  f"off the bake; the solver's own motions should reproduce it within {TOLERANCE:g} m")
        check(error.max() <= extras["largest_error_m"] + TOLERANCE,
              f"{path}: frame {k}: a vertex {error.max():.4g} m off, the file claims at most {extras['largest_error_m']:.4g}")
    return (f"{os.path.basename(path)}: {len(armatures[0].data.bones) if armatures else 0} bones, RMS error "
            f"{100 * extras['skinning_error_rms']:.2f} % (Blender within {worst_difference:.2g} m of the claim at "
            f"frames {checked})")


if __name__ == "__main__":
    blender_bake_check.run("check_skinned", __doc__, check_file)
