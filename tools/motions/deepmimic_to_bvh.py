#!/usr/bin/env python3
"""DeepMimic humanoid3d motion clips (pybullet_data/data/motions/humanoid3d_*.txt) to BVH.

    tools/motions/deepmimic_to_bvh.py IN.txt OUT.bvh
    tools/motions/deepmimic_to_bvh.py IN.txt --positions 0 10 20   # JSON: joint positions by
                                                                   # quaternion FK (the check)

A DeepMimic clip is JSON: {"Loop": ..., "Frames": [[dt, 43 numbers], ...]}. Each frame: its
duration dt (s), the root (pelvis) position (3, metres, y-up), the root orientation quaternion
(w, x, y, z, world), then each joint's rotation relative to its parent: chest, neck, right hip
(quaternions w, x, y, z), right knee (an angle in radians about z), right ankle, right
shoulder (quaternions), right elbow (angle about z), left hip, left knee, left ankle, left
shoulder, left elbow. The character faces +x with its right side at +z; at rest (identity
rotations) it stands with its arms down.

The skeleton (joint origins in the parent's frame, metres) is DeepMimic's humanoid3d: the joint
origins of pybullet_data/humanoid/humanoid.urdf times 0.25, the globalScaling pybullet's
DeepMimic environment loads it with (e.g. the chest at 0.944604 × 0.25 = 0.236151 above the
root). Written as BVH with these names (CMU/Mixamo-like):

    DeepMimic      BVH joint
    root           Hips            (6 channels: position, then rotation)
    chest          Spine
    neck           Neck
    (head centre)  Head            (fixed in DeepMimic: its channels are always 0)
    right_hip      RightUpLeg      left_hip       LeftUpLeg
    right_knee     RightLeg        left_knee      LeftLeg
    right_ankle    RightFoot       left_ankle     LeftFoot
    right_shoulder RightArm        left_shoulder  LeftArm
    right_elbow    RightForeArm    left_elbow     LeftForeArm
    right_wrist    RightHand       left_wrist     LeftHand   (fixed: channels always 0)

End sites: the top of the head sphere, the front of the sole (toe tip on the ground plane of
the foot box) and the far side of the hand sphere, from the same URDF's collision shapes.
Every joint but the root has `CHANNELS 3 Zrotation Yrotation Xrotation` (degrees; R = Rz Ry Rx,
the BVH convention: the middle axis, y, is the twist along a limb, so no gimbal lock in
ordinary motion); the root has `Xposition Yposition Zposition Yrotation Xrotation Zrotation`
(heading first). Angles are unwrapped over time so no channel jumps by 360°. The whole clip is turned 90°
about y (pre-multiplied into the root) so the character faces +z with its left side at +x, as
the CMU clips do; the frame time is the clip's (DeepMimic's constant frame duration).
"""

import json
import math
import sys

SCALE = 0.25
# name, parent, offset (URDF joint origin, unscaled), DeepMimic index of the rotation in a
# frame row (None: fixed), kind ("quat" or "angle"), end site (unscaled) or None.
SKELETON = [
    ("Hips", None, (0, 0, 0), 4, "root", None),
    ("Spine", "Hips", (0, 0.944604, 0), 8, "quat", None),
    ("Neck", "Spine", (0, 0.895576, 0), 12, "quat", None),
    ("Head", "Neck", (0, 0.7, 0), None, None, (0, 0.41, 0)),
    ("RightArm", "Spine", (-0.0962, 0.974, 0.73244), 25, "quat", None),
    ("RightForeArm", "RightArm", (0, -1.099152, 0), 29, "angle", None),
    ("RightHand", "RightForeArm", (0, -1.035788, 0), None, None, (0, -0.16, 0)),
    ("LeftArm", "Spine", (-0.0962, 0.974, -0.73244), 39, "quat", None),
    ("LeftForeArm", "LeftArm", (0, -1.099152, 0), 43, "angle", None),
    ("LeftHand", "LeftForeArm", (0, -1.035788, 0), None, None, (0, -0.16, 0)),
    ("RightUpLeg", "Hips", (0, 0, 0.339548), 16, "quat", None),
    ("RightLeg", "RightUpLeg", (0, -1.686184, 0), 20, "angle", None),
    ("RightFoot", "RightLeg", (0, -1.63948, 0), 21, "quat", (0.534, -0.2, 0)),
    ("LeftUpLeg", "Hips", (0, 0, -0.339548), 30, "quat", None),
    ("LeftLeg", "LeftUpLeg", (0, -1.686184, 0), 34, "angle", None),
    ("LeftFoot", "LeftLeg", (0, -1.63948, 0), 35, "quat", (0.534, -0.2, 0)),
]
# The foot's end site: the foot box (centre (0.18, -0.09, 0), size 0.708 × 0.22 × 0.36 in the
# URDF) at its front (0.18 + 0.354) and its sole (-0.09 - 0.11). The head: its sphere (centre
# 0.7 above the neck, radius 0.41) at the top. The hand: its sphere (radius 0.16) at the far side.

