#!/usr/bin/env python3
"""Extracts the real-art autorig set from Debian packages into tests/fixtures/autorig-real/.

Usage: make_set.py PKG_DIR OUT_DIR [NAME...]

PKG_DIR holds each package unpacked by `dpkg-deb -x PKG.deb PKG_DIR/PKG` (fetch.sh does it
with `apt-get download`). For every character of CHARACTERS (or only the NAMEs given) it cuts
one character out of the package's file, as a PNG with straight alpha on a canvas with a
MARGIN px transparent border: SVGs are rasterized with rsvg-convert at a fixed height, sprite
sheets are cropped to one frame and upscaled with nearest neighbour, sprites' baked shadows
(near-black, translucent) are removed, and only the character's pieces are kept (connected
pieces of at least `min_piece` px). Writes OUT_DIR/NAME.png and OUT_DIR/sources.json (package,
version, path, licence, author per character). The same packages give the same pixels: the
reference joints and layer polygons of OUT_DIR/NAME.json are in these PNGs' canvas px.
"""
import io
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
from PIL import Image

MARGIN = 12

TUXPAINT = ("tuxpaint-stamps-default", "2022.06.04-1", "usr/share/tuxpaint/stamps/",
            "GPL-2 (debian/copyright: Files: *, Copyright 2002-2022 Bill Kendrick and the Tux Paint stamp contributors)")
OPENCLIPART = ("openclipart-svg", "1:0.18+dfsg-19", "usr/share/openclipart/svg/",
               "Public domain (Creative Commons Public Domain Dedication, debian/copyright)")
FLARE = ("flare-game", "1.14-1", "usr/share/games/flare/mods/",
         "CC-BY-SA-3.0+ (debian/copyright: Files: *, Copyright 2012-2021 Clint Bellanger and others)")
PINGUS = ("pingus-data", "0.7.6-5.1", "usr/share/games/pingus/data/images/pingus/player0/",
          "GPL-2+ (debian/copyright: Copyright 1999-2007 Ingo Ruhnke and others)")
TEEWORLDS = ("teeworlds-data", "0.7.5-2", "usr/share/games/teeworlds/data/skins/",
             "CC-BY-SA-3.0 (debian/copyright: Files: data/*, Copyright Magnus Auvinen and contributors)")

# Who drew it, where the file itself does not say (SVG metadata `dc:creator` wins).
DEFAULT_AUTHOR = {
    "tuxpaint-stamps-default": "not stated per file (Tux Paint stamp contributors, debian/copyright)",
    "openclipart-svg": "not stated in the file",
    "flare-game": "Flare contributors (credits.txt: lead visual artists Clint Bellanger, Justin Nichol)",
    "pingus-data": "Pingus contributors (debian/copyright: Ingo Ruhnke and others)",
    "teeworlds-data": "Teeworlds contributors (debian/copyright: Magnus Auvinen and contributors)",
}

