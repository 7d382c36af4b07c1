#!/usr/bin/env bash
# The bundled character walking (or CLIP) retargeted by sinew and by the Animated
# Drawings-style baseline, rendered side by side for a look (docs/retarget-eval.md):
#
#   [IN_PLACE=1] tools/retarget-eval/render.sh OUT_DIR [CLIP]
#
# Writes OUT_DIR/CLIP_sinew.gif, OUT_DIR/CLIP_baseline.gif and OUT_DIR/CLIP_compare.png (eight
# frames, sinew above, baseline below, the rig's ground line — its lowest rest ankle — in red).
# Expects tools/retarget-eval/run.sh to have built target/release/sinew and the example
# (RETARGET_EVAL_BIN overrides the example's path).
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
out="$(mkdir -p "$1" && cd "$1" && pwd)"
clip="${2:-walk}"
sinew="$root/target/release/sinew"
eval_bin="${RETARGET_EVAL_BIN:-$root/target/release/examples/retarget_eval}"
cd "$out"
"$sinew" demo -o demo >/dev/null
"$eval_bin" --anims "$clip" demo/character.json rig.json ${IN_PLACE:+--in-place}
for a in "${clip}_sinew" "${clip}_baseline"; do
  "$sinew" render rig.json --anim "$a" --fps 30 --size 800x560 --background '#ffffff' -o "$a.gif"
  rm -rf "${a}_frames"
  "$sinew" render rig.json --anim "$a" --fps 30 --size 800x560 --background '#ffffff' -o "${a}_frames"
done
python3 "$root/tools/retarget-eval/compose.py" "$out/${clip}_compare.png" \
  "${clip}_sinew_frames" "${clip}_baseline_frames"