ROOT_ORDER = "Yrotation Xrotation Zrotation"
JOINT_ORDER = "Zrotation Yrotation Xrotation"
# The world turn: 90° about y clockwise seen from above (+x forward becomes +z forward).
TURN = (math.cos(-math.pi / 4), 0.0, math.sin(-math.pi / 4), 0.0)  # w, x, y, z


def qmul(a, b):
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


def qnorm(q):
    n = math.sqrt(sum(c * c for c in q))
    if not n > 0:
        raise ValueError(f"a zero quaternion: {q}")
    return tuple(c / n for c in q)


def qrotate(q, v):
    w, x, y, z = q
    p = qmul(qmul(q, (0.0, *v)), (w, -x, -y, -z))
    return p[1:]


def qmatrix(q):
    w, x, y, z = qnorm(q)
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]


def zyx_degrees(q):
    """(z, y, x) in degrees with R(q) = Rz(z) Ry(y) Rx(x)."""
    m = qmatrix(q)
    y = math.asin(max(-1.0, min(1.0, -m[2][0])))
    if math.cos(y) > 1e-9:
        z = math.atan2(m[1][0], m[0][0])
        x = math.atan2(m[2][1], m[2][2])
    else:  # gimbal lock: put it all in z
        z = math.atan2(-m[0][1], m[1][1])
        x = 0.0
    return tuple(math.degrees(a) for a in (z, y, x))


def yxz_degrees(q):
    """(y, x, z) in degrees with R(q) = Ry(y) Rx(x) Rz(z): the root's, whose heading (about y)
    may take any value without a gimbal lock."""
    m = qmatrix(q)
    x = math.asin(max(-1.0, min(1.0, -m[1][2])))
    if math.cos(x) > 1e-9:
        y = math.atan2(m[0][2], m[2][2])
        z = math.atan2(m[1][0], m[1][1])
    else:
        y = math.atan2(-m[2][0], m[0][0])
        z = 0.0
    return tuple(math.degrees(a) for a in (y, x, z))


def local_rotation(row, index, kind):
    if index is None:
        return (1.0, 0.0, 0.0, 0.0)
    if kind == "angle":
        a = row[index]
        return (math.cos(a / 2), 0.0, 0.0, math.sin(a / 2))
    return qnorm(tuple(row[index : index + 4]))


def offset(joint):
    return tuple(c * SCALE for c in joint[2])


def load(path):
    with open(path) as f:
        clip = json.load(f)
    frames = clip["Frames"]
    if not frames or any(len(r) != 44 for r in frames):
        raise ValueError(f"{path}: expected frames of 44 numbers (humanoid3d)")
    times = [r[0] for r in frames]
    dt = times[0]
    # The last frame's duration is sometimes 0 (nothing follows it).
    if any(abs(t - dt) > 1e-6 for t in times[:-1]) or not dt > 0:
        raise ValueError(f"{path}: frame durations differ: BVH needs one frame time")
    return clip, frames, dt


