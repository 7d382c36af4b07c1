"""Writes the layered-art fixtures of tests/layered.rs with psd-tools (the Python PSD library
most art pipelines use), and each file's flattened image as psd-tools composites it.

Usage: make_fixtures.py OUT_DIR | --krita-source FILE.psd | --pivots FILE.psd
                         | --bundled FILE.psd

Writes (all small):
  character.psd           RGB, groups (arm_l/upper, arm_l/hand), a hidden layer, an [ignore]
                          tagged layer, a half-opaque layer, one layer per channel compression
                          (raw, RLE, ZIP, ZIP with prediction), a layer partly off the canvas
  character.composite.png psd-tools' composite() of character.psd (the tool's flattening)
  character.psb           the same document saved as PSB (version 2)
  gray.psd                grayscale with alpha
  gray.composite.png
  deep16.psd              16-bit: must be refused
  cmyk.psd                CMYK: must be refused
  pivots.psd              a torso and an arm group (upper, forearm) whose "shoulder [origin]"
                          layer marks the arm's bone origin, away from where the parts overlap
  spine/character.json + spine/*.png
                          the layout GimpToSpine.py writes (trimmed PNGs, centre positions
                          relative to the canvas's bottom centre, y up), from character.psd
  bundled_character.psd   the bundled demo character (assets/character): 512x512 RGB, one RLE
                          pixel layer per name in layers.json, same names, same order (first =
                          bottom), each trimmed to its non-transparent bounding box and placed at
                          its offset, alpha as the transparency channel, no masks (as Photoshop
                          stores layers); merged composite on white
                          (--bundled FILE.psd writes just this one)
"""

import json
import math
import os
import sys

import numpy as np
from PIL import Image, ImageDraw
from psd_tools import PSDImage
from psd_tools.api.layers import Group, PixelLayer
from psd_tools.constants import Compression

W, H = 120, 160
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CHARACTER = os.path.join(ROOT, "assets", "character")


def shape(size, color, kind="ellipse", alpha=255):
    """An RGBA image of `size` with a soft-edged shape, so that edges carry partial alpha."""
    im = Image.new("RGBA", size, (0, 0, 0, 0))
    d = ImageDraw.Draw(im)
    box = (1, 1, size[0] - 2, size[1] - 2)
    fill = tuple(color) + (alpha,)
    if kind == "ellipse":
        d.ellipse(box, fill=fill)
    else:
        d.rounded_rectangle(box, radius=4, fill=fill)
    # A gradient in red across the shape, so that misplaced pixels show.
    a = np.array(im)
    ramp = np.linspace(0, 60, size[0]).astype(np.uint8)
    a[..., 0] = np.clip(a[..., 0].astype(int) + ramp[None, :], 0, 255)
    # Anti-aliased rim: halve alpha on the outermost opaque pixels.
    alpha_ch = a[..., 3]
    rim = (alpha_ch > 0) & (
        (np.roll(alpha_ch, 1, 0) == 0) | (np.roll(alpha_ch, -1, 0) == 0)
        | (np.roll(alpha_ch, 1, 1) == 0) | (np.roll(alpha_ch, -1, 1) == 0)
    )
    alpha_ch[rim] = alpha_ch[rim] // 2
    return Image.fromarray(a, "RGBA")


def character(mode="RGB", version=1):
    psd = PSDImage.new(mode, (W, H), color=0, compression=Compression.RLE)
    # PSB (version 2) before any layer is added, so that channels are encoded for PSB.
    psd._record.header.version = version
    conv = (lambda im: im) if mode == "RGB" else (lambda im: im.convert("LA"))
    PixelLayer.frompil(conv(shape((50, 70), (40, 90, 200), "rect")), psd, "torso", top=50,
                       left=35, compression=Compression.RAW)
    arm = Group.new(psd, "arm_l")
    PixelLayer.frompil(conv(shape((18, 45), (200, 150, 60), "rect")), arm, "upper", top=55,
                       left=80, compression=Compression.RLE)
    PixelLayer.frompil(conv(shape((20, 20), (230, 180, 120))), arm, "hand", top=96, left=78,
                       compression=Compression.ZIP)
    head = PixelLayer.frompil(conv(shape((44, 44), (240, 200, 170))), psd, "head", top=8,
                              left=38, compression=Compression.ZIP_WITH_PREDICTION)
    head.opacity = 200
    # Half off the canvas's left edge: pixels outside the canvas are not drawn.
    PixelLayer.frompil(conv(shape((30, 16), (20, 160, 40))), psd, "leaf", top=130, left=-12,
                       compression=Compression.RLE)
    sketch = PixelLayer.frompil(conv(shape((100, 140), (0, 0, 0), alpha=128)), psd, "sketch",
                                top=10, left=10, compression=Compression.RLE)
    sketch.visible = False
    PixelLayer.frompil(conv(shape((30, 30), (255, 0, 255))), psd, "guides [ignore]", top=0,
                       left=0, compression=Compression.RLE)
    return psd


def composite_png(psd, path, ignore_tagged):
    """psd-tools' flattening of the visible layers (tagged `[ignore]` ones hidden first: sinew
    drops them, Photoshop would draw them)."""
    for layer in psd.descendants():
        if ignore_tagged and "[ignore]" in layer.name:
            layer.visible = False
    im = psd.composite(ignore_preview=True, force=True)
    im.convert("RGBA").save(path)


