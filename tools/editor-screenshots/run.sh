#!/usr/bin/env bash
# Screenshots of the editor, one per mode, for the guide's images (a person runs this on purpose
# and looks at the PNGs before committing them).
#
#   tools/editor-screenshots/run.sh [OUT_DIR]      (default: docs/guide/src/images/)
#
# Builds in $CARGO_TARGET_DIR (default target/) with $PROFILE (default release; debug works
# too and is what a worktree sharing its dependencies with others would use).
#
# Runs the editor under Xvfb with Mesa's software OpenGL (no GPU needed). Installs what it needs
# on first use from Debian's packages (needs root or sudo): xvfb, xauth and the X libraries winit
# loads at run time. Exit status: 0 done, 3 on a setup error.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
out="${1:-$root/docs/guide/src/images}"

as_root() {
  if [ "$(id -u)" -eq 0 ]; then "$@"
  elif command -v sudo >/dev/null; then sudo "$@"
  else echo "editor-screenshots: need root (or sudo) to install $*" >&2; exit 3
  fi
}
if ! command -v xvfb-run >/dev/null; then
  as_root apt-get update -qq >&2
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
    xvfb xauth libgl1-mesa-dri libegl1 libxkbcommon-x11-0 libxcursor1 libxrandr2 libxi6 >&2
fi

cd "$root"
profile="${PROFILE:-release}"
target="${CARGO_TARGET_DIR:-$root/target}"
if [ "$profile" = release ]; then cargo build --release --locked; else cargo build --locked; fi
sinew="$target/$profile/sinew"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# The bundled character, rigged; the demo's rig refers to the assets by relative paths.
"$sinew" demo -o "$work/demo" >/dev/null
rig="$work/demo/character.json"
mkdir -p "$out"
shoot() { # MODE OUT.png [extra args]
  local mode="$1" png="$2"; shift 2
  LIBGL_ALWAYS_SOFTWARE=1 xvfb-run -a -s "-screen 0 1280x800x24" \
    "$sinew" edit "$rig" --mode "$mode" --screenshot "$png" "$@"
}
shoot rig "$out/editor-rig.png" --select arm_upper_l
shoot pose "$out/editor-pose.png" --pose "$root/assets/character/poses/lift.json" --select chest
# Animate mode with the graph view open on the left upper arm's curves in 'hop'.
shoot animate "$out/editor-animate.png" --select arm_upper_l --graph-view
# The tree: pose mode, the right forearm selected in it (its row highlighted).
shoot pose "$out/editor-tree.png" --select arm_lower_r
# Colorize mode on a generated line-art scene with its scribbles.
cargo run --quiet --profile "$([ "$profile" = debug ] && echo dev || echo "$profile")" --locked --example colorize_scenes -- "$work/scenes" >/dev/null
shoot colorize "$out/editor-colorize.png" --line-art "$work/scenes/closed-art.png" \
  --scribbles "$work/scenes/closed-scribbles.json"
echo "wrote $out/editor-{rig,pose,animate,tree,colorize}.png"
