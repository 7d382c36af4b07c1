#!/usr/bin/env python3
"""Draws the colorize evaluation set from Twemoji (CC-BY 4.0) vector art.

Usage: make_set.py TWEMOJI_SVG_DIR OUT_DIR [--size PX] [--count N] [--seed S]

Each chosen emoji is rasterized 4× oversampled (cairosvg) over white, every pixel snapped
to the emoji's flat fill colors (its palette), and the label map reduced to SIZE² by
majority. The truth is that label map's colors. The line art is drawn from it: every
boundary between two labels (background included) becomes a black line about 2 px wide,
antialiased by the 4× oversampling. Three variants per emoji, each a case:

- closed:  every color boundary drawn;
- gaps:    the same lines with GAP_COUNT openings of 3 to 5 px erased;
- undrawn: the boundary between UNDRAWN_PAIRS pair(s) of adjacent colors (neither the
           background, sharing ≥ 40 px of boundary), chosen at random, left undrawn.

Scribbles (the same in the three variants): one short stroke, 3 px wide, through the deepest
point of every connected color region of the closed variant (regions smaller than
MIN_REGION_PX get none), in the region's true color, on transparency.

Per case: NAME.lineart.png (gray ink on white, opaque), NAME.scribbles.png (RGBA),
NAME.truth.png (RGB), NAME.scored.png (255 where the pixel is scored: ink < 0.5 in that
variant's line art). cases.json lists them with their subset.
"""

import argparse
import io
import json
import os
import random

import cairosvg
import numpy as np
from PIL import Image
from scipy import ndimage

OVERSAMPLE = 4
LINE_HALF_WIDTH_PX = 1.0  # lines are 2 px wide at the final size
GAP_COUNT = 4
GAP_RADII_PX = (1.5, 2.0, 2.5)  # openings of 3 to 5 px
UNDRAWN_PAIRS = 1
MIN_REGION_PX = 12
MIN_COLOR_SHARE = 0.002  # a palette color covers at least this share of the oversampled image
MIN_PALETTE_COVER = 0.97  # emoji whose flat colors cover less (gradients) are skipped
MAX_COLORS = 12


def render(svg_path, size):
    png = cairosvg.svg2png(url=svg_path, output_width=size, output_height=size)
    rgba = np.asarray(Image.open(io.BytesIO(png)).convert("RGBA"), dtype=np.float64)
    a = rgba[..., 3:4] / 255.0
    return np.round(rgba[..., :3] * a + 255.0 * (1.0 - a)).astype(np.uint8)


def palette_labels(rgb):
    """The flat colors (share ≥ MIN_COLOR_SHARE) and every pixel's nearest one; None when the
    flat colors cover too little of the image (gradients, photos)."""
    flat = rgb.reshape(-1, 3)
    keys = (flat[:, 0].astype(np.int64) << 16) | (flat[:, 1].astype(np.int64) << 8) | flat[:, 2]
    values, counts = np.unique(keys, return_counts=True)
    keep = counts >= MIN_COLOR_SHARE * len(keys)
    if counts[keep].sum() < MIN_PALETTE_COVER * len(keys) or not 3 <= keep.sum() <= MAX_COLORS:
        return None
    palette = np.stack([(values[keep] >> 16) & 255, (values[keep] >> 8) & 255, values[keep] & 255], 1)
    d = ((flat[:, None, :].astype(np.int32) - palette[None, :, :].astype(np.int32)) ** 2).sum(2)
    return palette.astype(np.uint8), d.argmin(1).reshape(rgb.shape[:2])


def downsample_majority(labels, k, factor):
    h, w = labels.shape[0] // factor, labels.shape[1] // factor
    counts = np.zeros((k, h, w), np.int32)
    blocks = labels.reshape(h, factor, w, factor)
    for c in range(k):
        counts[c] = (blocks == c).sum((1, 3))
    return counts.argmax(0)


def boundary_pairs(labels):
    """Per oversampled pixel: the (min, max) label pair of a boundary with its right or lower
    neighbor, as one int (−1: no boundary)."""
    k = labels.max() + 1
    pair = np.full(labels.shape, -1, np.int64)
    for dy, dx in ((0, 1), (1, 0)):
        a = labels[: labels.shape[0] - dy, : labels.shape[1] - dx]
        b = labels[dy:, dx:]
        diff = a != b
        code = np.minimum(a, b) * k + np.maximum(a, b)
        region = pair[: labels.shape[0] - dy, : labels.shape[1] - dx]
        region[diff] = code[diff]
    return pair


def ink_from(boundary, factor):
    """Boundary pixels (oversampled) → antialiased ink at the final size."""
    radius = LINE_HALF_WIDTH_PX * factor
    dist = ndimage.distance_transform_edt(~boundary)
    thick = dist <= radius
    h, w = boundary.shape[0] // factor, boundary.shape[1] // factor
    return thick.reshape(h, factor, w, factor).mean((1, 3))


