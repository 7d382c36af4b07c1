#!/usr/bin/env python3
"""Writes the `hop` animation's deform keys (a belly squash on landing) into
assets/character/animations.json, for the torso mesh `sinew demo` builds.

    python3 tools/make-assets/deform_hop.py DEMO_FOLDER/character.json

Deform keys list one offset per mesh vertex, so they follow the mesh: rerun this after a change
to the torso art or to the default mesh options (`sinew demo` refuses a count that no longer
matches, naming the animation and part). Standard library only.
"""
import json
import math
import re
import sys
from pathlib import Path

ASSETS = Path(__file__).resolve().parents[2] / "assets" / "character"
SQUASH_WIDEN = 0.12  # horizontal bulge at the belly, share of the distance from the midline
SQUASH_DROP_PX = 6.0  # how far the belly sinks, px


def main() -> None:
    rig = json.loads(Path(sys.argv[1]).read_text())
    torso = next(p for p in rig["parts"] if p["name"] == "torso")
    vertices = torso["mesh"]["vertices"]
    xs = [v[0] for v in vertices]
    ys = [v[1] for v in vertices]
    mid_x = (min(xs) + max(xs)) / 2
    top, bottom = min(ys), max(ys)

    def squash(v):
        bump = math.sin(math.pi * (v[1] - top) / (bottom - top))
        return [round((v[0] - mid_x) * SQUASH_WIDEN * bump, 3), round(SQUASH_DROP_PX * bump, 3)]

    rest = [[0, 0] for _ in vertices]
    path = ASSETS / "animations.json"
    animations = json.loads(path.read_text())
    animations["hop"]["deform"] = {
        "torso": [
            {"time": 0.6, "value": rest},
            {"time": 0.67, "value": [squash(v) for v in vertices], "curve": [0.72, 0, 0.75, 1]},
            {"time": 0.8, "value": rest},
        ]
    }
    deform = animations["hop"].pop("deform")
    animations["hop"]["deform"] = "@DEFORM@"
    text = json.dumps(animations, indent=2)
    # One line per key: the offset lists are long; the rest keeps the file's layout.
    lines = ",\n".join("        " + json.dumps(k) for k in deform["torso"])
    text = text.replace('"@DEFORM@"', '{\n      "torso": [\n' + lines + "\n      ]\n    }")
    path.write_text(text + "\n")


if __name__ == "__main__":
    main()