def spine_layout(psd, out):
    """GimpToSpine.py's output for `psd`'s visible pixel layers: NAME.png trimmed, and
    a skeleton JSON whose attachments are centred relative to the canvas's bottom centre."""
    # GimpToSpine saves the PNGs beside the JSON (no "skeleton.images" path).
    images = out
    os.makedirs(images, exist_ok=True)
    slots, attachments = [], {}
    for layer in psd.descendants():
        if layer.is_group() or not layer.is_visible() or "[ignore]" in layer.name:
            continue
        # composite(): the layer alone, with its transparency (topil() of a psd-tools layer
        # reads the user-mask channel psd-tools writes as alpha).
        im = layer.composite().convert("RGBA")
        name = layer.name
        im.save(os.path.join(images, name + ".png"))
        x, y = layer.left, layer.top
        x += math.floor(layer.width / 2)
        y += math.floor(layer.height / 2)
        x -= math.floor(W / 2)
        y = H - y
        slots.insert(0, {"name": name, "bone": "root", "attachment": name})
        attachments[name] = {name: {"x": x, "y": y, "rotation": 0, "width": layer.width,
                                    "height": layer.height}}
    slots.reverse()
    doc = {"bones": [{"name": "root"}], "slots": slots,
           "skins": {"default": attachments}, "animations": {}}
    with open(os.path.join(out, "character.json"), "w") as f:
        json.dump(doc, f, indent=1)


def main(out):
    os.makedirs(out, exist_ok=True)
    psd = character()
    psd.save(os.path.join(out, "character.psd"))
    composite_png(PSDImage.open(os.path.join(out, "character.psd")),
                  os.path.join(out, "character.composite.png"), ignore_tagged=True)
    psb = character(version=2)
    psb.save(os.path.join(out, "character.psb"))
    gray = character("L")
    gray.save(os.path.join(out, "gray.psd"))
    composite_png(PSDImage.open(os.path.join(out, "gray.psd")),
                  os.path.join(out, "gray.composite.png"), ignore_tagged=True)
    PSDImage.new("RGB", (4, 4), depth=16).save(os.path.join(out, "deep16.psd"))
    PSDImage.new("CMYK", (4, 4)).save(os.path.join(out, "cmyk.psd"))
    spine_layout(PSDImage.open(os.path.join(out, "character.psd")), os.path.join(out, "spine"))
    pivots(os.path.join(out, "pivots.psd"))
    bundled(os.path.join(out, "bundled_character.psd"))


def pivots(path):
    """An arm group with a pivot layer: the shoulder dot (centre (76, 51)) lies on the upper
    arm, 16 px from the centre of its overlap with the torso ((60, 51)), where a bone would
    start without it."""
    psd = PSDImage.new("RGB", (W, H), color=0, compression=Compression.RLE)
    PixelLayer.frompil(shape((40, 90), (40, 90, 200), "rect"), psd, "torso", top=40, left=30,
                       compression=Compression.RLE)
    arm = Group.new(psd, "arm_l")
    PixelLayer.frompil(shape((62, 14), (200, 150, 60), "rect"), arm, "upper", top=44, left=50,
                       compression=Compression.RLE)
    PixelLayer.frompil(shape((14, 50), (230, 180, 120), "rect"), arm, "forearm", top=50,
                       left=100, compression=Compression.RLE)
    PixelLayer.frompil(shape((4, 4), (255, 0, 0)), arm, "shoulder [origin]", top=49, left=74,
                       compression=Compression.RLE)
    psd.save(path)


def bundled(path):
    """assets/character's layers (512x512 straight-alpha PNGs, named back to front in
    layers.json) as a layered PSD: each layer cropped to the box of its non-transparent pixels
    and placed at that box's offset, alpha in its transparency channel (no layer mask), RLE
    compressed; the merged image is psd-tools' composite() over white (as Photoshop's
    "maximize compatibility" composite)."""
    with open(os.path.join(CHARACTER, "layers.json")) as f:
        doc = json.load(f)
    w, h = doc["canvas"]
    psd = PSDImage.new("RGB", (w, h), color=255, compression=Compression.RLE)
    for name in doc["layers"]:
        im = Image.open(os.path.join(CHARACTER, name + ".png")).convert("RGBA")
        assert im.size == (w, h), (name, im.size)
        box = im.getchannel("A").getbbox()
        assert box is not None, name
        # fromarray() with a fourth channel stores it as the layer's transparency channel,
        # as Photoshop does (frompil() on an RGB document stores it as a user mask instead).
        PixelLayer.fromarray(np.asarray(im.crop(box)), psd, name, top=box[1], left=box[0],
                             compression=Compression.RLE)
    psd.save(path)


def krita_source(path):
    """The character with its `[ignore]` layer hidden: what Krita opens and re-exports (Krita
    draws every visible layer in its merged image; sinew drops tagged ones)."""
    psd = character()
    for layer in psd.descendants():
        if "[ignore]" in layer.name:
            layer.visible = False
    psd.save(path)


if __name__ == "__main__":
    if sys.argv[1] == "--krita-source":
        krita_source(sys.argv[2])
    elif sys.argv[1] == "--pivots":
        pivots(sys.argv[2])
    elif sys.argv[1] == "--bundled":
        bundled(sys.argv[2])
    else:
        main(sys.argv[1])
