#!/usr/bin/env bash
# The real-art autorig evaluation (docs/autorig-real-eval.md): scores `sinew autorig` on the 34
# characters of tests/fixtures/autorig-real, each as a flat sprite and as a layered .ora, against
# the hand-placed reference joints and layer parts (score.py), and prints the table.
#
# Usage: tools/autorig-real/run.sh SINEW_BINARY [--label L] [--template-given] [--out DIR]
#   --template-given  pass `--template KIND` for humanoid and quadruped characters
#   --out DIR         where proposals, previews, rigs and scores.json go (default: a new temp dir)
#   env  VENV=DIR     the virtual environment (default: tools/autorig-real/.venv)
# The set itself is rebuilt from Debian's packages by tools/autorig-real/fetch.sh.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
set_dir="$root/tests/fixtures/autorig-real"
venv="${VENV:-$here/.venv}"
sinew=""
out=""
extra=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --label) extra+=(--label "$2"); shift 2 ;;
    --template-given) extra+=(--template-given); shift ;;
    --out) out="$2"; shift 2 ;;
    *) sinew="$1"; shift ;;
  esac
done
if [[ -z "$sinew" ]]; then
  echo "usage: $0 SINEW_BINARY [--label L] [--template-given] [--out DIR]" >&2
  exit 2
fi
sinew="$(cd "$(dirname "$sinew")" && pwd)/$(basename "$sinew")"

if [[ ! -x "$venv/bin/python" ]]; then
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$here/requirements.txt"
if [[ -z "$out" ]]; then
  out="$(mktemp -d "${TMPDIR:-/tmp}/sinew-autorig-real.XXXXXX")"
fi
"$venv/bin/python" "$here/score.py" "$sinew" "$set_dir" "$out" "${extra[@]}"
echo "proposals, previews, rigs and scores.json: $out" >&2
