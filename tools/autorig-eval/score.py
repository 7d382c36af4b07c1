#!/usr/bin/env python3
"""Scores `sinew autorig` proposals against the evaluation set's reference joints.

Usage: score.py SINEW_BINARY SET_DIR OUT_DIR [--rig] [--label NAME]

For every character of SET_DIR/index.json (written by make_set.py) it runs
`SINEW autorig NAME.png -o OUT_DIR/NAME.handles.json --preview OUT_DIR/NAME.preview.png` with
the character's `autorig_args`, then measures:

- joint error: for each reference joint, the distance to the nearest bone end (head or tail),
  relative to the character's height (the height of its opaque pixels' box);
- bones: how many, and whether that lies in the character's budget;
- bones inside: every bone, sampled every 0.5 px, on pixels of the drawing as `sinew rig` traces
  it (alpha >= 1, grown by the trace padding of 2 px);
- pieces reached: connected pieces of that grown drawing (at least 8 px², the trace's minimum
  area) with some bone on them;
- with --rig: whether `SINEW rig NAME.png --handles ... -o ...` then builds the rig (weights
  for every piece), and the one-line warning it printed if any.

Writes OUT_DIR/scores.json and prints a Markdown table with the median and distribution.
"""
import json
import math
import statistics
import subprocess
import sys
from pathlib import Path

from PIL import Image, ImageChops

ALPHA_THRESHOLD = 1  # TraceOptions::alpha_threshold default
PADDING_PX = 2.0  # TraceOptions::padding_px default
MIN_AREA_PX2 = 8  # TraceOptions::min_area_px2 default
LIMBS = [f"{p}_{s}" for p in ("arm_upper", "arm_lower", "leg_upper", "leg_lower") for s in "lr"]
LEGS = [f"leg_{e}_{p}_{s}" for e in ("front", "back") for p in ("upper", "lower") for s in "lr"]
# The bones a template fit names (a fit that fell back, or lost a bone, names fewer).
NAMED = {
    "humanoid": ["hip", "chest", "neck", "head"] + LIMBS,
    "quadruped": ["hip", "chest", "neck", "head", "tail_1"] + LEGS,
}


def grown_mask(image):
    """The opaque pixels grown by the pixel disk of PADDING_PX (as the tracer dilates)."""
    alpha = image.getchannel("A").point(lambda a: 255 if a >= ALPHA_THRESHOLD else 0)
    out = alpha.copy()
    r = int(math.floor(PADDING_PX))
    w, h = alpha.size
    for dy in range(-r, r + 1):
        for dx in range(-r, r + 1):
            if (dx, dy) == (0, 0) or dx * dx + dy * dy > PADDING_PX * PADDING_PX:
                continue
            shifted = Image.new("L", (w, h), 0)
            shifted.paste(alpha, (dx, dy))
            out = ImageChops.lighter(out, shifted)
    return out


def components(mask):
    """Per pixel a piece id (8-connected) or -1, and each piece's area."""
    w, h = mask.size
    px = mask.load()
    label = [-1] * (w * h)
    areas = []
    for y0 in range(h):
        for x0 in range(w):
            if px[x0, y0] == 0 or label[y0 * w + x0] != -1:
                continue
            k = len(areas)
            stack = [(x0, y0)]
            label[y0 * w + x0] = k
            area = 0
            while stack:
                x, y = stack.pop()
                area += 1
                for dx in (-1, 0, 1):
                    for dy in (-1, 0, 1):
                        nx, ny = x + dx, y + dy
                        if 0 <= nx < w and 0 <= ny < h and px[nx, ny] and label[ny * w + nx] == -1:
                            label[ny * w + nx] = k
                            stack.append((nx, ny))
            areas.append(area)
    return label, areas


def bone_samples(bone):
    (hx, hy), (tx, ty) = bone["head"], bone["tail"]
    n = max(1, int(math.ceil(math.hypot(tx - hx, ty - hy) * 2)))
    return [(hx + (tx - hx) * s / n, hy + (ty - hy) * s / n) for s in range(n + 1)]


