#!/usr/bin/env bash
# Benchmark: full frame times of the editor while a hand drags the bundled character in pose
# mode, under Xvfb with Mesa's software GL (llvmpipe), driven by xdotool. The editor logs each
# frame (`sinew edit --frame-log`): its own code, the whole frame as eframe measures it (GL draw
# included, swap wait excluded) and the interval between frame starts; this prints the median
# and 95th percentile of each over the drag's frames, and the machine's load. Issue 20's goal:
# median under 16 ms, p95 under 33 ms.
#
#   tools/editor-x11/frame-times.sh [STEPS] [PROFILE]
#       STEPS pointer moves (default 200), 10 ms apart; PROFILE release (default) or debug (the
#       test profile: sinew at opt-level 1, its dependencies at 3)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
steps="${1:-200}"
profile="${2:-release}"

source "$here/lib.sh"
need_x11

cd "$root"
if [ "$profile" = release ]; then cargo build --locked --quiet --release; else cargo build --locked --quiet; fi
sinew="${CARGO_TARGET_DIR:-$root/target}/$profile/sinew"
make_work

"$sinew" demo -o "$work/demo" >/dev/null
start_x11
start_editor "$work/demo/character.json" --mode pose --frame-log "$work/frames.tsv"
startup_frames=$(($(wc -l <"$work/frames.tsv") - 1))
load_before="$(cut -d' ' -f1-3 /proc/loadavg)"
# Grab the belly right of the spine's bones (window point 790, 420 at the fitted view) and
# circle it: every frame solves the skinning IK and skins and draws the character.
x0=790; y0=420
xdotool mousemove $(at $x0 $y0) sleep 0.3 mousedown 1 sleep 0.2
for k in $(seq 1 "$steps"); do
  dx=$(python3 -c "import math; print(round(60 * math.sin($k / 20)))")
  dy=$(python3 -c "import math; print(round(40 * (1 - math.cos($k / 20))))")
  xdotool mousemove $(at $((x0 + dx)) $((y0 - dy))) sleep 0.01
done
xdotool mouseup 1 sleep 1
kill -0 "$editor_pid" 2>/dev/null || fail "the editor crashed"
python3 - "$work/frames.tsv" "$startup_frames" "$load_before" "$profile" <<'PY'
import statistics, sys
path, skip, load = sys.argv[1], int(sys.argv[2]), sys.argv[3]
rows = [l.split("\t") for l in open(path).read().split("\n")[1:] if l.strip()]
rows = [[float(x) for x in r] for r in rows[skip:]]
if len(rows) < 10:
    sys.exit(f"editor-x11 frame times: only {len(rows)} frames during the drag")
def stats(k):
    v = sorted(r[k] for r in rows)
    p95 = v[min(len(v) - 1, int(round(0.95 * (len(v) - 1))))]
    return f"median {statistics.median(v):.1f} ms, p95 {p95:.1f} ms, max {v[-1]:.1f} ms"
print(f"editor frame times over {len(rows)} frames of a drag in pose mode (Xvfb, llvmpipe, {sys.argv[4]} build):")
print(f"  whole frame (GL draw incl.): {stats(1)}")
print(f"  editor's own code:           {stats(0)}")
print(f"  interval between frames:     {stats(2)}")
print(f"  load before: {load}; after: {open('/proc/loadavg').read().split()[:3]}")
PY
