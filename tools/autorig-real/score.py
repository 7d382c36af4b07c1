#!/usr/bin/env python3
"""Scores `sinew autorig` on the real-art set, flat and layered, against hand-placed references.

Usage: score.py SINEW_BINARY SET_DIR OUT_DIR [--label L] [--template-given]

For every character of SET_DIR/index.json (NAME.png, NAME.ora, NAME.json; see
docs/autorig-real-eval.md) and each of its two inputs, the flat sprite (NAME.png) and the
layered file (NAME.ora):

- runs `SINEW autorig FILE -o OUT/NAME[.layered].handles.json --preview OUT/....preview.png`
  (with --template-given: plus `--template KIND` for humanoid and quadruped characters), one at
  a time, and records its exit code and output;
- template: the chosen one is the `template: X` line sinew prints on stdout, else the one
  given, else `none`; right when it equals the reference `kind`;
- joint error: per reference joint, the distance to the nearest bone end (head or tail of any
  bone) over the character's height (its opaque box in NAME.png);
- root at the hips (humanoid and quadruped characters with a reference pelvis): the root bone
  (no parent; of several, the one with the most descendants) has its head within 8 % of the
  height of the reference pelvis;
- layered only: bones per part (bones whose `bind` lists the part; an unbound bone counts for
  the parts whose opaque pixels its midpoint lies on), parts without a bone, and weight bleed:
  `SINEW rig NAME.ora --handles ... -o OUT/NAME.rig.json`, then per part the share of its
  vertices' weight held by bones bound elsewhere (a bone in `bind` not listing the part, or an
  unbound bone whose midpoint is not on the part), over all vertices and over those farther than
  3 % of the height from every other part's opaque pixels ("outside seams").

Writes OUT/scores.json and prints a Markdown table and summary lines.
"""
import json
import math
import statistics
import subprocess
import sys
import zipfile
import io
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
from PIL import Image

ROOT_TOLERANCE = 0.08
SEAM_FRACTION = 0.03
TEMPLATES = ("humanoid", "quadruped")


def pct(xs, q):
    xs = sorted(xs)
    if not xs:
        return float("nan")
    k = (len(xs) - 1) * q
    f = math.floor(k)
    c = min(f + 1, len(xs) - 1)
    return xs[f] + (xs[c] - xs[f]) * (k - f)


def ora_layers(path):
    """name -> opaque mask (canvas-sized bool array), in stack.xml order (front first)."""
    with zipfile.ZipFile(path) as z:
        root = ET.fromstring(z.read("stack.xml"))
        w, h = int(root.get("w")), int(root.get("h"))
        out = {}
        for layer in root.iter("layer"):
            img = Image.open(io.BytesIO(z.read(layer.get("src")))).convert("RGBA")
            x, y = int(float(layer.get("x", 0))), int(float(layer.get("y", 0)))
            canvas = Image.new("RGBA", (w, h), (0, 0, 0, 0))
            canvas.paste(img, (x, y))
            out[layer.get("name")] = np.asarray(canvas)[..., 3] > 0
    return out


def dilate(mask, r):
    """mask grown by the pixel disk of radius r."""
    h, w = mask.shape
    out = mask.copy()
    ri = int(math.ceil(r))
    for dy in range(-ri, ri + 1):
        for dx in range(-ri, ri + 1):
            if dx * dx + dy * dy > r * r or (dx == 0 and dy == 0):
                continue
            ys = slice(max(0, -dy), min(h, h - dy))
            yd = slice(max(0, dy), min(h, h + dy))
            xs = slice(max(0, -dx), min(w, w - dx))
            xd = slice(max(0, dx), min(w, w + dx))
            out[yd, xd] |= mask[ys, xs]
    return out


def on_mask(mask, x, y):
    i, j = int(math.floor(x)), int(math.floor(y))
    h, w = mask.shape
    return 0 <= i < w and 0 <= j < h and bool(mask[j, i])


