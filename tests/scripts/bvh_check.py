#!/usr/bin/env python3
"""Check a `timpanist render --bvh` file with an independent reader: the PyPI `bvh`
package parses it; forward kinematics written here (plain Python, the channels in the
order each joint declares) puts the stick tips (the grips' End Sites) where the motion
CSV of the same render has them (performer frame x right, y forward, z up -> BVH
(-x, z, y)): the performer faces +Z. Prints the joint count, frames, frame time and the worst tip distance;
exits 1 if the frames differ or a tip is more than 1 mm off.

Usage: pip install bvh; tests/scripts/bvh_check.py OUT.bvh MOTION.csv [--cm]
"""
import csv
import math
import sys

from bvh import Bvh


def rot(axis, deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return {
        "X": [[1, 0, 0], [0, c, -s], [0, s, c]],
        "Y": [[c, 0, s], [0, 1, 0], [-s, 0, c]],
        "Z": [[c, -s, 0], [s, c, 0], [0, 0, 1]],
    }[axis]


def mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def apply(a, v):
    return [sum(a[i][k] * v[k] for k in range(3)) for i in range(3)]


def end_site(mocap, joint):
    for child in mocap.get_joint(joint).children:
        if child.value[:2] == ["End", "Site"]:
            return [float(x) for x in child["OFFSET"]]
    raise SystemExit(f"{joint} has no End Site")


def main():
    path, csv_path = sys.argv[1], sys.argv[2]
    per_metre = 100.0 if "--cm" in sys.argv else 1.0
    with open(path) as f:
        mocap = Bvh(f.read())
    names = mocap.get_joints_names()
    parent = {n: (mocap.joint_parent(n).name if mocap.joint_parent(n) else None) for n in names}
    with open(csv_path) as f:
        rows = list(csv.DictReader(f))
    print(f"{path}: {len(names)} joints, {mocap.nframes} frames, frame time {mocap.frame_time} s")
    if mocap.nframes != len(rows):
        raise SystemExit(f"{mocap.nframes} frames but {len(rows)} CSV rows")
    ends = {"left": end_site(mocap, "grip_l"), "right": end_site(mocap, "grip_r")}
    worst = 0.0
    for f, row in enumerate(rows):
        pos, rot_of = {}, {}
        for n in names:
            local = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
            t = [float(x) for x in mocap.joint_offset(n)]
            channels = mocap.joint_channels(n)
            values = mocap.frame_joint_channels(f, n, channels)
            for c, v in zip(channels, values):
                if c.endswith("position"):
                    t["XYZ".index(c[0])] = v
                else:
                    local = mul(local, rot(c[0], v))
            p = parent[n]
            if p is None:
                pos[n], rot_of[n] = t, local
            else:
                d = apply(rot_of[p], t)
                pos[n] = [pos[p][i] + d[i] for i in range(3)]
                rot_of[n] = mul(rot_of[p], local)
        for hand, grip in (("left", "grip_l"), ("right", "grip_r")):
            d = apply(rot_of[grip], ends[hand])
            tip = [pos[grip][i] + d[i] for i in range(3)]
            x, y, z = (float(row[f"{hand}_tip_{a}_m"]) for a in "xyz")
            want = [-x * per_metre, z * per_metre, y * per_metre]
            worst = max(worst, math.dist(tip, want) / per_metre)
    print(f"worst stick-tip distance to the motion CSV: {worst * 1e3:.4f} mm")
    if worst > 1e-3:
        raise SystemExit("a stick tip is more than 1 mm off")


if __name__ == "__main__":
    main()
