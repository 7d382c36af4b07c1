#!/usr/bin/env python3
"""Runs every method on the colorize evaluation set and prints the results table.

Usage: score.py SINEW_BINARY SET_DIR OUT_DIR [--methods a,b,...]

Methods (each a process per case, timed wall-clock including reading and writing PNGs):
- sinew-flat, sinew-soft: `sinew colorize LINEART --scribbles S.png -o OUT [--fill soft]`;
- gmic-smart: G'MIC "Colorize Lineart [Smart Coloring]" (fx_colorize_lineart_smart, mode
  "Extrapolate Color Spots on Transparent Top Layer", the filter's defaults otherwise);
- gmic-propagation: G'MIC "Colorize Lineart [Propagation]" (fx_colorize_lineart, defaults);
  (env SINEW_ARGS: more arguments for sinew, e.g. "--split weights");
- flood: the paint bucket from every scribble pixel, in palette order, between line pixels
  (ink ≥ 0.5), 4-connected (not timed).

Score: each method's fill multiplied by the line art (as sinew composites opaque line art,
and as G'MIC's filters set their line layer to multiply) against the truth multiplied the
same way; the share of scored pixels (NAME.scored.png: ink < 0.5) whose largest channel
difference is ≤ 16/255. Writes OUT_DIR/scores.json and every output image.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np
from PIL import Image
from scipy import ndimage

TOLERANCE = 16
GMIC_SMART_ARGS = "1,95,0,0,1,24,200,0,75,2,60,20,90,1,10,1,0"
GMIC_PROPAGATION_ARGS = "0,2,0,0.05"
SUBSETS = ["closed", "gaps", "undrawn"]
# The issue's set: "a third of the cases have color boundaries that the line art does not draw,
# or gaps"; ours has a third of each subset.
ISSUE_MIX = {"closed": 2 / 3, "gaps": 1 / 6, "undrawn": 1 / 6}
ALL_METHODS = ["sinew-flat", "sinew-soft", "gmic-smart", "gmic-propagation", "flood"]


def load_rgb(path):
    return np.asarray(Image.open(path).convert("RGB"), dtype=np.int32)


def run_timed(cmd):
    t0 = time.perf_counter()
    done = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    seconds = time.perf_counter() - t0
    if done.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed: {done.stderr.decode(errors='replace').strip()}")
    return seconds


def flood(lineart, scribbles):
    ink = 1.0 - lineart.mean(2) / 255.0
    open_px = ink < 0.5
    comp, _ = ndimage.label(open_px)
    fill = np.full(lineart.shape, 255, np.int32)
    alpha = scribbles[..., 3] > 0
    colors = []
    for c in map(tuple, scribbles[..., :3][alpha]):
        if c not in colors:
            colors.append(c)
    taken = np.zeros(comp.max() + 1, bool)
    taken[0] = True
    for c in colors:
        here = alpha & (scribbles[..., :3] == c).all(2) & open_px
        for r in np.unique(comp[here]):
            if not taken[r]:
                fill[comp == r] = c
                taken[r] = True
    return fill


def method_fill(method, sinew, case_base, out_base):
    """The method's fill (for G'MIC and flood) or composite (sinew) and its seconds."""
    lineart = case_base + ".lineart.png"
    scribbles = case_base + ".scribbles.png"
    if method.startswith("sinew"):
        out = out_base + f".{method}.png"
        cmd = [sinew, "colorize", lineart, "--scribbles", scribbles, "-o", out]
        if method == "sinew-soft":
            cmd += ["--fill", "soft"]
        cmd += os.environ.get("SINEW_ARGS", "").split()
        seconds = run_timed(cmd)
        return load_rgb(out), True, seconds
    if method.startswith("gmic"):
        out = out_base + f".{method}.png"
        if method == "gmic-smart":
            cmd = ["gmic", scribbles, lineart, "fx_colorize_lineart_smart", GMIC_SMART_ARGS, "-o[2]", out]
        else:
            cmd = ["gmic", scribbles, lineart, "fx_colorize_lineart", GMIC_PROPAGATION_ARGS, "-o[1]", out]
        seconds = run_timed(cmd)
        return load_rgb(out), False, seconds
    art = load_rgb(lineart)
    s = np.asarray(Image.open(scribbles).convert("RGBA"), dtype=np.int32)
    fill = flood(art, s)
    Image.fromarray(fill.astype(np.uint8), "RGB").save(out_base + ".flood.png")
    return fill, False, None


def score(image, composited, truth, art, scored):
    if not composited:
        image = (image * art + 127) // 255
    expected = (truth * art + 127) // 255
    ok = np.abs(image - expected).max(2) <= TOLERANCE
    return float(ok[scored].mean())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("sinew")
    ap.add_argument("set_dir")
    ap.add_argument("out_dir")
    ap.add_argument("--methods", default=",".join(ALL_METHODS))
    args = ap.parse_args()
    methods = args.methods.split(",")
    with open(os.path.join(args.set_dir, "cases.json")) as f:
        meta = json.load(f)
    os.makedirs(args.out_dir, exist_ok=True)
    results = {m: [] for m in methods}
    for case in meta["cases"]:
        base = os.path.join(args.set_dir, case["name"])
        out_base = os.path.join(args.out_dir, case["name"])
        truth = load_rgb(base + ".truth.png")
        art = load_rgb(base + ".lineart.png")
        scored = np.asarray(Image.open(base + ".scored.png")) > 127
        line = [case["name"]]
        for m in methods:
            image, composited, seconds = method_fill(m, args.sinew, base, out_base)
            s = score(image, composited, truth, art, scored)
            results[m].append({"name": case["name"], "subset": case["subset"], "score": s, "seconds": seconds})
            line.append(f"{m} {s:.4f}" + (f" {seconds:.2f}s" if seconds is not None else ""))
        print("  ".join(line), file=sys.stderr, flush=True)
    with open(os.path.join(args.out_dir, "scores.json"), "w") as f:
        json.dump({"size": meta["size"], "results": results}, f, indent=1)
    print_table(results, meta["size"], len(meta["cases"]))


def print_table(results, size, count):
    print(f"{count} cases at {size}²; score = share of non-line pixels within {TOLERANCE}/255 of the truth")
    print()
    print("| method | all | closed | gaps | undrawn | hard (gaps + undrawn) | issue's mix | worst case | median s |")
    print("|---|---|---|---|---|---|---|---|---|")
    rows_of = dict(results)
    if len(results) > 1:
        # The best method per case: a bound on what choosing among these methods could score.
        rows_of["best per case"] = [
            max((rows[k] for rows in results.values()), key=lambda r: r["score"]) | {"seconds": None}
            for k in range(len(next(iter(results.values()))))
        ]
    for m, rows in rows_of.items():
        def mean(pred):
            v = [r["score"] for r in rows if pred(r)]
            return statistics.fmean(v) if v else float("nan")

        secs = [r["seconds"] for r in rows if r["seconds"] is not None]
        by_subset = {s: mean(lambda r, s=s: r["subset"] == s) for s in SUBSETS}
        cells = [
            mean(lambda r: True),
            *by_subset.values(),
            mean(lambda r: r["subset"] != "closed"),
            # Weighted as the issue's own set: a third of the cases hard (half gaps, half
            # undrawn), two thirds closed.
            sum(ISSUE_MIX[s] * v for s, v in by_subset.items()),
            min(r["score"] for r in rows),
        ]
        median = f"{statistics.median(secs):.3f}" if secs else "—"
        print(f"| {m} | " + " | ".join(f"{c:.4f}" for c in cells) + f" | {median} |")


if __name__ == "__main__":
    main()