def root_bone(bones):
    children = {}
    for b in bones:
        children.setdefault(b.get("parent"), []).append(b["name"])

    def count(name):
        return sum(1 + count(c) for c in children.get(name, []))

    roots = [b for b in bones if not b.get("parent")]
    if not roots:
        return None
    return max(roots, key=lambda b: count(b["name"]))


def run_autorig(sinew, file, out_dir, stem, kind, template_given):
    handles = out_dir / f"{stem}.handles.json"
    cmd = [sinew, "autorig", str(file), "-o", str(handles), "--preview", str(out_dir / f"{stem}.preview.png")]
    given = None
    if template_given and kind in TEMPLATES:
        given = kind
        cmd += ["--template", kind]
    run = subprocess.run(cmd, capture_output=True, text=True)
    chosen = None
    for line in run.stdout.splitlines():
        if line.startswith("template: "):
            chosen = line[len("template: "):].split()[0].strip().rstrip(".,:;")
            break
    res = {"cmd": " ".join(cmd[1:]), "exit_code": run.returncode, "stdout": run.stdout.strip()[:2000],
           "stderr": run.stderr.strip()[:2000]}
    if chosen is None:
        chosen = given or "none"
    res["template"] = chosen
    res["template_fit_failed"] = "does not match" in (run.stdout + run.stderr)
    if run.returncode != 0 or not handles.exists():
        res["error"] = (run.stderr.strip() or run.stdout.strip() or f"exit code {run.returncode}")[:300]
        res["template"] = "failed"
        return res, None
    return res, json.loads(handles.read_text())


def joint_scores(ref, handles, height):
    bones = handles.get("bones", [])
    ends = [p for b in bones for p in (b["head"], b["tail"])]
    errors = {}
    for joint, (x, y) in ref["joints"].items():
        d = min((math.hypot(x - ex, y - ey) for ex, ey in ends), default=float("inf"))
        errors[joint] = d / height
    out = {"bones": len(bones), "joint_errors": errors,
           "median_joint_error": statistics.median(errors.values()) if errors else None}
    root = root_bone(bones)
    out["root"] = root["name"] if root else None
    if ref["kind"] in TEMPLATES and "pelvis" in ref["joints"]:
        px, py = ref["joints"]["pelvis"]
        if root:
            d = math.hypot(root["head"][0] - px, root["head"][1] - py) / height
            out["root_to_pelvis"] = d
            out["root_at_hips"] = d <= ROOT_TOLERANCE
        else:
            out["root_at_hips"] = False
    return out


def layered_scores(sinew, ref, ora, handles, handles_path, out_dir, height):
    masks = ora_layers(ora)
    bones = handles.get("bones", [])
    bind = handles.get("bind", {}) or {}
    mid = {b["name"]: ((b["head"][0] + b["tail"][0]) / 2, (b["head"][1] + b["tail"][1]) / 2) for b in bones}

    def bone_on_part(bone, part):
        if bone in bind:
            return part in bind[bone]
        x, y = mid.get(bone, (-1, -1))
        return on_mask(masks[part], x, y)

    per_part = {part: [b["name"] for b in bones if bone_on_part(b["name"], part)] for part in masks}
    res = {"bones_per_part": {p: len(v) for p, v in per_part.items()},
           "parts_without_bone": [p for p, v in per_part.items() if not v],
           "bind": bool(bind)}
    rig_path = out_dir / f"{ref['name']}.rig.json"
    run = subprocess.run([sinew, "rig", str(ora), "--handles", str(handles_path), "-o", str(rig_path)],
                         capture_output=True, text=True)
    res["rig_exit_code"] = run.returncode
    res["rig_stderr"] = run.stderr.strip()[:2000]
    if run.returncode != 0 or not rig_path.exists():
        res["rig_error"] = (run.stderr.strip() or f"exit code {run.returncode}")[:300]
        return res
    rig = json.loads(rig_path.read_text())
    radius = SEAM_FRACTION * height
    grown = {p: dilate(m, radius) for p, m in masks.items()}
    bleed = {}
    tot = tot_w = out_n = out_w = 0.0
    for part in rig["parts"]:
        name = part["name"]
        weights = part.get("weights")
        if name not in masks or not weights:
            continue
        columns = weights["handles"]
        foreign = [c not in mid or not bone_on_part(c, name) for c in columns]
        others = np.zeros_like(masks[name])
        for p, g in grown.items():
            if p != name:
                others |= g
        w_all = w_out = 0.0
        n_out = 0
        for (x, y), row in zip(part["mesh"]["vertices"], weights["rows"]):
            f = sum(w for c, w in row if foreign[c])
            w_all += f
            if not on_mask(others, x, y):
                n_out += 1
                w_out += f
        n = len(part["mesh"]["vertices"])
        bleed[name] = {"share": w_all / n if n else 0.0, "outside_seams": w_out / n_out if n_out else 0.0,
                       "vertices": n, "vertices_outside_seams": n_out}
        tot += n
        tot_w += w_all
        out_n += n_out
        out_w += w_out
    res["bleed_per_part"] = bleed
    res["bleed"] = tot_w / tot if tot else None
    res["bleed_outside_seams"] = out_w / out_n if out_n else None
    res["max_part_bleed_outside_seams"] = max((b["outside_seams"] for b in bleed.values()), default=None)
    return res


