"""Writes the bundled character (assets/character) as a layered PSD scaled x4: a 2048 x 2048
RGB canvas, one RLE pixel layer per name of layers.json (same names and order, first = bottom),
each layer's 512 px PNG resized x4 (Lanczos, straight alpha), trimmed to its non-transparent box
and placed at its offset, alpha as the transparency channel, as
tools/layered-fixtures/make_fixtures.py writes the 512 px tests/fixtures/layered/bundled_character.psd.
For tools/auto-bench/run.sh.

Usage: python make_big_character.py OUT.psd [FACTOR]
"""
import json
import os
import sys

import numpy as np
from PIL import Image
from psd_tools import PSDImage
from psd_tools.api.layers import PixelLayer
from psd_tools.constants import Compression

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CHARACTER = os.path.join(ROOT, "assets", "character")


def main():
    out = sys.argv[1]
    factor = int(sys.argv[2]) if len(sys.argv) > 2 else 4
    with open(os.path.join(CHARACTER, "layers.json")) as f:
        doc = json.load(f)
    w, h = doc["canvas"]
    W, H = w * factor, h * factor
    psd = PSDImage.new("RGB", (W, H), color=255, compression=Compression.RLE)
    for name in doc["layers"]:
        im = Image.open(os.path.join(CHARACTER, name + ".png")).convert("RGBA")
        assert im.size == (w, h), (name, im.size)
        # Premultiply for the resize (no dark fringes), then back to straight alpha.
        a = np.asarray(im).astype(np.float32) / 255.0
        pre = np.concatenate([a[..., :3] * a[..., 3:], a[..., 3:]], axis=2)
        big = np.stack(
            [
                np.asarray(
                    Image.fromarray(pre[..., c], mode="F").resize((W, H), Image.LANCZOS)
                )
                for c in range(4)
            ],
            axis=2,
        )
        big = np.clip(big, 0.0, 1.0)
        alpha = big[..., 3:]
        rgb = np.where(alpha > 1e-6, big[..., :3] / np.maximum(alpha, 1e-6), 0.0)
        rgba = np.concatenate([np.clip(rgb, 0, 1), alpha], axis=2)
        rgba = (rgba * 255.0 + 0.5).astype(np.uint8)
        layer = Image.fromarray(rgba, "RGBA")
        box = layer.getchannel("A").getbbox()
        assert box is not None, name
        PixelLayer.fromarray(np.asarray(layer.crop(box)), psd, name, top=box[1], left=box[0],
                             compression=Compression.RLE)
    psd.save(out)


if __name__ == "__main__":
    main()