def scribble_for(region, rng):
    """A 3-px stroke through the deepest point of a region (bool mask): pixel coordinates."""
    dist = ndimage.distance_transform_edt(region)
    py, px = np.unravel_index(dist.argmax(), dist.shape)
    dmax = dist[py, px]
    theta = rng.uniform(0, np.pi)
    ys, xs = np.nonzero(region)
    along = (xs - px) * np.cos(theta) + (ys - py) * np.sin(theta)
    across = -(xs - px) * np.sin(theta) + (ys - py) * np.cos(theta)
    keep = (
        (np.abs(across) <= 1.5)
        & (np.abs(along) <= min(20.0, 2.0 * dmax))
        & (dist[ys, xs] >= max(1.0, 0.5 * dmax))
    )
    if not keep.any():
        keep = (ys == py) & (xs == px)
    return ys[keep], xs[keep]


def make_case(svg, size, rng):
    big = render(svg, size * OVERSAMPLE)
    pl = palette_labels(big)
    if pl is None:
        return None
    palette, labels_big = pl
    k = len(palette)
    labels = downsample_majority(labels_big, k, OVERSAMPLE)
    pairs = boundary_pairs(labels_big)
    boundary = pairs >= 0
    ink_closed = ink_from(boundary, OVERSAMPLE)
    non_line = ink_closed < 0.5
    # Regions: connected same-color pixels off the closed lines.
    scribbles = np.zeros((size, size, 4), np.uint8)
    region_count = 0
    for c in range(k):
        comp, n = ndimage.label((labels == c) & non_line)
        for r in range(1, n + 1):
            region = comp == r
            if region.sum() < MIN_REGION_PX:
                continue
            ys, xs = scribble_for(region, rng)
            scribbles[ys, xs, :3] = palette[c]
            scribbles[ys, xs, 3] = 255
            region_count += 1
    if region_count < 3:
        return None
    variants = {"closed": ink_closed}
    # Gaps: openings erased from the oversampled boundary, centered on boundary pixels.
    by, bx = np.nonzero(boundary)
    gapped = boundary.copy()
    yy, xx = np.mgrid[0 : boundary.shape[0], 0 : boundary.shape[1]]
    for _ in range(GAP_COUNT):
        i = rng.randrange(len(by))
        r = (rng.choice(GAP_RADII_PX) + LINE_HALF_WIDTH_PX) * OVERSAMPLE
        y0, x0 = by[i], bx[i]
        window = (slice(max(0, y0 - int(r) - 1), y0 + int(r) + 2), slice(max(0, x0 - int(r) - 1), x0 + int(r) + 2))
        disk = (yy[window] - y0) ** 2 + (xx[window] - x0) ** 2 <= r * r
        gapped[window][disk] = False
    variants["gaps"] = ink_from(gapped, OVERSAMPLE)
    # Undrawn: the longest-shared boundaries between two colors, neither the background.
    background = labels_big[0, 0]
    codes, lengths = np.unique(pairs[boundary], return_counts=True)
    inner = [(n, c) for c, n in zip(codes, lengths) if background not in (c // k, c % k) and n >= 40 * OVERSAMPLE]
    if len(inner) < 1:
        return None
    chosen = [c for _, c in sorted(inner)]
    rng.shuffle(chosen)
    chosen = chosen[:UNDRAWN_PAIRS]
    undrawn = boundary & ~np.isin(pairs, chosen)
    variants["undrawn"] = ink_from(undrawn, OVERSAMPLE)
    truth = palette[labels]
    return truth, scribbles, variants


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("svg_dir")
    ap.add_argument("out_dir")
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--count", type=int, default=24)
    ap.add_argument("--seed", type=int, default=26)
    args = ap.parse_args()
    os.makedirs(args.out_dir, exist_ok=True)
    names = sorted(n for n in os.listdir(args.svg_dir) if n.endswith(".svg") and "-" not in n)
    rng = random.Random(args.seed)
    rng.shuffle(names)
    cases = []
    made = 0
    for name in names:
        if made >= args.count:
            break
        case = make_case(os.path.join(args.svg_dir, name), args.size, rng)
        if case is None:
            continue
        truth, scribbles, variants = case
        stem = name[:-4]
        for subset, ink in variants.items():
            case_name = f"{stem}-{subset}"
            gray = np.round(255.0 * (1.0 - ink)).astype(np.uint8)
            Image.fromarray(gray, "L").convert("RGB").save(os.path.join(args.out_dir, case_name + ".lineart.png"))
            Image.fromarray(scribbles, "RGBA").save(os.path.join(args.out_dir, case_name + ".scribbles.png"))
            Image.fromarray(truth, "RGB").save(os.path.join(args.out_dir, case_name + ".truth.png"))
            Image.fromarray(((ink < 0.5) * 255).astype(np.uint8), "L").save(
                os.path.join(args.out_dir, case_name + ".scored.png")
            )
            cases.append({"name": case_name, "emoji": stem, "subset": subset})
        made += 1
    with open(os.path.join(args.out_dir, "cases.json"), "w") as f:
        json.dump({"size": args.size, "seed": args.seed, "cases": cases}, f, indent=1)
    print(f"{made} emoji, {len(cases)} cases in {args.out_dir}")


if __name__ == "__main__":
    main()