def score_one(sinew, set_dir, out_dir, name, template_given):
    ref = json.loads((set_dir / f"{name}.json").read_text())
    png = set_dir / f"{name}.png"
    ora = set_dir / f"{name}.ora"
    box = Image.open(png).convert("RGBA").getchannel("A").point(lambda a: 255 if a else 0).getbbox()
    height = box[3] - box[1]
    result = {"name": name, "kind": ref["kind"], "view": ref["view"], "traits": ref.get("traits", []),
              "height_px": height}
    for variant, file, stem in (("flat", png, name), ("layered", ora, f"{name}.layered")):
        res, handles = run_autorig(sinew, file, out_dir, stem, ref["kind"], template_given)
        res["template_right"] = res["template"] == ref["kind"]
        if handles is not None:
            res.update(joint_scores(ref, handles, height))
            if variant == "layered":
                res.update(layered_scores(sinew, ref, ora, handles, out_dir / f"{stem}.handles.json", out_dir, height))
        result[variant] = res
    return result


def fmt_pct(v, digits=1):
    return "–" if v is None else f"{100 * v:.{digits}f} %"


def main():
    args = sys.argv[1:]
    template_given = "--template-given" in args
    args = [a for a in args if a != "--template-given"]
    label = "sinew"
    if "--label" in args:
        i = args.index("--label")
        label = args[i + 1]
        del args[i:i + 2]
    sinew, set_dir, out_dir = args[0], Path(args[1]), Path(args[2])
    out_dir.mkdir(parents=True, exist_ok=True)
    names = json.loads((set_dir / "index.json").read_text())
    results = []
    for n in names:
        results.append(score_one(sinew, set_dir, out_dir, n, template_given))
        print(f"{n} done", file=sys.stderr)
    (out_dir / "scores.json").write_text(json.dumps(
        {"label": label, "template_given": template_given, "sinew": sinew, "characters": results}, indent=1) + "\n")

    print(f"### {label}{' (template given)' if template_given else ' (no template given)'}\n")
    print("| character | kind | view | template flat | template layered | bones flat / layered "
          "| median joint error flat | median joint error layered | root at hips flat / layered "
          "| parts without a bone | weight bleed | bleed outside seams |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")

    def tmpl(r):
        t = r["template"]
        s = t if r["template_right"] else f"{t} ✗"
        if r.get("template_fit_failed"):
            s += " (fit failed)"
        return s

    def root(r):
        if "root_at_hips" not in r:
            return "–"
        return "yes" if r["root_at_hips"] else f"no ({100 * r.get('root_to_pelvis', float('nan')):.0f} %)"

    for r in results:
        f, l = r["flat"], r["layered"]
        parts = "–"
        bleed = seams = "–"
        if "bones_per_part" in l:
            n = len(l["bones_per_part"])
            parts = f"{len(l['parts_without_bone'])}/{n}"
            if l["parts_without_bone"]:
                parts += " (" + ", ".join(l["parts_without_bone"]) + ")"
            if "rig_error" in l:
                bleed = "rig failed: " + l["rig_error"].replace("|", "/")[:80]
            else:
                bleed, seams = fmt_pct(l.get("bleed")), fmt_pct(l.get("bleed_outside_seams"))
        bones = f"{f.get('bones', '–')} / {l.get('bones', '–')}"
        print(f"| {r['name']} | {r['kind']} | {r['view']} | {tmpl(f)} | {tmpl(l)} | {bones} "
              f"| {fmt_pct(f.get('median_joint_error'))} | {fmt_pct(l.get('median_joint_error'))} "
              f"| {root(f)} / {root(l)} | {parts} | {bleed} | {seams} |")
    print()
    for variant in ("flat", "layered"):
        rs = [r[variant] for r in results]
        failed = [r["name"] for r in results if "error" in r[variant]]
        right = sum(x["template_right"] for x in rs)
        errs = [e for x in rs for e in x.get("joint_errors", {}).values()]
        roots = [x["root_at_hips"] for x in rs if "root_at_hips" in x]
        line = (f"- {variant}: template right {right}/{len(rs)} ({100 * right / len(rs):.0f} %)"
                + (f", autorig failed on {len(failed)} ({', '.join(failed)})" if failed else "")
                + (f"; joint error over {len(errs)} joints (% of height): median {100 * statistics.median(errs):.1f}, "
                   f"90th percentile {100 * pct(errs, 0.9):.1f}" if errs else "")
                + f"; root at the hips {sum(roots)}/{len(roots)}")
        print(line)
        by_kind = {}
        for r in results:
            by_kind.setdefault(r["kind"], []).append(r[variant]["template_right"])
        print("  - template right by kind: " + ", ".join(f"{k} {sum(v)}/{len(v)}" for k, v in by_kind.items()))
        fitted = [r for r in results if r[variant]["template"] in TEMPLATES]
        if fitted:
            failed_fit = [r["name"] for r in fitted if r[variant].get("template_fit_failed")]
            print(f"  - template fit failed (sinew fell back to the medial axis): {len(failed_fit)}/{len(fitted)}"
                  + (f" ({', '.join(failed_fit)})" if failed_fit else ""))
    lay = [r["layered"] for r in results if "bones_per_part" in r["layered"]]
    n_parts = sum(len(x["bones_per_part"]) for x in lay)
    without = sum(len(x["parts_without_bone"]) for x in lay)
    print(f"- layered: parts without a bone {without}/{n_parts} (characters with one: "
          f"{sum(bool(x['parts_without_bone']) for x in lay)}/{len(lay)}); bones bound with `bind`: "
          f"{sum(x['bind'] for x in lay)}/{len(lay)} characters")
    bl = [x for x in lay if x.get("bleed") is not None]
    if bl:
        print(f"- layered weight bleed (share of weight held by bones bound elsewhere): mean over characters "
              f"{100 * statistics.mean(x['bleed'] for x in bl):.1f} %, outside seams "
              f"{100 * statistics.mean(x['bleed_outside_seams'] or 0 for x in bl):.1f} % "
              f"(max per character {100 * max(x['bleed_outside_seams'] or 0 for x in bl):.1f} %); "
              f"characters with bleed 0 outside seams: {sum((x['bleed_outside_seams'] or 0) < 1e-6 for x in bl)}/{len(bl)}; "
              f"`sinew rig` failed: {sum('rig_error' in x for x in lay)}")


if __name__ == "__main__":
    main()
