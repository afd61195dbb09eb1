"""Import a `timpanist render --bvh` file (and optionally its `--glb`) into Blender in
background mode with the importers' defaults and check what an animator would see:
the armature's 11 bones, one Blender frame per BVH frame, and each stick bone's tail
(the End Site at the tip) where the motion CSV of the same render has the tip. Both
files are Y up with the performer facing +Z; both importers turn that into Blender's
Z up with the performer facing -Y (its front view), so the CSV's (x, y, z) is at
Blender's (-x, -y, z). With a .glb, its importer's stick_tip_l/_r empties are checked
the same way. Exits 1 past 1 mm.

Usage: blender -b --python tests/scripts/blender_check.py -- OUT.bvh MOTION.csv [OUT.glb]
"""
import builtins
import csv
import math
import sys

import bpy

# Debian 12's Blender 3.4 runs on Python 3.11, which refuses the mode 'rU' its BVH
# importer opens files with: drop the 'U' (universal newlines are the default anyway).
_open = builtins.open


def _open_without_u(file, mode="r", *a, **k):
    return _open(file, mode.replace("U", "") if isinstance(mode, str) else mode, *a, **k)


builtins.open = _open_without_u

if glb_path := (sys.argv[sys.argv.index("--") + 1:] + [None, None, None])[2]:
    # Its glTF importer needs numpy (Debian: python3-numpy) and still names np.bool,
    # which numpy 1.24 removed.
    import numpy

    numpy.bool = bool

args = sys.argv[sys.argv.index("--") + 1:]
bvh_path, csv_path = args[0], args[1]
with open(csv_path) as f:
    rows = list(csv.DictReader(f))

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_anim.bvh(filepath=bvh_path, update_scene_fps=True, update_scene_duration=True)
arm = next(o for o in bpy.context.scene.objects if o.type == "ARMATURE")
scene = bpy.context.scene
print(f"{bvh_path}: {len(arm.data.bones)} bones, frames {scene.frame_start}-{scene.frame_end},"
      f" {scene.render.fps / scene.render.fps_base:.1f} fps")
if len(arm.data.bones) != 11:
    sys.exit(1)

def tip(row, hand):
    x, y, z = (float(row[f"{hand}_tip_{a}_m"]) for a in "xyz")
    return [-x, -y, z]

empties = {}
if glb_path:
    bpy.ops.import_scene.gltf(filepath=glb_path)
    empties = {h: bpy.data.objects[f"stick_tip_{h[0]}"] for h in ("left", "right")}

worst_bvh = worst_glb = 0.0
step = max(1, len(rows) // 200)
frames = range(0, len(rows), step)
for k in frames:
    scene.frame_set(scene.frame_start + k)
    for hand, bone in (("left", "grip_l"), ("right", "grip_r")):
        tail = arm.matrix_world @ arm.pose.bones[bone].tail
        worst_bvh = max(worst_bvh, math.dist(tail, tip(rows[k], hand)))
print(f"BVH: worst stick-tip distance to the CSV {worst_bvh * 1e3:.3f} mm over {len(frames)} frames")

if empties:
    # The glTF importer keys time t at frame t x fps (250 fps, set by the BVH import).
    for k in frames:
        scene.frame_set(k)
        for hand in ("left", "right"):
            p = empties[hand].matrix_world.translation
            worst_glb = max(worst_glb, math.dist(p, tip(rows[k], hand)))
    print(f"glTF: worst stick-tip distance to the CSV {worst_glb * 1e3:.3f} mm over {len(frames)} frames")

if worst_bvh > 1e-3 or worst_glb > 1e-3:
    sys.exit(1)
