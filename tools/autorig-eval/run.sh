#!/usr/bin/env bash
# The autorig evaluation: draws the set (tests/fixtures/autorig-eval, make_set.py) and scores
# `sinew autorig` on it against the reference joints (score.py), printing the table of
# docs/autorig-eval.md.
#
# Usage: tools/autorig-eval/run.sh [SINEW_BINARY] [--redraw] [--rig]
#   SINEW_BINARY  default: target/debug/sinew (under $CARGO_TARGET_DIR if set)
#   --redraw      rewrite the set's PNG and JSON files first
#   --rig         also run `sinew rig` with every proposal
#   env  VENV=DIR  the virtual environment (default: tools/autorig-eval/.venv)
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
set_dir="$root/tests/fixtures/autorig-eval"
venv="${VENV:-$here/.venv}"
sinew="${CARGO_TARGET_DIR:-$root/target}/debug/sinew"
redraw=0
extra=()
for arg in "$@"; do
  case "$arg" in
    --redraw) redraw=1 ;;
    --rig) extra+=(--rig) ;;
    *) sinew="$arg" ;;
  esac
done

if [[ ! -x "$venv/bin/python" ]]; then
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$here/requirements.txt"
if [[ $redraw == 1 ]]; then
  "$venv/bin/python" "$here/make_set.py" "$set_dir"
fi
out="$(mktemp -d "${TMPDIR:-/tmp}/sinew-autorig-eval.XXXXXX")"
"$venv/bin/python" "$here/score.py" "$sinew" "$set_dir" "$out" "${extra[@]}"
echo "proposals, previews and scores.json: $out" >&2
