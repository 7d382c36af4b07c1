#!/usr/bin/env python3
"""Cuts each character of the real-art set into body-part layers and writes NAME.ora.

Usage: make_layers.py SET_DIR [NAME...] [--overlay DIR]

Reads SET_DIR/NAME.png and the `layers` of SET_DIR/NAME.json: a list, front-most first (the
order of stack.xml), of {"name", "part", "parent", "polygon"}, drawn by hand along the body
parts. Every opaque pixel is given to one layer, its owner: of the polygons containing it, the
one of the part nearest the root of the `parent` tree (ties: the earlier in the list); pixels
in no polygon go to the nearest owned pixel's layer (grown a pixel at a time). A child layer
also gets the pixels of its own polygon that its parent owns: the overlap artists leave under a
joint (the child's polygon reaches a few px under its parent). Writes SET_DIR/NAME.ora
(OpenRaster: `mimetype` stored first, stack.xml, data/*.png, mergedimage.png,
Thumbnails/thumbnail.png), every layer a canvas-sized PNG at 0,0. With --overlay DIR, also
writes DIR/NAME.layers.png: each layer tinted, the polygons and the reference joints drawn.
"""
import io
import json
import sys
import zipfile
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np
from PIL import Image, ImageDraw

COLORS = [(230, 25, 75), (60, 180, 75), (255, 225, 25), (0, 130, 200), (245, 130, 48),
          (145, 30, 180), (70, 240, 240), (240, 50, 230), (210, 245, 60), (250, 190, 212),
          (0, 128, 128), (170, 110, 40), (128, 0, 0), (128, 128, 0), (0, 0, 128), (128, 128, 128)]


def polygon_mask(size, polygon):
    m = Image.new("L", size, 0)
    ImageDraw.Draw(m).polygon([tuple(p) for p in polygon], fill=255, outline=255)
    return np.asarray(m) > 0


def depth(layers, name):
    by_name = {l["name"]: l for l in layers}
    d = 0
    while by_name[name].get("parent"):
        name = by_name[name]["parent"]
        d += 1
        if d > len(layers):
            raise SystemExit(f"parent cycle at {name}")
    return d


def cut(image, layers):
    """One RGBA array per layer (canvas-sized)."""
    a = np.asarray(image.convert("RGBA"))
    opaque = a[..., 3] > 0
    h, w = opaque.shape
    masks = [polygon_mask((w, h), l["polygon"]) for l in layers]
    order = sorted(range(len(layers)), key=lambda k: (depth(layers, layers[k]["name"]), k))
    owner = np.full((h, w), -1, dtype=np.int32)
    for k in reversed(order):
        owner[masks[k]] = k
    owner[~opaque] = -1
    # pixels in no polygon: grow the owned labels into them
    todo = opaque & (owner == -1)
    while todo.any():
        grown = owner.copy()
        for dy, dx in ((0, 1), (0, -1), (1, 0), (-1, 0), (1, 1), (1, -1), (-1, 1), (-1, -1)):
            src = np.full((h, w), -1, dtype=np.int32)
            ys, yd = (slice(0, h - dy), slice(dy, h)) if dy >= 0 else (slice(-dy, h), slice(0, h + dy))
            xs, xd = (slice(0, w - dx), slice(dx, w)) if dx >= 0 else (slice(-dx, w), slice(0, w + dx))
            src[yd, xd] = owner[ys, xs]
            take = todo & (grown == -1) & (src >= 0)
            grown[take] = src[take]
        if (grown == owner).all():
            break
        owner = grown
        todo = opaque & (owner == -1)
    # pieces that no growth reached (apart from every polygon): the layer of the nearest polygon
    left = np.argwhere(opaque & (owner == -1))
    if len(left):
        centers = [np.array(l["polygon"], dtype=np.float64) for l in layers]
        for y, x in left:
            owner[y, x] = min(range(len(layers)), key=lambda k: np.min(np.hypot(centers[k][:, 0] - x, centers[k][:, 1] - y)))
    index = {l["name"]: k for k, l in enumerate(layers)}
    out = []
    for k, l in enumerate(layers):
        mine = owner == k
        parent = l.get("parent")
        if parent:
            mine = mine | (masks[k] & (owner == index[parent]))
        layer = np.zeros_like(a)
        layer[mine] = a[mine]
        out.append(layer)
    return out, owner


