#!/usr/bin/env bash
# A scripted editing run with real X input events: the editor under Xvfb (Mesa's software GL)
# on the bundled character, driven by xdotool as a person would drive it — animate mode, a drag
# of the drawing, K (set key), Ctrl+S — then the saved file is checked: the animation edited
# has one more IK timeline, keyed at 0 s, and the file still opens (`sinew pose`).
#
#   tools/editor-x11/run.sh
#
# Installs xvfb, xauth, xdotool and the X libraries winit loads on first use from Debian's
# packages when it can (root or sudo). Where it cannot, or there is no apt, it says so on one
# line and exits 0 (skipped). Exit status: 0 passed or skipped, 1 failed.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"

source "$here/lib.sh"
need_x11

cd "$root"
# The binary `cargo test` built (an integration test's build brings it up to date): a plain
# `cargo build` would compile the dependencies again with other features, minutes on CI.
cargo test --release --locked --quiet --no-run --test cli
sinew="${CARGO_TARGET_DIR:-$root/target}/release/sinew"
make_work

"$sinew" demo -o "$work/demo" >/dev/null
rig="$work/demo/character.json"
ik_count() { # the first animation's IK timelines with a key at 0 s
  python3 - "$1" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
name = sorted(doc["animations"])[0]
print(sum(1 for t in doc["animations"][name].get("ik", []) if any(abs(k["time"]) < 1e-9 for k in t["to"])))
PY
}
before="$(ik_count "$rig")"

start_x11
start_editor "$rig" --mode animate

# Drag the belly (window point 830, 430 shows it in animate mode at the fitted view, right of
# the spine's bones: a drag that starts on a bone turns the bone) up and right, in steps, as a
# hand does; then K keys the pose, Ctrl+S saves.
xdotool mousemove $(at 830 430) sleep 0.3 mousedown 1 sleep 0.3
for k in 1 2 3 4 5 6; do xdotool mousemove $(at $((830 + 5 * k)) $((430 - 4 * k))) sleep 0.15; done
xdotool mouseup 1 sleep 1
xdotool key --clearmodifiers k sleep 1
xdotool key --clearmodifiers ctrl+s
saved=""
for _ in $(seq 40); do
  after="$(ik_count "$rig" 2>/dev/null || echo "$before")"
  [ "$after" -gt "$before" ] && { saved=1; break; }
  sleep 0.25
done
if [ -z "$saved" ] && [ -n "${EDITOR_X11_DEBUG:-}" ]; then
  cp "$rig" "$EDITOR_X11_DEBUG/after.json"; cp "$work/editor.log" "$EDITOR_X11_DEBUG/"
  xdotool getwindowgeometry "$wid" >"$EDITOR_X11_DEBUG/geometry.txt"
fi
[ -n "$saved" ] || fail "the saved file has $before IK timelines keyed at 0 s, as before (editor log: $(tail -3 "$work/editor.log"))"
kill -0 "$editor_pid" 2>/dev/null || fail "the editor crashed"
# The saved document still opens and poses.
"$sinew" pose "$rig" --anim "$(python3 -c 'import json,sys; print(sorted(json.load(open(sys.argv[1]))["animations"])[0])' "$rig")" \
  --time 0 -o "$work/posed.png" >/dev/null || fail "the saved file does not pose"
echo "editor-x11: passed (IK timelines keyed at 0 s: $before before, $after after the drag, K and Ctrl+S)"
