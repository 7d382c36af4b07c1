#!/usr/bin/env bash
# The retargeting evaluation of issue 42 (docs/retarget-eval.md): builds `sinew` and the
# `retarget_eval` example, proposes the characters' skeletons with `sinew autorig`, retargets
# every clip of the bundled library onto each character with sinew and with an Animated
# Drawings-style baseline, and prints the Markdown tables on stdout.
#
#   tools/retarget-eval/run.sh [--no-build] > table.md
#
# Characters: the bundled one (assets/character/handles.json, whose arms are root bones); five
# humanoids of the generated autorig set (tests/fixtures/autorig-eval/NAME.png, proposed with
# `--template humanoid`); three layered characters of the real-art set
# (tests/fixtures/autorig-real/NAME.ora, proposed from their layers). Each was picked because
# its proposal names hip or chest, both legs (leg_upper_*, leg_lower_*) and at least one arm as
# the humanoid template does (JointMap::humanoid drives only bones so named).
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
cd "$root"
if [[ "${1:-}" != "--no-build" ]]; then
  cargo build --release --quiet --bin sinew --example retarget_eval >&2
fi
sinew="$root/target/release/sinew"
eval_bin="${RETARGET_EVAL_BIN:-$root/target/release/examples/retarget_eval}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

generated=(stick_walker chibi tall_thin stick_man muscle_man)
real=(kid man_walking goblin)
args=("bundled=assets/character/handles.json")
for n in "${generated[@]}"; do
  "$sinew" autorig "tests/fixtures/autorig-eval/$n.png" --template humanoid \
    -o "$work/$n.handles.json" >/dev/null 2>&1
  args+=("$n=$work/$n.handles.json")
done
for n in "${real[@]}"; do
  "$sinew" autorig "tests/fixtures/autorig-real/$n.ora" -o "$work/$n.handles.json" >/dev/null 2>&1
  args+=("$n=$work/$n.handles.json")
done

echo "Run $(date -u +%Y-%m-%dT%H:%MZ) at commit $(git rev-parse --short HEAD)."
"$eval_bin" "${args[@]}" > "$work/out.md"
built="$(sed -n 's/.*sha256 \([0-9a-f]*\).*/\1/p' "$work/out.md" | head -1)"
# Which commit's src/motion/retarget.rs the example was built with (the newest that matches).
state="a version no commit has (uncommitted changes; sha256 $built)"
for c in $(git log --format=%h -n 50 -- src/motion/retarget.rs); do
  if [[ "$(git show "$c:src/motion/retarget.rs" | sha256sum | cut -d' ' -f1)" == "$built" ]]; then
    state="as of commit $c"
    break
  fi
done
echo "src/motion/retarget.rs $state."
echo
sed '1,2d' "$work/out.md"