# name: (package, source kind, path under the package's data folder, options)
CHARACTERS = {
    # Tux Paint stamps
    "man_in_suit": (TUXPAINT, "svg", "people/cartoon/man_in_suit.svg", {"height": 400}),
    "scarecrow": (TUXPAINT, "svg", "people/cartoon/scarecrow.svg", {"height": 400}),
    "woman_doctor": (TUXPAINT, "svg", "people/cartoon/woman_doctor.svg", {"height": 400}),
    "woman_police": (TUXPAINT, "svg", "people/cartoon/woman_police_officer_1.svg", {"height": 400}),
    "woman_chemist": (TUXPAINT, "svg", "people/cartoon/woman_chemist.svg", {"height": 400}),
    "teddy_bear": (TUXPAINT, "png", "animals/mammals/bears/cartoon/teddy_bear.png", {"scale": 1}),
    "cheetah": (TUXPAINT, "svg", "animals/mammals/cats/cheetah.svg", {"height": 220}),
    "zebra": (TUXPAINT, "svg", "animals/mammals/equines/zebra2.svg", {"height": 320}),
    "swallow": (TUXPAINT, "svg", "animals/birds/swallow.svg", {"height": 300}),
    "kite": (TUXPAINT, "svg", "hobbies/kite.svg", {"height": 360}),
    # Open Clip Art Library
    "kid": (OPENCLIPART, "svg", "people/kid_01.svg", {"height": 1000}),
    "chibi_girl": (OPENCLIPART, "svg", "people/chibi_character_rick_.svg", {"height": 1000}),
    "man_walking": (OPENCLIPART, "svg", "people/man_01.svg", {"height": 420}),
    "buddy": (OPENCLIPART, "svg", "people/buddy01.svg", {"height": 300}),
    "police_man": (OPENCLIPART, "svg", "people/police_man_ganson.svg", {"height": 400}),
    "clown": (OPENCLIPART, "svg", "people/brozo_the_clown_enrique__01.svg", {"height": 420}),
    "bull": (OPENCLIPART, "svg", "animals/mammals/bull_utrescu_.svg", {"height": 300}),
    "pig": (OPENCLIPART, "svg", "animals/mammals/pig_marcelo_caiafa1.svg", {"height": 400}),
    "cow": (OPENCLIPART, "svg", "animals/mammals/vacca_pezzata_rossa_val_01.svg", {"height": 300}),
    "lion": (OPENCLIPART, "svg", "animals/mammals/big_cats/leone_01_architetto_fran_01.svg", {"height": 320}),
    "cat": (OPENCLIPART, "svg", "animals/mammals/cartoon_cat_gerald_g._01.svg", {"height": 300}),
    "beagle": (OPENCLIPART, "svg", "animals/mammals/dogs/beagle_copper_ganson.svg", {"height": 320}),
    "fawn": (OPENCLIPART, "svg", "animals/mammals/fawn_mo_01.svg", {"height": 600}),
    "fish": (OPENCLIPART, "svg", "animals/fish/clown_loach_01.svg", {"height": 300}),
    # Flare (sprite sheets: one frame of the stance animation; portraits)
    "goblin": (FLARE, "flare", "fantasycore/animations/enemies/goblin.txt", {"dir": 6, "scale": 5}),
    "skeleton": (FLARE, "flare", "fantasycore/animations/enemies/skeleton.txt", {"dir": 2, "scale": 3}),
    "minotaur": (FLARE, "flare", "fantasycore/animations/enemies/minotaur.txt", {"dir": 6, "scale": 2}),
    "zombie": (FLARE, "flare", "fantasycore/animations/enemies/zombie.txt", {"dir": 1, "scale": 3}),
    "portrait_man": (FLARE, "png", "fantasycore/images/portraits/male05.png", {"scale": 1}),
    "portrait_woman": (FLARE, "png", "fantasycore/images/portraits/female02.png", {"scale": 1}),
    # Pingus (32 px frames)
    "pingu_blocker": (PINGUS, "frame", "blocker.png", {"box": [0, 0, 32, 32], "scale": 5}),
    "pingu_walker": (PINGUS, "frame", "walker.png", {"box": [0, 32, 32, 64], "scale": 5}),
    # Teeworlds (a tee put together from its skin's parts as the game draws it)
    "tee": (TEEWORLDS, "tee", "body/standard.png", {"color": [255, 210, 140]}),
    "tee_kitty": (TEEWORLDS, "tee", "body/kitty.png", {"color": [190, 200, 255]}),
}


def rasterize_svg(path, height):
    png = subprocess.run(["rsvg-convert", "-h", str(height), str(path)], check=True,
                         capture_output=True).stdout
    return Image.open(io.BytesIO(png)).convert("RGBA")


def flare_frame(mod_dir, anim_txt, direction):
    txt = (mod_dir / anim_txt).read_text()
    image = re.search(r"^image=(\S+)", txt, re.M).group(1)
    sheet = Image.open(mod_dir / anim_txt.split("/")[0] / image).convert("RGBA")
    stance = txt.split("[stance]")[1].split("\n[")[0]
    for line in stance.splitlines():
        if line.startswith("frame="):
            f = [int(v) for v in line.split("=")[1].split(",")]
            if f[0] == 0 and f[1] == direction:
                return sheet.crop((f[2], f[3], f[2] + f[4], f[3] + f[5])), image
    raise SystemExit(f"{anim_txt}: no stance frame 0 in direction {direction}")


def tint(image, color):
    a = np.asarray(image, dtype=np.float32).copy()
    a[..., :3] = a[..., :3] * np.array(color, dtype=np.float32) / 255.0
    return Image.fromarray(a.clip(0, 255).astype(np.uint8), "RGBA")


def tee(skins, body_file, color):
    """A tee as the game draws it standing: the body (colored fill, shading, outline), the eyes,
    one hand beside it and two feet below it, the back foot darker, all apart."""
    body = Image.open(skins / body_file).convert("RGBA")
    feet = Image.open(skins / "feet/standard.png").convert("RGBA")
    hands = Image.open(skins / "hands/standard.png").convert("RGBA")
    eyes = Image.open(skins / "eyes/standard.png").convert("RGBA")
    canvas = Image.new("RGBA", (300, 300), (0, 0, 0, 0))

    def paste(img, x, y):
        canvas.alpha_composite(img, (x, y))

    # body sheet 256x256: outline (0,0), fill (128,0), shading (0,128), upper outline (128,128);
    # feet and hands sheets: the colored piece (0,0) and its outline (64,0), 64x64 each
    outline = body.crop((0, 0, 128, 128))
    fill = tint(body.crop((128, 0, 256, 128)), color)
    shade = body.crop((0, 128, 128, 256))
    upper = body.crop((128, 128, 256, 256))
    foot, foot_outline = feet.crop((0, 0, 64, 64)), feet.crop((64, 0, 128, 64))
    hand, hand_outline = hands.crop((0, 0, 64, 64)), hands.crop((64, 0, 128, 64))
    dark = [c * 0.7 for c in color]
    # back foot (darker), body, front foot, hand, eyes: back to front
    paste(foot_outline, 92, 182)
    paste(tint(foot, dark), 92, 182)
    paste(outline, 86, 78)
    paste(fill, 86, 78)
    paste(shade, 86, 78)
    paste(upper, 86, 78)
    paste(foot_outline, 146, 186)
    paste(tint(foot, color), 146, 186)
    paste(hand_outline, 206, 118)
    paste(tint(hand, color), 206, 118)
    paste(eyes.crop((0, 0, 64, 32)), 150, 112)
    return canvas


