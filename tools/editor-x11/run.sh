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

skip() { echo "editor-x11: skipped: $*"; exit 0; }
fail() { echo "editor-x11: FAILED: $*" >&2; exit 1; }

need=()
command -v Xvfb >/dev/null || need+=(xvfb xauth)
command -v xdotool >/dev/null || need+=(xdotool)
command -v python3 >/dev/null || need+=(python3)
if [ "${#need[@]}" -gt 0 ]; then
  command -v apt-get >/dev/null || skip "no apt-get to install ${need[*]}"
  if [ "$(id -u)" -eq 0 ]; then as_root=(); elif command -v sudo >/dev/null && sudo -n true 2>/dev/null; then as_root=(sudo -n); else skip "need root or sudo to install ${need[*]}"; fi
  "${as_root[@]}" apt-get update -qq >/dev/null 2>&1 || skip "apt-get update failed (offline?)"
  "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
    "${need[@]}" libgl1-mesa-dri libegl1 libxkbcommon-x11-0 libxcursor1 libxrandr2 libxi6 \
    >/dev/null 2>&1 || skip "could not install ${need[*]}"
fi

cd "$root"
cargo build --locked --quiet
sinew="${CARGO_TARGET_DIR:-$root/target}/debug/sinew"
work="$(mktemp -d)"
xvfb_pid=""; editor_pid=""
cleanup() {
  [ -n "$editor_pid" ] && kill "$editor_pid" 2>/dev/null || true
  [ -n "$xvfb_pid" ] && kill "$xvfb_pid" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

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

# A free display number, our own X server.
display=""
for n in $(seq 90 140); do
  [ -e "/tmp/.X11-unix/X$n" ] || [ -e "/tmp/.X$n-lock" ] || { display=":$n"; break; }
done
[ -n "$display" ] || skip "no free X display number"
Xvfb "$display" -screen 0 1280x800x24 -nolisten tcp >/dev/null 2>&1 &
xvfb_pid=$!
export DISPLAY="$display"
for _ in $(seq 50); do xdotool getmouselocation >/dev/null 2>&1 && break; sleep 0.1; done
xdotool getmouselocation >/dev/null 2>&1 || skip "Xvfb did not start"

LIBGL_ALWAYS_SOFTWARE=1 "$sinew" edit "$rig" --mode animate >"$work/editor.log" 2>&1 &
editor_pid=$!
wid=""
for _ in $(seq 120); do
  wid="$(xdotool search --name '^sinew' 2>/dev/null | head -1)" && [ -n "$wid" ] && break
  kill -0 "$editor_pid" 2>/dev/null || fail "the editor exited: $(cat "$work/editor.log")"
  sleep 0.25
done
[ -n "$wid" ] || fail "no editor window after 30 s"
sleep 4 # first frames under software GL
# No window manager: give the window the keyboard focus ourselves.
xdotool windowfocus "$wid" 2>/dev/null || true
eval "$(xdotool getwindowgeometry --shell "$wid")"
at() { echo $((X + $1)) $((Y + $2)); }

# Drag the belly (window point 800, 430 shows it in animate mode at the fitted view) up and
# right, in steps, as a hand does; then K keys the pose, Ctrl+S saves.
xdotool mousemove $(at 800 430) sleep 0.3 mousedown 1 sleep 0.3
for k in 1 2 3 4 5 6; do xdotool mousemove $(at $((800 + 5 * k)) $((430 - 4 * k))) sleep 0.15; done
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
