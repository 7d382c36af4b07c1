"""Writes a batch folder for the Ray test and the figures: generated sprites and line art, a copy
of the bundled character, and manifest.json over them.

  python3 make_batch.py OUT_DIR ASSETS_DIR [--colorize N] [--size PX] [--only-colorize]

Jobs: the character rigged with its handles and attachments, its four animations rendered
(GIF, sprite sheet, frame folders), its Spine export; four generated sprites rigged (no handles);
N colorize jobs over generated line art (rectangles and rings, each with its own scribbles).
Pure Python (zlib PNGs): nothing to install.
"""

import argparse
import json
import os
import shutil
import struct
import zlib


def png(path, width, height, pixel):
    """Writes an RGBA PNG; pixel(x, y) -> (r, g, b, a)."""
    rows = b"".join(
        b"\0" + b"".join(bytes(pixel(x, y)) for x in range(width)) for y in range(height)
    )

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(rows, 6)))
        f.write(chunk(b"IEND", b""))


def sprite(path, k, size=128):
    """An opaque blob on transparency: an ellipse with a notch, varying with k."""
    cx, cy = size / 2, size / 2
    rx, ry = size * (0.25 + 0.04 * k), size * (0.35 - 0.03 * k)

    def pixel(x, y):
        dx, dy = (x + 0.5 - cx) / rx, (y + 0.5 - cy) / ry
        inside = dx * dx + dy * dy <= 1 and not (abs(x - cx) < 6 and y < cy - ry * 0.4)
        return (200, 120 + 20 * k, 60, 255) if inside else (0, 0, 0, 0)

    png(path, size, size, pixel)


def lineart(path, k, size):
    """Black lines on white: a frame, a ring and a bar whose places vary with k."""
    m = 4 + k % 5
    ring_c = (size * 0.4 + k % 7, size * 0.45)
    ring_r = size * 0.2

    def pixel(x, y):
        frame = min(x, y, size - 1 - x, size - 1 - y) in (m, m + 1)
        d = ((x + 0.5 - ring_c[0]) ** 2 + (y + 0.5 - ring_c[1]) ** 2) ** 0.5
        ring = abs(d - ring_r) < 1.2
        bar = abs(x - (size * 0.75 - k % 4)) < 1 and m < y < size - m
        return (0, 0, 0, 255) if frame or ring or bar else (255, 255, 255, 255)

    png(path, size, size, pixel)
    ring_x, ring_y = ring_c
    return {
        "strokes": [
            {"color": "#e04040", "width": 3, "points": [[ring_x - 3, ring_y], [ring_x + 3, ring_y + 2]]},
            {"color": "#3060d0", "width": 3, "points": [[m + 6, m + 6], [m + 10, size / 2]]},
            {"color": "#40a040", "width": 3, "points": [[size - m - 6, size / 2]]},
        ]
    }


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("out")
    parser.add_argument("assets")
    parser.add_argument("--colorize", type=int, default=12)
    parser.add_argument("--size", type=int, default=64)
    parser.add_argument("--only-colorize", action="store_true")
    args = parser.parse_args()
    out = args.out
    for sub in ("in/character", "in/sprites", "in/lineart"):
        os.makedirs(os.path.join(out, sub), exist_ok=True)
    jobs = []
    if not args.only_colorize:
        layers = json.load(open(os.path.join(args.assets, "layers.json")))
        names = layers["layers"] + list(layers.get("attachments", {}))
        for name in names + ["handles"]:
            ext = "json" if name == "handles" else "png"
            shutil.copy(os.path.join(args.assets, f"{name}.{ext}"), os.path.join(out, "in/character"))
        jobs.append({
            "kind": "rig", "name": "character",
            "inputs": {"images": [f"in/character/{n}.png" for n in names],
                       "handles": "in/character/handles.json"},
            "options": {"attachments": layers.get("attachments", {})},
            "outputs": {"rig": "out/character/character.json", "preview": "out/character/mesh.png"},
        })
        # The rig has no animations of its own: rendered animations come with a rig that has
        # them, which `sinew rig` does not write. The character's animations are rendered from
        # the rig the demo writes (in/demo/character.json, made by the caller).
        for k, (anim, target) in enumerate([("walk", "walk.gif"), ("wave", "wave.png"),
                                           ("hop", "hop"), ("lift", "lift.gif")]):
            jobs.append({
                "kind": "render", "name": f"render-{anim}",
                "inputs": {"rig": "in/demo/character.json"},
                "options": {"animation": anim, "fps": 8, "scale": 0.25},
                "outputs": {"output": f"out/render/{target}"},
            })
        jobs.append({
            "kind": "export", "name": "export-spine",
            "inputs": {"rig": "in/demo/character.json"},
            "options": {"skeleton": "character"},
            "outputs": {"folder": "out/spine"},
        })
        jobs.append({
            "kind": "export", "name": "export-rigged",
            "inputs": {"rig": "out/character/character.json"},
            "options": {"spine_version": "4.1"},
            "outputs": {"folder": "out/spine-rigged"},
        })
        for k in range(4):
            sprite(os.path.join(out, f"in/sprites/blob{k}.png"), k)
            jobs.append({
                "kind": "rig", "name": f"sprite-{k}",
                "inputs": {"images": [f"in/sprites/blob{k}.png"]},
                "outputs": {"rig": f"out/sprites/blob{k}.json"},
            })
    for k in range(args.colorize):
        strokes = lineart(os.path.join(out, f"in/lineart/art{k}.png"), k, args.size)
        with open(os.path.join(out, f"in/lineart/art{k}.json"), "w") as f:
            json.dump(strokes, f)
        jobs.append({
            "kind": "colorize", "name": f"colorize-{k}",
            "inputs": {"lineart": f"in/lineart/art{k}.png", "scribbles": f"in/lineart/art{k}.json"},
            "options": {"fill": "soft" if k % 3 == 0 else "flat"},
            "outputs": {"image": f"out/colorized/art{k}.png"},
        })
    with open(os.path.join(out, "manifest.json"), "w") as f:
        json.dump({"jobs": jobs}, f, indent=1)
    print(f"{out}/manifest.json: {len(jobs)} jobs")


if __name__ == "__main__":
    main()
