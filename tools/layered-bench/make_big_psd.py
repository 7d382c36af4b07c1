"""Writes a large layered PSD with psd-tools: a 4096 x 4096 canvas of 40 pixel layers (a
character's worth of parts: ellipses and rounded bars from 60 to 900 px, RLE compressed,
placed over the canvas with a fixed seed), for tools/layered-bench/run.sh.

Usage: python make_big_psd.py OUT.psd [SIDE_PX] [LAYERS]
"""
import random
import sys

from PIL import Image, ImageDraw
from psd_tools import PSDImage
from psd_tools.api.layers import PixelLayer
from psd_tools.constants import Compression


def part(rng, w, h):
    img = Image.new("RGBA", (w, h), (0, 0, 0, 0))
    color = tuple(rng.randrange(30, 230) for _ in range(3)) + (255,)
    draw = ImageDraw.Draw(img)
    if rng.random() < 0.5:
        draw.ellipse((0, 0, w - 1, h - 1), fill=color)
    else:
        draw.rounded_rectangle((0, 0, w - 1, h - 1), radius=min(w, h) // 3, fill=color)
    return img


def main():
    out = sys.argv[1]
    side = int(sys.argv[2]) if len(sys.argv) > 2 else 4096
    count = int(sys.argv[3]) if len(sys.argv) > 3 else 40
    rng = random.Random(40)
    psd = PSDImage.new("RGB", (side, side), color=0, compression=Compression.RLE)
    for k in range(count):
        w = rng.randrange(60, 900) * side // 4096
        h = rng.randrange(60, 900) * side // 4096
        left = rng.randrange(0, side - w)
        top = rng.randrange(0, side - h)
        PixelLayer.frompil(part(rng, max(w, 8), max(h, 8)), psd, f"part_{k:02}", top=top,
                           left=left, compression=Compression.RLE)
    psd.save(out)


if __name__ == "__main__":
    main()