def clean(image, shadows, min_piece):
    a = np.asarray(image).copy()
    if shadows:
        dark = a[..., :3].max(axis=-1) < 40
        a[dark & (a[..., 3] < 230), 3] = 0
    a[a[..., 3] == 0] = 0
    alpha = a[..., 3] > 0
    # keep pieces of at least min_piece px (8-connected)
    h, w = alpha.shape
    label = np.full((h, w), -1, dtype=np.int32)
    sizes = []
    for y0, x0 in zip(*np.nonzero(alpha)):
        if label[y0, x0] != -1:
            continue
        k = len(sizes)
        stack = [(y0, x0)]
        label[y0, x0] = k
        n = 0
        while stack:
            y, x = stack.pop()
            n += 1
            for dy in (-1, 0, 1):
                for dx in (-1, 0, 1):
                    ny, nx = y + dy, x + dx
                    if 0 <= ny < h and 0 <= nx < w and alpha[ny, nx] and label[ny, nx] == -1:
                        label[ny, nx] = k
                        stack.append((ny, nx))
        sizes.append(n)
    keep = np.array([s >= min_piece for s in sizes] + [False])
    a[~keep[label]] = 0
    return Image.fromarray(a, "RGBA")


def trim(image):
    box = image.getchannel("A").getbbox()
    image = image.crop(box)
    out = Image.new("RGBA", (image.width + 2 * MARGIN, image.height + 2 * MARGIN), (0, 0, 0, 0))
    out.paste(image, (MARGIN, MARGIN))
    return out


def svg_author(path):
    text = path.read_text(errors="replace")
    m = re.search(r"<dc:creator>\s*<cc:Agent>\s*<dc:title>([^<]*)</dc:title>", text)
    return m.group(1).strip() if m and m.group(1).strip() else None


def build(pkg_dir, name):
    (package, version, base, licence), kind, rel, opt = CHARACTERS[name]
    data = pkg_dir / package / base
    path = data / rel
    source = {"package": package, "version": version, "path": "/" + base + rel, "licence": licence}
    shadows, min_piece = False, 1
    if kind == "svg":
        image = rasterize_svg(path, opt["height"])
        source["rasterized"] = f"rsvg-convert -h {opt['height']}"
        author = svg_author(path)
        if author:
            source["author"] = author
        min_piece = 20
    elif kind == "png":
        image = Image.open(path).convert("RGBA")
    elif kind == "flare":
        image, sheet = flare_frame(pkg_dir / package / base, rel, opt["dir"])
        source["path"] = "/" + base + rel.split("/")[0] + "/" + sheet
        source["frame"] = f"{rel.split('/')[-1]}: [stance] frame 0, direction {opt['dir']}"
        shadows, min_piece = True, 4
    elif kind == "frame":
        image = Image.open(path).convert("RGBA").crop(opt["box"])
        source["frame"] = f"box {opt['box']}"
    elif kind == "tee":
        image = tee(data, rel, opt["color"])
        source["path"] = "/" + base + rel + ", feet/standard.png, hands/standard.png, eyes/standard.png"
        source["composed"] = "body, eyes, one hand and two feet placed as the game draws a standing tee; tint " + str(opt["color"])
    else:
        raise SystemExit(kind)
    if "author" not in source:
        source["author"] = DEFAULT_AUTHOR[package]
        if "ganson" in rel:
            source["author"] = "ganson (Open Clip Art user, from the file name)"
    scale = opt.get("scale", 1)
    if scale != 1:
        image = image.resize((image.width * scale, image.height * scale), Image.NEAREST)
        source["upscaled"] = f"x{scale} nearest neighbour"
    image = trim(clean(image, shadows, min_piece * scale * scale))
    return image, source


def main():
    pkg_dir, out_dir = Path(sys.argv[1]), Path(sys.argv[2])
    names = sys.argv[3:] or list(CHARACTERS)
    out_dir.mkdir(parents=True, exist_ok=True)
    sources_path = out_dir / "sources.json"
    sources = json.loads(sources_path.read_text()) if sources_path.exists() else {}
    for name in names:
        image, source = build(pkg_dir, name)
        image.save(out_dir / f"{name}.png", optimize=True)
        sources[name] = source
        print(f"{name}: {image.width}x{image.height}", file=sys.stderr)
    sources = {k: sources[k] for k in CHARACTERS if k in sources}
    sources_path.write_text(json.dumps(sources, indent=1, ensure_ascii=False) + "\n")


if __name__ == "__main__":
    main()
