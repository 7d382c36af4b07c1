#!/usr/bin/env bash
# Peak memory of a long render: the bundled character's walk looped for DURATION seconds
# (default 60) at 60 fps into 1920×1080 frames, written as a frame folder, measured with
# GNU time's maximum resident set size. Issue 24's target: under 1 GB.
#
#   tools/render-memory/run.sh [DURATION_S] [TARGET]     # TARGET: folder (default), gif, sheet
#
# Uses the release binary when it is built (`cargo build --release`), else the debug one.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
duration="${1:-60}"
kind="${2:-folder}"
target_dir="${CARGO_TARGET_DIR:-$root/target}"
sinew="$target_dir/release/sinew"
[ -x "$sinew" ] || sinew="$target_dir/debug/sinew"
[ -x "$sinew" ] || { echo "render-memory: build sinew first (cargo build)" >&2; exit 2; }
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

"$sinew" demo -o "$work/demo" >/dev/null
# The walk (1 s) repeated to fill DURATION seconds: every key shifted by whole loops.
python3 - "$work/demo/character.json" "$duration" <<'PY'
import json, sys
path, duration = sys.argv[1], int(sys.argv[2])
doc = json.load(open(path))
walk = doc["animations"]["walk"]
def stretch(node):
    if isinstance(node, list) and node and all(isinstance(k, dict) and "time" in k for k in node):
        span = 1.0
        out = []
        for loop in range(duration):
            for key in node:
                if loop > 0 and key["time"] == 0:
                    continue
                k = dict(key)
                k["time"] = key["time"] + loop * span
                if "curve" in k and isinstance(k["curve"], list):
                    k["curve"] = [c + loop * span if i % 2 == 0 else c for i, c in enumerate(k["curve"])]
                out.append(k)
        return out
    if isinstance(node, dict):
        return {k: stretch(v) for k, v in node.items()}
    return node
long = stretch({k: v for k, v in walk.items() if k != "events"})
doc["animations"]["long"] = long
json.dump(doc, open(path, "w"))
PY
case "$kind" in
  folder) out="$work/frames" ;;
  gif) out="$work/long.gif" ;;
  sheet) out="$work/long.png" ;;
  *) echo "render-memory: TARGET is folder, gif or sheet" >&2; exit 2 ;;
esac
fps=60; size=1920x1080; scale=2
[ "$kind" = gif ] && fps=50
/usr/bin/time -v "$sinew" render "$work/demo/character.json" --anim long --fps "$fps" \
  --size "$size" --scale "$scale" -o "$out" 2> "$work/time.txt" >/dev/null
frames=$(ls "$work/frames" 2>/dev/null | wc -l)
rss_kb=$(grep "Maximum resident set size" "$work/time.txt" | awk '{print $NF}')
wall=$(grep "Elapsed (wall clock)" "$work/time.txt" | awk '{print $NF}')
echo "render-memory: $kind, ${duration} s at ${fps} fps, ${size}: peak RSS $((rss_kb / 1024)) MiB, wall ${wall}, ${frames} frame files, load $(cut -d' ' -f1-3 /proc/loadavg), binary ${sinew#$root/}"
