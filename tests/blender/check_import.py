"""Checks that BVH files import into Blender and that Blender's joints are
where mocap's forward kinematics puts them.

Run by Blender, not by Python (see run.sh, which also makes the positions):

    blender --background --factory-startup --python-exit-code 1 \
        --python tests/blender/check_import.py -- \
        take.bvh take.positions.json [other.bvh other.positions.json ...] \
        [--tolerance 1e-3] [--report out.json]

Each BVH file comes with the global joint positions that mocap computes for
it (`mocap positions take.bvh --json -o take.positions.json`). For each file
the script imports the BVH with Blender's own importer (io_anim_bvh, with the
axis conversion switched off so that Blender's world frame is the file's),
counts the armature's bones and animated frames, and at a few frames compares
the world position of every bone head with mocap's position of the joint of
the same name. A file passes when every joint became a bone, the frame counts
agree and the largest distance is within `tolerance * body height` (height:
vertical extent of the first frame).

The importer's code has a `skip_frame = 1` (it keeps a rest pose before the
file's frames); the script derives the frame offset from the frame counts
(0 or 1), compares Blender's frame `k` with the file's frame `k + offset`
and reports the offset. With Blender 3.4.1 the offset is 0 and the positions
agree frame for frame, so an off-by-one would show as errors of centimetres.
"""

import builtins
import json
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from harness import run_checks  # noqa: E402


def work_around_open_mode_ru():
    """Blender 3.4's BVH importer opens files with mode 'rU', which Python
    3.11 refuses (ValueError: invalid mode: 'rU'): with Debian 12's blender
    package (3.4.1 on Python 3.11) every BVH import fails. 'U' has meant
    nothing since Python 3 (universal newlines are the default), so the
    importer module gets an open() that drops it. Newer Blenders open with
    'r' and are left alone."""
    try:
        from io_anim_bvh import import_bvh
    except ImportError:
        return False

    def open_without_u(file, mode="r", *args, **kwargs):
        return builtins.open(file, mode.replace("U", ""), *args, **kwargs)

    import_bvh.open = open_without_u
    return True


def check(bvh_path, positions_path, tolerance):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    # After the factory settings, which (re)load the add-ons.
    work_around_open_mode_ru()
    with open(positions_path) as f:
        ours = json.load(f)
    names = ours["joints"]
    frames = ours["positions"]
    result = {
        "file": bvh_path,
        "joints": len(names),
        "frames": len(frames),
    }
    try:
        bpy.ops.import_anim.bvh(
            filepath=bvh_path,
            target="ARMATURE",
            global_scale=1.0,
            frame_start=1,
            use_fps_scale=False,
            update_scene_fps=False,
            update_scene_duration=True,
            rotate_mode="NATIVE",
            # The file's own axes: no conversion to Blender's z-up.
            axis_forward="Y",
            axis_up="Z",
        )
    except Exception as e:  # the importer's own error, reported as such
        result.update(imported=False, error=str(e), passed=False)
        return result
    armatures = [o for o in bpy.context.scene.objects if o.type == "ARMATURE"]
    if not armatures:
        result.update(imported=False, error="no armature was created", passed=False)
        return result
    arm = armatures[0]
    bones = arm.pose.bones
    result["imported"] = True
    result["bones"] = len(bones)
    missing = [n for n in names if n.replace(" ", "_") not in bones]
    result["missing_joints"] = missing
    action = arm.animation_data.action if arm.animation_data else None
    if action is None:
        blender_frames = 1
    else:
        start, end = action.frame_range
        blender_frames = int(round(end - start)) + 1
    result["blender_frames"] = blender_frames
    offset = len(frames) - blender_frames
    result["frame_offset"] = offset
    if offset not in (0, 1) or missing:
        result["passed"] = False
        return result

    first = frames[0]
    ys = [p[1] for p in first]
    height = max(ys) - min(ys)
    limit = tolerance * height
    result["height"] = height
    result["tolerance"] = limit
    checked = sorted({0, blender_frames // 3, (2 * blender_frames) // 3, blender_frames - 1})
    worst = 0.0
    worst_at = None
    scene = bpy.context.scene
    for k in checked:
        scene.frame_set(1 + k)
        bpy.context.view_layer.update()
        expected = frames[k + offset]
        for j, name in enumerate(names):
            head = arm.matrix_world @ bones[name.replace(" ", "_")].head
            d = sum((head[i] - expected[j][i]) ** 2 for i in range(3)) ** 0.5
            if d > worst:
                worst = d
                worst_at = {"frame": k + offset, "joint": name}
    result["checked_frames"] = [k + offset for k in checked]
    result["max_error"] = worst
    result["max_error_relative"] = worst / height if height > 0 else None
    result["max_error_at"] = worst_at
    result["passed"] = worst <= limit
    return result


def main():
    run_checks(check, "BVH", "BLENDER-CHECK")


main()
