"""Checks that glTF/GLB files written by `mocap convert` import into
Blender's own glTF importer with the right bones, frame range and joint
positions.

Run by Blender, not by Python (see tests/gltf/run.sh, which also makes the
positions):

    blender --background --factory-startup --python-exit-code 1 \
        --python tests/blender/check_gltf.py -- \
        take.glb take.positions.json [other.gltf other.positions.json ...] \
        [--tolerance 0.001] [--report out.json]

Each glTF file comes with the global joint positions that mocap computes
for the take it was converted from (`mocap positions --json`), in the
take's own units. The glTF is in metres, as the format requires, and the
converter records the take's units in the file (asset extras); the script
reads them from the file so that a wrong scale shows as an error. For each
file it imports with `bpy.ops.import_scene.gltf`, counts the armature's
bones, reads the frame range of the imported action (the importer puts
time t at frame t * scene fps, so the scene's fps is set to the take's
first), and at frames 0, middle and last compares the world position of
every bone head with our position of the joint of the same name, turned
from glTF's Y-up into Blender's Z-up as the importer does ((x, y, z) ->
(x, -z, y)). A file passes when every joint became a bone, the frame range
holds every frame and the largest distance is within `tolerance` metres
(1 mm by default).
"""

import json
import os
import struct
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from harness import run_checks  # noqa: E402


def work_around_numpy_bool():
    """Blender 3.4's glTF importer uses `numpy.bool`, which numpy 1.24
    removed (it was only an alias of Python's bool): with Debian 12's
    blender and python3-numpy (1.24) every skinned import fails with
    "module 'numpy' has no attribute 'bool'". The alias is put back before
    the importer runs; newer Blenders use `bool` and are not affected."""
    import numpy

    if not hasattr(numpy, "bool"):
        numpy.bool = bool


def gltf_json(path):
    """The glTF JSON of a .gltf file or of a .glb's first chunk."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] == b"glTF":
        length, kind = struct.unpack_from("<II", data, 12)
        if kind != 0x4E4F534A:  # "JSON"
            raise ValueError(f"{path}: the first GLB chunk is not JSON")
        return json.loads(data[20:20 + length].decode("utf-8"))
    return json.loads(data.decode("utf-8"))


def units_per_metre(document):
    """The take's units per metre as the converter recorded them."""
    extras = document.get("asset", {}).get("extras", {}) or {}
    mocap = extras.get("mocap", extras)
    value = mocap.get("units_per_metre")
    if value is None:
        raise ValueError("the file does not record the take's units (asset.extras.mocap.units_per_metre)")
    return float(value)


def check(path, positions_path, tolerance):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    with open(positions_path) as f:
        ours = json.load(f)
    names = ours["joints"]
    frames = ours["positions"]
    result = {"file": path, "joints": len(names), "frames": len(frames)}
    document = gltf_json(path)
    scale = 1.0 / units_per_metre(document)
    result["metres_per_unit"] = scale
    fps = ours.get("fps")
    if fps is None:
        fps = 1.0 / ours["frame_time"]
    scene = bpy.context.scene
    scene.render.fps = int(round(fps))
    scene.render.fps_base = 1.0
    try:
        bpy.ops.import_scene.gltf(filepath=path)
    except Exception as e:  # the importer's own error, reported as such
        result.update(imported=False, error=str(e), passed=False)
        return result
    armatures = [o for o in scene.objects if o.type == "ARMATURE"]
    meshes = [o for o in scene.objects if o.type == "MESH"]
    result["meshes"] = len(meshes)
    if not armatures:
        result.update(imported=False, error="no armature was created", passed=False)
        return result
    arm = armatures[0]
    bones = arm.pose.bones
    result["imported"] = True
    result["bones"] = len(bones)
    missing = [n for n in names if n not in bones]
    result["missing_joints"] = missing
    action = arm.animation_data.action if arm.animation_data else None
    if action is None:
        result.update(error="no animation was imported", passed=False)
        return result
    start, end = action.frame_range
    result["frame_range"] = [start, end]
    blender_frames = int(round(end - start)) + 1
    result["blender_frames"] = blender_frames
    if missing or blender_frames != len(frames) or bones is None:
        result["passed"] = False
        return result

    checked = sorted({0, len(frames) // 2, len(frames) - 1})
    worst = 0.0
    worst_at = None
    for k in checked:
        scene.frame_set(int(round(start)) + k)
        bpy.context.view_layer.update()
        expected = frames[k]
        for j, name in enumerate(names):
            head = arm.matrix_world @ bones[name].head
            x, y, z = (c * scale for c in expected[j])
            want = (x, -z, y)
            d = sum((head[i] - want[i]) ** 2 for i in range(3)) ** 0.5
            if d > worst:
                worst = d
                worst_at = {"frame": k, "joint": name}
    result["checked_frames"] = checked
    result["max_error_m"] = worst
    result["max_error_at"] = worst_at
    result["passed"] = worst <= tolerance
    return result


def main():
    work_around_numpy_bool()
    run_checks(check, "glTF", "BLENDER-GLTF")


main()