def positions(row):
    """World positions (turned to face +z) by quaternion FK: {name: (x, y, z)}, plus
    "NAME/end" for end sites."""
    world = {}
    out = {}
    for joint in SKELETON:
        name, parent, _, index, kind, end = joint
        if parent is None:
            rot = qmul(TURN, qnorm(tuple(row[4:8])))
            pos = qrotate(TURN, tuple(row[1:4]))
        else:
            prot, ppos = world[parent]
            rot = qmul(prot, local_rotation(row, index, kind))
            o = qrotate(prot, offset(joint))
            pos = tuple(p + d for p, d in zip(ppos, o))
        world[name] = (rot, pos)
        out[name] = pos
        if end:
            e = qrotate(rot, tuple(c * SCALE for c in end))
            out[name + "/end"] = tuple(p + d for p, d in zip(pos, e))
    return out


def unwrap(previous, angles):
    if previous is None:
        return angles
    return tuple(a + 360.0 * round((p - a) / 360.0) for p, a in zip(previous, angles))


def write_bvh(out, frame_time, rows):
    """rows: per frame, a list of (root position (3), then per joint (z, y, x) degrees) in
    SKELETON order."""
    children = {}
    for joint in SKELETON:
        children.setdefault(joint[1], []).append(joint)
    lines = ["HIERARCHY"]

    def emit(joint, depth):
        pad = "  " * depth
        name, parent, _, _, _, end = joint
        o = offset(joint)
        lines.append(f"{pad}{'ROOT' if parent is None else 'JOINT'} {name}")
        lines.append(f"{pad}{{")
        lines.append(f"{pad}  OFFSET {o[0]:.6f} {o[1]:.6f} {o[2]:.6f}")
        if parent is None:
            lines.append(f"{pad}  CHANNELS 6 Xposition Yposition Zposition {ROOT_ORDER}")
        else:
            lines.append(f"{pad}  CHANNELS 3 {JOINT_ORDER}")
        for child in children.get(name, []):
            emit(child, depth + 1)
        if end:
            e = [c * SCALE for c in end]
            lines.append(f"{pad}  End Site")
            lines.append(f"{pad}  {{")
            lines.append(f"{pad}    OFFSET {e[0]:.6f} {e[1]:.6f} {e[2]:.6f}")
            lines.append(f"{pad}  }}")
        lines.append(f"{pad}}}")

    emit(SKELETON[0], 0)
    # The values follow the order joints are written in (depth first), not SKELETON's.
    order = []

    def walk(joint):
        order.append(SKELETON.index(joint))
        for child in children.get(joint[0], []):
            walk(child)

    walk(SKELETON[0])
    lines.append("MOTION")
    lines.append(f"Frames: {len(rows)}")
    lines.append(f"Frame Time: {frame_time:.7f}")
    for pos, angles in rows:
        values = [f"{c:.6f}" for c in pos]
        for i in order:
            values += [f"{a:.5f}" for a in angles[i]]
        lines.append(" ".join(v if v != "-0.000000" and v != "-0.00000" else v[1:] for v in values))
    with open(out, "w") as f:
        f.write("\n".join(lines) + "\n")


def convert(path, out):
    _, frames, dt = load(path)
    rows = []
    previous = [None] * len(SKELETON)
    for row in frames:
        angles = []
        for k, (name, parent, _, index, kind, _) in enumerate(SKELETON):
            if parent is None:
                euler = yxz_degrees(qmul(TURN, qnorm(tuple(row[4:8]))))
            else:
                euler = zyx_degrees(local_rotation(row, index, kind))
            a = unwrap(previous[k], euler)
            previous[k] = a
            angles.append(a)
        rows.append((qrotate(TURN, tuple(row[1:4])), angles))
    write_bvh(out, dt, rows)


def main(argv):
    if len(argv) >= 3 and argv[2] == "--positions":
        _, frames, _ = load(argv[1])
        result = {f: positions(frames[int(f)]) for f in argv[3:]}
        json.dump(result, sys.stdout, indent=1)
        print()
        return 0
    if len(argv) != 3:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    convert(argv[1], argv[2])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