def score_one(sinew, set_dir, out_dir, name, rig):
    meta = json.loads((set_dir / f"{name}.json").read_text())
    png = set_dir / f"{name}.png"
    handles_path = out_dir / f"{name}.handles.json"
    cmd = [sinew, "autorig", str(png), "-o", str(handles_path), "--preview",
           str(out_dir / f"{name}.preview.png")] + meta["autorig_args"]
    run = subprocess.run(cmd, capture_output=True, text=True)
    result = {"name": name, "kind": meta["kind"], "budget": meta["budget"]}
    if run.returncode != 0:
        result["error"] = run.stderr.strip()
        return result
    handles = json.loads(handles_path.read_text())
    bones = handles["bones"]
    image = Image.open(png).convert("RGBA")
    box = image.getchannel("A").point(lambda a: 255 if a >= ALPHA_THRESHOLD else 0).getbbox()
    height = box[3] - box[1]
    mask = grown_mask(image)
    w, h = mask.size
    label, areas = components(mask)
    mpx = mask.load()
    outside = []
    reached = set()
    for b in bones:
        inside = True
        for x, y in bone_samples(b):
            i, j = int(math.floor(x)), int(math.floor(y))
            if not (0 <= i < w and 0 <= j < h and mpx[i, j]):
                inside = False
            else:
                reached.add(label[j * w + i])
        if not inside:
            outside.append(b["name"])
    pieces = [k for k, a in enumerate(areas) if a >= MIN_AREA_PX2]
    ends = [p for b in bones for p in (b["head"], b["tail"])]
    errors = {}
    for joint, (x, y) in meta["joints"].items():
        d = min((math.hypot(x - ex, y - ey) for ex, ey in ends), default=float("inf"))
        errors[joint] = d / height
    names = {b["name"] for b in bones}
    expected = NAMED.get(meta["kind"], [])
    lo, hi = meta["budget"]
    result.update(
        height_px=height,
        bones=len(bones),
        in_budget=lo <= len(bones) <= hi,
        bones_outside=outside,
        pieces=len(pieces),
        pieces_reached=len([k for k in pieces if k in reached]),
        joint_errors=errors,
        median_joint_error=statistics.median(errors.values()),
        max_joint_error=max(errors.values()),
        named=f"{len([n for n in expected if n in names])}/{len(expected)}" if expected else "–",
        shortest_bone_px=min(math.hypot(b["tail"][0] - b["head"][0], b["tail"][1] - b["head"][1]) for b in bones),
    )
    if rig:
        rig_out = out_dir / f"{name}.rig.json"
        run = subprocess.run([sinew, "rig", str(png), "--handles", str(handles_path), "-o", str(rig_out)],
                             capture_output=True, text=True)
        result["rig_ok"] = run.returncode == 0
        result["rig_message"] = (run.stderr.strip() or "")[:300]
    return result


def pct(xs, q):
    xs = sorted(xs)
    if not xs:
        return float("nan")
    k = (len(xs) - 1) * q
    f = math.floor(k)
    c = min(f + 1, len(xs) - 1)
    return xs[f] + (xs[c] - xs[f]) * (k - f)


def main():
    args = sys.argv[1:]
    rig = "--rig" in args
    label = "sinew"
    if "--label" in args:
        label = args[args.index("--label") + 1]
        del args[args.index("--label"):args.index("--label") + 2]
    args = [a for a in args if a != "--rig"]
    sinew, set_dir, out_dir = args[0], Path(args[1]), Path(args[2])
    out_dir.mkdir(parents=True, exist_ok=True)
    names = json.loads((set_dir / "index.json").read_text())
    results = [score_one(sinew, set_dir, out_dir, n, rig) for n in names]
    (out_dir / "scores.json").write_text(json.dumps(results, indent=1) + "\n")
    ok = [r for r in results if "error" not in r]
    all_errors = [e for r in ok for e in r["joint_errors"].values()]
    print(f"### {label}\n")
    print("| character | kind | bones (budget) | bones outside | pieces reached | median joint error | max joint error | shortest bone px | template bones named |" + (" rig |" if rig else ""))
    print("|---|---|---|---|---|---|---|---|---|" + ("---|" if rig else ""))
    for r in results:
        if "error" in r:
            print(f"| {r['name']} | {r['kind']} | autorig failed: {r['error']} ||||||" + ("|" if rig else ""))
            continue
        row = (f"| {r['name']} | {r['kind']} | {r['bones']} ({r['budget'][0]}–{r['budget'][1]}){'' if r['in_budget'] else ' ✗'} "
               f"| {len(r['bones_outside'])} | {r['pieces_reached']}/{r['pieces']} "
               f"| {100 * r['median_joint_error']:.1f} % | {100 * r['max_joint_error']:.1f} % | {r['shortest_bone_px']:.1f} | {r['named']} |")
        if rig:
            row += " ok |" if r["rig_ok"] else f" fails: {r['rig_message']} |"
        print(row)
    print()
    print(f"- characters: {len(results)}, autorig failed on {len(results) - len(ok)}")
    print(f"- within the bone budget: {sum(r['in_budget'] for r in ok)}/{len(ok)}")
    print(f"- every bone inside: {sum(not r['bones_outside'] for r in ok)}/{len(ok)}"
          f" ({sum(len(r['bones_outside']) for r in ok)} bones outside in all)")
    print(f"- every piece reached: {sum(r['pieces_reached'] == r['pieces'] for r in ok)}/{len(ok)}")
    if rig:
        print(f"- `sinew rig` builds the rig: {sum(r['rig_ok'] for r in ok)}/{len(ok)}")
    if all_errors:
        print(f"- joint error over all {len(all_errors)} reference joints (% of height): median "
              f"{100 * statistics.median(all_errors):.1f}, quartiles {100 * pct(all_errors, 0.25):.1f} / "
              f"{100 * pct(all_errors, 0.75):.1f}, 90th percentile {100 * pct(all_errors, 0.9):.1f}, "
              f"max {100 * max(all_errors):.1f}")
        med = [r["median_joint_error"] for r in ok]
        print(f"- per-character median joint error (% of height): median {100 * statistics.median(med):.1f}, "
              f"max {100 * max(med):.1f}")


if __name__ == "__main__":
    main()
