"""Blender 3.4 (headless) reads treeanim's outputs as an artist would, and gets the bake back:

1. imports the animated GLB (import_shading='SMOOTH': Blender 3.4's default path hits a numpy
   error) and checks every shape key against the HDF5 frame it stands for, to 1e-5 m;
2. imports each point cache's rest OBJ (PC2, and MDD when given), adds a Mesh Cache modifier
   reading the cache, and checks the evaluated vertices at several frames against the HDF5
   frames, to 1e-5 m;
3. both: the mesh has the materials bark and leaf, its faces as many of each as
   /mesh/triangle_material says (the OBJ's face by face).

Usage: blender -b --factory-startup --python check_blender.py -- BAKE.h5 ANIM.glb CACHE.pc2 REST.obj
       [CACHE.mdd REST.obj]
Exit 0 when everything holds, 1 otherwise. Runs with Blender's Python (h5py from python3-h5py)."""
import sys

import bpy
import h5py
import numpy as np

TOLERANCE = 1e-5  # m; float32 rest + displacement rounds at about 1e-7 relative

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)


def clear_scene():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)


def only_mesh_object():
    meshes = [o for o in bpy.data.objects if o.type == 'MESH']
    check(len(meshes) == 1, f"expected one mesh object, got {len(meshes)}")
    return meshes[0]


def coordinates(vertices):
    co = np.empty(3 * len(vertices))
    vertices.foreach_get("co", co)
    return co.reshape(-1, 3)


def y_up(blender_co):
    # Blender's glTF importer turns glTF's Y-up (x, y, z) into Blender's Z-up (x, -z, y).
    return np.stack([blender_co[:, 0], blender_co[:, 2], -blender_co[:, 1]], axis=1)


def check_materials(path, obj, bake, face_by_face):
    # Blender suffixes a material name it already has (".001") when a later file brings it again.
    names = [m.name.split(".")[0] for m in obj.data.materials]
    check(names == ["bark", "leaf"], f"{path}: materials {names}, expected ['bark', 'leaf']")
    index = np.empty(len(obj.data.polygons), np.int64)
    obj.data.polygons.foreach_get("material_index", index)
    expected = bake["mesh/triangle_material"][()].astype(np.int64)
    counts, expected_counts = np.bincount(index, minlength=2), np.bincount(expected, minlength=2)
    check(np.array_equal(counts, expected_counts),
          f"{path}: {counts.tolist()} bark and leaf faces in Blender, {expected_counts.tolist()} in the bake")
    if face_by_face:
        check(np.array_equal(index, expected), f"{path}: face materials differ from /mesh/triangle_material")


def check_animated_glb(path, bake):
    clear_scene()
    fps = bake.attrs["fps"]
    bpy.context.scene.render.fps = int(round(fps))  # the importer converts seconds to frames with it
    bpy.context.scene.render.fps_base = round(fps) / fps
    bpy.ops.import_scene.gltf(filepath=path, import_shading='SMOOTH')
    obj = only_mesh_object()
    check_materials(path, obj, bake, face_by_face=False)
    # The importer keeps the vertices some triangle uses, in ascending id order (a primitive per
    # material: the bark's vertices, then the leaves', which come after them in the model).
    used = np.unique(bake["mesh/triangles"][()])
    check(len(obj.data.vertices) == len(used),
          f"{path}: {len(obj.data.vertices)} vertices in Blender, {len(used)} used in the bake")
    keys = obj.data.shape_keys.key_blocks
    time = bake["frames/time"][()]
    check(len(keys) == 1 + len(time), f"{path}: {len(keys) - 1} shape keys for {len(time)} frames")
    worst = 0.0
    for k in range(min(len(time), len(keys) - 1)):
        key = keys[1 + k]
        index = int(round(time[k] * fps))
        check(key.name == f"frame_{index:04d}", f"{path}: shape key {key.name} for frame {index}")
        error = np.abs(y_up(coordinates(key.data)) - bake["frames/positions"][k][used]).max()
        worst = max(worst, error)
        check(error <= TOLERANCE, f"{path}: shape key {key.name} differs from the bake by {error:.3g} m")
    # The weights animation turns on exactly frame k's key at frame k.
    for k in sorted({0, len(time) // 2, len(time) - 1}):
        index = int(round(time[k] * fps))
        bpy.context.scene.frame_set(index)
        values = np.array([key.value for key in keys[1:]])
        check(abs(values[k] - 1) < 1e-6 and abs(values.sum() - 1) < 1e-6,
              f"{path}: at frame {index} the shape key weights are {values.round(3).tolist()}")
    return worst


def check_mesh_cache(cache, rest_obj, bake):
    clear_scene()
    # Axes as in the file (no Y-up => Z-up turn), so the cache's coordinates apply unchanged.
    bpy.ops.wm.obj_import(filepath=rest_obj, forward_axis='Y', up_axis='Z')
    obj = only_mesh_object()
    check_materials(rest_obj, obj, bake, face_by_face=True)
    rest = bake["mesh/rest_positions"][()]
    check(len(obj.data.vertices) == len(rest), f"{rest_obj}: {len(obj.data.vertices)} vertices in Blender, "
          f"{len(rest)} in the bake (Blender drops vertices no face uses)")
    if len(obj.data.vertices) != len(rest):
        return 0.0, []  # Mesh Cache needs equal counts; reported above
    check(np.abs(coordinates(obj.data.vertices) - rest).max() <= TOLERANCE, f"{rest_obj}: rest pose differs")
    modifier = obj.modifiers.new("cache", 'MESH_CACHE')
    modifier.cache_format = 'MDD' if cache.endswith(".mdd") else 'PC2'
    modifier.filepath = cache
    # Mesh Cache in FRAME mode plays sample (scene frame - frame_start): sample 0 is the bake's
    # frame_start (the PC2 header says so too).
    start = int(bake.attrs["frame_start"])
    modifier.frame_start = start
    time = bake["frames/time"][()]
    fps = bake.attrs["fps"]
    frames = [int(round(t * fps)) for t in time]
    checked = sorted({0, len(frames) // 2, len(frames) - 1})
    worst = 0.0
    for k in checked:
        bpy.context.scene.frame_set(frames[k])
        evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
        co = coordinates(evaluated.data.vertices)
        error = np.abs(co - bake["frames/positions"][k]).max()
        worst = max(worst, error)
        check(error <= TOLERANCE, f"{cache}: frame {frames[k]} through Mesh Cache differs from the bake by {error:.3g} m")
    check(len(checked) > 0, f"{cache}: no frame checked")
    return worst, [frames[k] for k in checked]


def main():
    argv = sys.argv[sys.argv.index("--") + 1:]
    if len(argv) not in (4, 6):
        print(__doc__)
        return 2
    bake_path, glb = argv[:2]
    caches = list(zip(argv[2::2], argv[3::2]))
    summary = []
    with h5py.File(bake_path, "r") as bake:
        glb_error = check_animated_glb(glb, bake)
        for cache, rest_obj in caches:
            cache_error, frames = check_mesh_cache(cache, rest_obj, bake)
            summary.append(f"{cache.rsplit('.', 1)[-1].upper()} at frames {frames} within {cache_error:.3g} m")
    for failure in failures:
        print(f"check_blender: {failure}")
    print(f"check_blender: {'FAILED' if failures else 'ok'}: shape keys within {glb_error:.3g} m, "
          f"Mesh Cache: {'; '.join(summary)}")
    return 1 if failures else 0


if __name__ == "__main__":
    code = main()
    sys.stdout.flush()
    # Blender ignores a script's exit status unless it leaves itself.
    import os
    os._exit(code)
