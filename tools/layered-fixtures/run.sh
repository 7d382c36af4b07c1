#!/usr/bin/env bash
# Regenerates tests/fixtures/layered/: layered files written by real tools, which
# tests/layered.rs reads and compares with the tools' own flattened images.
#   1. psd-tools (pinned in requirements.txt, installed into a virtual environment) writes the
#      PSD/PSB/grayscale/refused documents, their composites and a GimpToSpine-style folder
#      (make_fixtures.py).
#   2. Krita (Debian package `krita`, run headless under xvfb-run) opens the psd-tools
#      character (its [ignore] layer hidden, as Krita would draw it) and exports it as
#      OpenRaster (with Krita's own mergedimage.png) and as PSD.
#
# Usage: tools/layered-fixtures/run.sh
#   env  VENV=DIR        the virtual environment (default: /tmp/sinew-layered-venv)
#        PYTHON=python3  the interpreter that creates it
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
out="$root/tests/fixtures/layered"
venv="${VENV:-/tmp/sinew-layered-venv}"
python="${PYTHON:-python3}"

if [[ ! -x "$venv/bin/python" ]]; then
  echo "== creating $venv" >&2
  "$python" -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$here/requirements.txt"

rm -rf "$out"
mkdir -p "$out"
echo "== psd-tools" >&2
"$venv/bin/python" "$here/make_fixtures.py" "$out"

echo "== krita $(krita --version 2>/dev/null | head -1)" >&2
work="$(mktemp -d "${TMPDIR:-/tmp}/sinew-krita.XXXXXX")"
trap 'rm -rf "$work"' EXIT
"$venv/bin/python" "$here/make_fixtures.py" --krita-source "$work/source.psd"
for target in krita.ora krita.psd; do
  HOME="$work" xvfb-run -a krita "$work/source.psd" --export \
    --export-filename "$out/$target" >"$work/krita.log" 2>&1 \
    || { cat "$work/krita.log" >&2; exit 1; }
done
ls -l "$out" >&2
du -sh "$out" >&2