def png_bytes(array_or_image):
    img = array_or_image if isinstance(array_or_image, Image.Image) else Image.fromarray(array_or_image, "RGBA")
    buf = io.BytesIO()
    img.save(buf, "PNG", optimize=True)
    return buf.getvalue()


def write_ora(path, image, layers, arrays):
    w, h = image.size
    stack = [f'<?xml version="1.0" encoding="UTF-8"?>\n<image version="0.0.3" w="{w}" h="{h}">\n <stack>\n']
    files = []
    for k, (l, arr) in enumerate(zip(layers, arrays)):
        src = f"data/layer{k:02d}.png"
        stack.append(f'  <layer name={quoteattr(l["name"])} src="{src}" x="0" y="0" opacity="1.0" '
                     f'visibility="visible" composite-op="svg:src-over"/>\n')
        files.append((src, png_bytes(arr)))
    stack.append(" </stack>\n</image>\n")
    merged = Image.new("RGBA", (w, h), (0, 0, 0, 0))
    for arr in reversed(arrays):
        merged.alpha_composite(Image.fromarray(arr, "RGBA"))
    thumb = merged.copy()
    thumb.thumbnail((256, 256))
    with zipfile.ZipFile(path, "w") as z:
        info = zipfile.ZipInfo("mimetype", date_time=(2026, 1, 1, 0, 0, 0))
        info.compress_type = zipfile.ZIP_STORED
        z.writestr(info, "image/openraster")
        for name, data in [("stack.xml", "".join(stack).encode())] + files + [
                ("mergedimage.png", png_bytes(merged)), ("Thumbnails/thumbnail.png", png_bytes(thumb))]:
            info = zipfile.ZipInfo(name, date_time=(2026, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info, data)


def overlay(image, layers, owner, joints, path):
    a = np.asarray(image.convert("RGBA")).astype(np.float32)
    tinted = np.zeros_like(a)
    tinted[..., 3] = 255
    tinted[..., :3] = 250
    for k in range(len(layers)):
        m = owner == k
        tinted[m, :3] = 0.45 * a[m, :3] + 0.55 * np.array(COLORS[k % len(COLORS)])
    S = 2 if max(image.size) < 300 else 1
    out = Image.fromarray(tinted.astype(np.uint8), "RGBA").resize((image.width * S, image.height * S), Image.NEAREST)
    d = ImageDraw.Draw(out)
    for k, l in enumerate(layers):
        pts = [(x * S, y * S) for x, y in l["polygon"]]
        d.line(pts + [pts[0]], fill=COLORS[k % len(COLORS)] + (255,), width=1)
        cx, cy = pts[0]
        d.text((cx + 2, cy + 1), l["name"], fill=(0, 0, 0, 255))
    for name, (x, y) in joints.items():
        x, y = x * S, y * S
        d.ellipse([x - 4, y - 4, x + 4, y + 4], outline=(0, 0, 0, 255), fill=(255, 255, 255, 255))
        d.text((x + 5, y - 5), name, fill=(0, 0, 0, 255))
    out.save(path)


def main():
    args = sys.argv[1:]
    overlay_dir = None
    if "--overlay" in args:
        i = args.index("--overlay")
        overlay_dir = Path(args[i + 1])
        del args[i:i + 2]
    set_dir = Path(args[0])
    names = args[1:] or json.loads((set_dir / "index.json").read_text())
    for name in names:
        ref = json.loads((set_dir / f"{name}.json").read_text())
        image = Image.open(set_dir / f"{name}.png").convert("RGBA")
        layers = ref["layers"]
        known = {l["name"] for l in layers}
        for l in layers:
            if l.get("parent") and l["parent"] not in known:
                raise SystemExit(f"{name}: layer {l['name']!r}: unknown parent {l['parent']!r}")
        arrays, owner = cut(image, layers)
        empty = [l["name"] for l, arr in zip(layers, arrays) if not (arr[..., 3] > 0).any()]
        if empty:
            raise SystemExit(f"{name}: empty layers {empty}")
        write_ora(set_dir / f"{name}.ora", image, layers, arrays)
        if overlay_dir:
            overlay_dir.mkdir(parents=True, exist_ok=True)
            overlay(image, layers, owner, ref.get("joints", {}), overlay_dir / f"{name}.layers.png")
        print(f"{name}: {len(layers)} layers", file=sys.stderr)


if __name__ == "__main__":
    main()
