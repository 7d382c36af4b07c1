#!/usr/bin/env python3
"""Keys a wave by hand on the DeepMimic humanoid3d skeleton (see deepmimic_to_bvh.py) and
writes it as BVH: no capture in the packages the library draws from covers a wave.

    tools/motions/key_wave.py OUT.bvh

Two seconds at 30 frames per second (the DeepMimic walk's rate), standing still facing +z: the
right arm rises out to the side with the forearm up (0–0.5 s), the forearm waves three times
in the frontal plane (0.5–1.5 s), the arm comes down (1.5–2 s). Other joints carry a small
breathing sway so the figure is not frozen. It starts and ends at the same pose, so it loops.

The keys (degrees; body-local axes: x forward, y up, z to the character's right):
- RightArm: abduction about x from 0 (down) to -95 (just above horizontal, out to the right),
  and a twist of -90 about the upper arm's axis so the elbow hinge points forward;
- RightForeArm: elbow flexion about z from 0 to 80, then 80 ± 25 for the waves;
- Spine: a lean of 3 away from the raised arm about x; Neck: 5 towards the hand;
- LeftArm: 6 out from the side.
Between keys the angles ease with a smoothstep; the waves are a sine.
"""

import math
import sys

sys.path.insert(0, __import__("os").path.dirname(__file__))
import deepmimic_to_bvh as dm  # noqa: E402

FPS = 30
SECONDS = 2.0
# Standing with straight legs: the hips above the ground by the thigh, the shin and the
# ankle's height over the sole (metres, from the skeleton).
HIP_HEIGHT = (1.686184 + 1.63948 + 0.2) * dm.SCALE


def smoothstep(a, b, t):
    t = min(1.0, max(0.0, (t - a) / (b - a)))
    return t * t * (3 - 2 * t)


def axis_quat(axis, degrees):
    h = math.radians(degrees) / 2
    q = [math.cos(h), 0.0, 0.0, 0.0]
    q[1 + axis] = math.sin(h)
    return tuple(q)


def pose(t):
    """Local rotations (quaternions) by joint name at time t."""
    up = smoothstep(0.0, 0.5, t) * (1 - smoothstep(1.5, 2.0, t))
    wave = math.sin(2 * math.pi * 3 * (t - 0.5)) if 0.5 <= t <= 1.5 else 0.0
    breath = math.sin(2 * math.pi * t / SECONDS)
    return {
        "RightArm": dm.qmul(axis_quat(0, -95 * up), axis_quat(1, -90 * up)),
        "RightForeArm": axis_quat(2, 80 * up + 25 * wave * up),
        "Spine": dm.qmul(axis_quat(0, 3 * up), axis_quat(2, 1.5 * breath)),
        "Neck": axis_quat(0, -5 * up),
        "LeftArm": axis_quat(0, 6),
    }


def main(argv):
    if len(argv) != 2:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    rows = []
    frames = int(round(SECONDS * FPS)) + 1
    for f in range(frames):
        t = f / FPS
        rotations = pose(t)
        angles = []
        for name, parent, *_ in dm.SKELETON:
            if parent is None:
                angles.append(dm.yxz_degrees(dm.TURN))
            else:
                angles.append(dm.zyx_degrees(rotations.get(name, (1.0, 0.0, 0.0, 0.0))))
        rows.append(((0.0, HIP_HEIGHT, 0.0), angles))
    dm.write_bvh(argv[1], 1.0 / FPS, rows)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
