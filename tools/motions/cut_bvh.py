#!/usr/bin/env python3
"""Cuts frames out of a BVH file, keeping its hierarchy, frame time and rows as written.

    tools/motions/cut_bvh.py IN.bvh OUT.bvh FIRST LAST

FIRST and LAST are 0-based frame indices (the first row after `Frame Time:` is frame 0), both
kept. Only `Frames:` changes; every kept row is copied byte for byte (line ends made \\n).
"""

import sys


def main(argv):
    if len(argv) != 5:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    src, dst, first, last = argv[1], argv[2], int(argv[3]), int(argv[4])
    with open(src, newline="") as f:
        lines = [l.rstrip("\r\n") for l in f]
    motion = next(i for i, l in enumerate(lines) if l.strip() == "MOTION")
    frames_at = next(i for i in range(motion, len(lines)) if lines[i].strip().startswith("Frames:"))
    time_at = next(i for i in range(motion, len(lines)) if lines[i].strip().startswith("Frame Time:"))
    rows = [l for l in lines[time_at + 1 :] if l.strip()]
    if not 0 <= first <= last < len(rows):
        print(f"{src}: frames {first}..{last} outside 0..{len(rows) - 1}", file=sys.stderr)
        return 2
    header = lines[: frames_at] + [f"Frames: {last - first + 1}"] + lines[frames_at + 1 : time_at + 1]
    with open(dst, "w") as f:
        f.write("\n".join(header + rows[first : last + 1]) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
